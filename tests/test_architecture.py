"""The shape of the package: which module may import which, and where files are looked up.

The measurement (``amontons.measure``) and the virtual experiment (``amontons.virtual``) are
siblings that share only ``amontons.physics`` and ``amontons.io``: only the tests connect them,
so that the analysis can never use what the generator knows. The import graph is read from
the source with ``ast``, every ``import`` and ``from ... import`` at any depth.
"""

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "src" / "amontons"


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _import_pairs(path: Path) -> list[tuple[str, str | None]]:
    """Every import in ``path``, at any depth, as ``(module, name)``: ``(x.y, None)`` for
    ``import x.y``, ``(base, name)`` for ``from base import name`` with relative bases
    resolved (``from . import kernels`` in amontons/contact/cg.py is
    ``("amontons.contact", "kernels")``)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    here = _module_name(path).split(".")
    if path.name != "__init__.py":
        here = here[:-1]
    pairs = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            pairs += [(alias.name, None) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(here[: len(here) - node.level + 1] + ([base] if base else []))
            pairs += [(base, alias.name) for alias in node.names]
    return pairs


def _imports(path: Path) -> set[str]:
    """Every amontons module ``path`` imports (relative imports resolved): for ``from base
    import name`` both ``base`` and ``base.name``."""
    found = set()
    for base, name in _import_pairs(path):
        found.add(base)
        if name is not None:
            found.add(f"{base}.{name}")
    return {name for name in found if name == "amontons" or name.startswith("amontons.")}


IMPORTS = {_module_name(p): _imports(p) for p in PACKAGE.rglob("*.py")}


def _edges(source: str, target: str) -> list[tuple[str, str]]:
    """Imports from modules under ``source`` of modules under ``target``."""
    return [
        (module, name)
        for module, names in IMPORTS.items()
        if module == source or module.startswith(source + ".")
        for name in names
        if name == target or name.startswith(target + ".")
    ]


def test_the_import_graph_is_read():
    # A parser that found nothing would pass every test below.
    assert ("amontons.measure.edge_gap", "amontons.measure.newton_rings") in _edges(
        "amontons.measure", "amontons.measure"
    )
    assert _edges("amontons.virtual", "amontons.physics")
    assert _edges("amontons.measure", "amontons.io")


@pytest.mark.parametrize(
    ("source", "target"),
    [
        ("amontons.measure", "amontons.virtual"),
        ("amontons.virtual", "amontons.measure"),
        ("amontons.simulate", "amontons.virtual"),
        ("amontons.measure", "amontons.simulate"),
    ],
)
def test_the_analysis_and_the_generator_never_import_each_other(source, target):
    assert _edges(source, target) == []


def test_only_the_validation_study_connects_them_and_nothing_of_either_imports_it():
    """amontons.validation (docs/study.md §7) is, beside the tests, the one place that joins
    the generator's truths to the analysis's judgement, as the tests do; no part of either
    half, of the simulation or of the verdict may import it (the workflow names its jobs)."""
    assert _edges("amontons.validation", "amontons.virtual")
    assert _edges("amontons.validation", "amontons.measure")
    halves = ("measure", "virtual", "simulate", "study", "contact")
    for source in halves:
        assert _edges(f"amontons.{source}", "amontons.validation") == []
    # the workflow names the jobs from the cases module alone (pure Python)
    assert {
        name.removeprefix("amontons.validation.cases").split(".")[0]
        for _, name in _edges("amontons.workflow", "amontons.validation")
    } == {""}


def test_the_generator_takes_from_simulate_only_what_knows_nothing_of_the_analysis():
    """The virtual experiment shares the simulation's grid tools (docs/simulate.md), but
    simulate imports the analysis (Otsu, levelling): the virtual experiment may import only
    simulate modules that import no measurement."""
    used = {name for _, name in _edges("amontons.virtual", "amontons.simulate")}
    assert used, "the virtual experiment no longer uses simulate; drop this test"
    for module in used:
        module = module if module in IMPORTS else module.rsplit(".", 1)[0]
        assert not [n for n in IMPORTS[module] if n.startswith("amontons.measure")], module


@pytest.mark.parametrize("source", ["amontons.io", "amontons.physics"])
def test_formats_and_shared_physics_import_neither_half(source):
    for half in ("amontons.measure", "amontons.virtual", "amontons.contact"):
        assert _edges(source, half) == []


def test_the_solver_imports_nothing_else_of_amontons():
    outside = [
        (module, name)
        for module, name in _edges("amontons.contact", "amontons")
        if not name.startswith("amontons.contact")
    ]
    assert outside == []


DAG_PACKAGES = ("amontons.workflow", "amontons.config")


def test_the_workflow_helpers_import_no_numerical_stack():
    """The Snakefile's helpers (amontons.workflow, which reads amontons.config): parsing the DAG
    must not pay for numpy, pandas or scipy. Every module of both packages is imported."""
    modules = sorted(m for m in IMPORTS if m.startswith(DAG_PACKAGES))
    assert "amontons.workflow.run" in modules and "amontons.config.geometry" in modules
    code = (
        f"import sys; import {', '.join(modules)}; "
        "print(sorted(m for m in ('numpy', 'pandas', 'scipy') if m in sys.modules))"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


def _top(name: str) -> str:
    """The package (or top-level module) of amontons that ``name`` belongs to."""
    parts = name.split(".")
    return ".".join(parts[:2]) if len(parts) > 1 else name


def _cycle(graph: dict[str, set[str]]) -> list[str]:
    """One circle in ``graph`` (node -> nodes it imports), or [] if there is none."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str]:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt) :] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        state[node] = 2
        path.pop()
        return []

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return []


def _module_graph(exclude: str | None = None) -> dict[str, set[str]]:
    """Module -> the amontons modules it imports (a name imported from a package counts as
    the package unless it is a module of its own)."""
    graph = {}
    for module, names in IMPORTS.items():
        if exclude and module.startswith(exclude):
            continue
        targets = {n if n in IMPORTS else n.rsplit(".", 1)[0] for n in names}
        graph[module] = {t for t in targets if t in IMPORTS and t != module}
    return graph


def test_the_circle_finder_finds_a_circle():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) == []


def test_no_package_imports_a_package_that_imports_it():
    """Between amontons' packages (config, workflow, accuracy, simulate, ...) the imports run
    one way: amontons.config sits below amontons.accuracy, which sits below the workflow."""
    graph: dict[str, set[str]] = {}
    for module, names in IMPORTS.items():
        graph.setdefault(_top(module), set()).update(
            _top(n) for n in names if _top(n) != _top(module) and n != "amontons"
        )
    assert _cycle(graph) == []


def test_no_module_outside_the_solver_closes_an_import_circle():
    """Module by module, every import at any depth. Inside amontons.contact the floor tests
    below check it, with a reader that tells ``from . import kernels`` (a module) from
    ``from . import solve`` (the package's __init__)."""
    assert _cycle(_module_graph(exclude="amontons.contact")) == []


# The floors of the contact solver, bottom up (docs/models.md §2, "Floors"): a module imports
# only modules of its own floor or of floors below it, never above.
CONTACT_FLOORS = (
    # 1. laws, options, results: what a caller passes and gets
    ("errors", "laws", "options", "pools", "result", "surfaces", "array_backends", "locks"),
    # 2. operators: FFT plans and wisdom, Green's functions, convolutions
    ("wisdom", "fft", "greens", "jit", "spectrum", "array_convolution", "convolution"),
    # 3. kernel sets: the element-wise work of one iteration
    ("kernels", "device_sources", "array_kernels", "bounded_load", "preconditioned_kernels"),
    # 4. the iteration: the one Polonsky-Keer control flow, its steps and its constraints
    ("stall", "constraints", "cg_iteration", "cg", "preconditioned", "conjugate_gradient"),
    # 5. routes, chosen from one table
    ("plastic_increments", "root_find", "elastic", "winkler", "bounded", "appendix", "routes"),
    # 6. public calls (and the warm-up, which solves through them)
    ("api", "greenwood_tripp", "kernel_cache", ""),
)
CONTACT = "amontons.contact"


def _floor_of(module: str) -> int:
    """The floor (1-6) of a module of amontons.contact ("" is the package's __init__)."""
    short = module[len(CONTACT) + 1 :] if module != CONTACT else ""
    return next(i for i, names in enumerate(CONTACT_FLOORS, 1) if short in names)


def _contact_imports(path: Path) -> set[str]:
    """The amontons.contact modules ``path`` imports: a name imported from a package is that
    module if it is one, else the package (``from . import kernels`` is kernels,
    ``from amontons.contact import solve`` is the package's __init__)."""
    found = set()
    for base, name in _import_pairs(path):
        full = base if name is None else f"{base}.{name}"
        found.add(full if full in IMPORTS else base)
    return {n for n in found if n == CONTACT or n.startswith(CONTACT + ".")}


def _contact_graph() -> dict[str, set[str]]:
    return {
        module: _contact_imports(path) - {module}
        for path in (PACKAGE / "contact").glob("*.py")
        for module in [_module_name(path)]
    }


def test_every_solver_module_has_a_floor():
    modules = sorted(_contact_graph())
    assert "amontons.contact.cg" in modules and len(modules) > 20
    unplaced = []
    for module in modules:
        try:
            _floor_of(module)
        except StopIteration:
            unplaced.append(module)
    assert unplaced == [], "place each in CONTACT_FLOORS (and docs/models.md §2)"


def test_no_solver_module_imports_a_floor_above_its_own():
    graph = _contact_graph()
    assert "amontons.contact.kernels" in graph["amontons.contact.cg"]
    upward = [
        f"{module} (floor {_floor_of(module)}) imports {target} (floor {_floor_of(target)})"
        for module, targets in sorted(graph.items())
        for target in sorted(targets)
        if _floor_of(target) > _floor_of(module)
    ]
    assert upward == []


def test_no_solver_module_closes_an_import_circle():
    """Inside amontons.contact, with names imported from the package read as the package:
    a circle through the __init__ counts too."""
    assert _cycle(_contact_graph()) == []


def _hidden_imports(path: Path) -> list[str]:
    """Imports of amontons modules anywhere but at a module's top level (in a function, a
    class, an ``if`` such as ``if TYPE_CHECKING``, a ``try``), with the line. (Optional
    third-party imports - pyfftw, fcntl - may sit in a ``try`` or a function.)"""
    tree = ast.parse(path.read_text(), filename=str(path))
    top = {id(node) for node in tree.body}
    return [
        f"{path.name}:{node.lineno}"
        for node in ast.walk(tree)
        if id(node) not in top
        and (
            (isinstance(node, ast.ImportFrom) and (node.level or "amontons" in (node.module or "")))
            or (isinstance(node, ast.Import) and any("amontons" in a.name for a in node.names))
        )
    ]


def test_the_hidden_import_scan_finds_one(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("def f():\n    from .api import solve\n")
    assert _hidden_imports(probe) == ["probe.py:2"]


def test_the_solver_hides_no_import():
    """No import hidden in a function or behind ``if TYPE_CHECKING`` to dodge a circle."""
    hidden = [
        hit for path in sorted((PACKAGE / "contact").glob("*.py")) for hit in _hidden_imports(path)
    ]
    assert hidden == []


def test_cupy_is_imported_by_one_module_only():
    """CuPy, the optional GPU dependency, is imported in one small module
    (amontons.contact.array_backends) and only inside the function that loads it, so that
    no other import, and no solve on the CPU, needs it."""
    found = {
        f"{_module_name(path)}:{base}"
        for path in PACKAGE.rglob("*.py")
        for base, _ in _import_pairs(path)
        if base.split(".")[0] in ("cupy", "cupyx")
    }
    loader = "amontons.contact.array_backends"
    # cupyx.scipy.fft: cuFFT's plans, which the convolution runs directly (RealFFTPair)
    assert found == {f"{loader}:cupy", f"{loader}:cupyx", f"{loader}:cupyx.scipy.fft"}
    tree = ast.parse((PACKAGE / "contact" / "array_backends.py").read_text())
    at_top = [
        node.lineno
        for node in tree.body
        if isinstance(node, ast.Import | ast.ImportFrom) and "cupy" in ast.unparse(node)
    ]
    assert at_top == []


def _function_level_imports(module: str) -> list[str]:
    path = PACKAGE.parent / (module.replace(".", "/") + ".py")
    if not path.exists():
        path = PACKAGE.parent / module.replace(".", "/") / "__init__.py"
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            found += [
                f"{module}:{sub.lineno}"
                for sub in ast.walk(node)
                if isinstance(sub, ast.Import | ast.ImportFrom)
            ]
    return found


def test_the_dag_helpers_import_only_at_the_top_of_a_module():
    """No import hidden in a function (to dodge a circle or a slow import) where the DAG is
    built."""
    modules = sorted(m for m in IMPORTS if m.startswith(DAG_PACKAGES))
    assert [hit for m in modules for hit in _function_level_imports(m)] == []


WORKFLOW = REPO / "workflow"


def test_common_smk_only_wires_the_rules_to_amontons_workflow():
    """workflow/rules/common.smk imports amontons.workflow and nothing else of amontons, and
    defines no function: the DAG's logic is importable and tested."""
    text = (WORKFLOW / "rules" / "common.smk").read_text()
    imported = re.findall(r"^(?:from|import) (amontons[\w.]*)", text, flags=re.M)
    assert imported and all(name.startswith("amontons.workflow") for name in imported)
    assert not re.search(r"^\s*def ", text, flags=re.M)


def test_no_rule_types_a_shared_file_name_again():
    """A file that one rule writes and another reads is named once, in amontons.workflow.paths;
    rules reach it through that provider or through ``rules.<name>.output``."""
    tree = ast.parse((PACKAGE / "workflow" / "paths.py").read_text())
    names = [
        node.value.value
        for node in tree.body
        if isinstance(node, ast.Assign)
        and isinstance(node.value, ast.Constant)
        and isinstance(node.value.value, str)
        and "." in node.value.value
    ]
    assert "solve.json" in names and "psf.json" in names
    sources = [REPO / "Snakefile", *sorted((WORKFLOW / "rules").glob("*.smk"))]
    typed = [
        f"{path.name}: {name}"
        for path in sources
        for name in names
        if re.search(rf"[/\"]{re.escape(name)}\"", path.read_text())
    ]
    assert typed == []


LOOKUPS = ("glob", "rglob", "iterdir", "listdir", "scandir", "walk")


def _folder_lookups(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    calls = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in LOOKUPS:
                calls.append(f"{path.name}:{node.lineno} {name}")
    return calls


def test_the_lookup_scan_finds_a_glob(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("from pathlib import Path\nPath('.').glob('*.tif')\n")
    assert _folder_lookups(probe) == ["probe.py:2 glob"]


def test_no_script_or_measurement_looks_into_a_raw_data_folder():
    """Scripts read exactly the files their rule declares; only the workflow's helpers match a
    measured sphere's files to its loads (amontons.io.layout, at DAG time). The atomic
    writers look beside the file they write for the temporaries a killed writer of that
    same file left (amontons.io.files, the FFTW wisdom), never into a raw-data folder."""
    sources = [*sorted((REPO / "scripts").glob("*.py")), *sorted(PACKAGE.rglob("*.py"))]
    allowed = {
        PACKAGE / "io" / "layout.py",
        PACKAGE / "io" / "files.py",
        PACKAGE / "contact" / "wisdom.py",
    }
    found = [call for path in sources if path not in allowed for call in _folder_lookups(path)]
    assert found == []


# The longest function the solver may hold, docstring included (issue: a newcomer reads the
# solver in named steps), and the longest step of the conjugate-gradient iteration.
MAX_SOLVER_FUNCTION_LINES = 150
MAX_CG_STEP_LINES = 80


def _function_lengths(path: Path) -> dict[str, int]:
    """Every function and method of ``path`` (qualified by its class) with its length in
    lines, from ``def`` to its last line, docstring and comments included."""
    tree = ast.parse(path.read_text(), filename=str(path))
    lengths = {}

    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                name = f"{prefix}{child.name}"
                lengths[f"{path.name}::{name}"] = child.end_lineno - child.lineno + 1
                visit(child, f"{name}.")
            elif isinstance(child, ast.ClassDef):
                visit(child, f"{prefix}{child.name}.")

    visit(tree, "")
    return lengths


def test_the_length_reader_counts_methods_and_docstrings(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text('class A:\n    def f(self):\n        """Doc."""\n\n        return 1\n')
    assert _function_lengths(probe) == {"probe.py::A.f": 4}


def test_no_solver_function_is_longer_than_150_lines():
    lengths = {}
    for path in sorted((PACKAGE / "contact").glob("*.py")):
        lengths |= _function_lengths(path)
    assert len(lengths) > 200  # the reader found the solver
    long = {name: n for name, n in lengths.items() if n > MAX_SOLVER_FUNCTION_LINES}
    assert long == {}, f"split these into named steps (at most {MAX_SOLVER_FUNCTION_LINES})"


def test_every_step_of_the_cg_iteration_fits_80_lines():
    lengths = _function_lengths(PACKAGE / "contact" / "cg_iteration.py")
    assert "cg_iteration.py::CGIteration.run" in lengths
    long = {name: n for name, n in lengths.items() if n > MAX_CG_STEP_LINES}
    assert long == {}, f"the iteration's steps stay at most {MAX_CG_STEP_LINES} lines"


def _compiled_functions(tree: ast.Module) -> list[ast.FunctionDef]:
    """The functions of a module decorated by numba (``@numba.njit(...)``, ``@njit``...)."""

    def is_numba(decorator) -> bool:
        target = decorator.func if isinstance(decorator, ast.Call) else decorator
        return "numba" in ast.unparse(target) or ast.unparse(target) in {"njit", "jit"}

    return [
        node
        for node in tree.body
        if isinstance(node, ast.FunctionDef) and any(map(is_numba, node.decorator_list))
    ]


def _names_imported_from_amontons(tree: ast.Module) -> set[str]:
    """The names a module binds by importing from amontons (relative imports are amontons'):
    the name or its alias, a module's alias included (``from . import fft as _fft``)."""
    bound = set()
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and (
            node.level or (node.module or "").startswith("amontons")
        ):
            bound |= {alias.asname or alias.name for alias in node.names}
        elif isinstance(node, ast.Import):
            bound |= {
                alias.asname or alias.name.split(".")[0]
                for alias in node.names
                if alias.name.startswith("amontons")
            }
    return bound


def _foreign_names_in_kernels(path: Path) -> list[str]:
    """Names a numba-compiled function of ``path`` reads that its module imported from
    another amontons module (a function, a constant or a module)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    foreign = _names_imported_from_amontons(tree)
    return [
        f"{path.name}:{node.lineno} {func.name} reads {node.id}"
        for func in _compiled_functions(tree)
        for node in ast.walk(func)
        if isinstance(node, ast.Name) and node.id in foreign
    ]


def test_the_kernel_scan_finds_an_imported_helper(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text(
        "import numba\nfrom .other import helper\nfrom . import fft as _fft\n\n"
        "@numba.njit(cache=True)\ndef kernel(x):\n    return helper(x) + _fft.n\n"
    )
    assert _foreign_names_in_kernels(probe) == [
        "probe.py:7 kernel reads helper",
        "probe.py:7 kernel reads _fft",
    ]


def test_no_compiled_kernel_reads_a_name_from_another_module():
    """numba's disk cache checks only the source file of the function it caches: a helper
    or constant imported from another file, changed there, would leave the cached machine
    code stale (numba issue #1833; numba's documentation of ``cache=True``). So each kernel
    module holds every helper and constant its compiled functions read."""
    modules = [p for p in sorted((PACKAGE / "contact").glob("*.py")) if "numba" in p.read_text()]
    assert PACKAGE / "contact" / "kernels.py" in modules
    found = [hit for path in modules for hit in _foreign_names_in_kernels(path)]
    assert found == []


# The plasticity laws' class names: the solver asks a law what it needs (its exact route,
# its bound, its capacity, its appendix start) instead of testing its type (issue 78).
LAW_TYPES = {"PenetrationHardness", "ContactHardening", "PLASTICITY_LAWS"}


def _law_type_tests(tree: ast.AST, name: str) -> list[str]:
    """``isinstance`` calls of a module whose class argument names a plasticity law."""
    found = []
    for node in ast.walk(tree):
        if not (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id == "isinstance"
            and len(node.args) == 2
        ):
            continue
        named = {n.id for n in ast.walk(node.args[1]) if isinstance(n, ast.Name)}
        if named & LAW_TYPES:
            found.append(f"{name}:{node.lineno}")
    return found


def test_the_law_type_scan_finds_a_planted_test():
    tree = ast.parse("if isinstance(law, PenetrationHardness | ContactHardening):\n    pass\n")
    assert _law_type_tests(tree, "probe.py") == ["probe.py:1"]


def test_no_module_tests_a_law_by_its_type_outside_the_laws():
    """Only contact/laws.py (where ``check_law`` validates what a caller passed) may test
    a law's type; the solver and the pipeline ask the law."""
    found = [
        hit
        for path in sorted(PACKAGE.rglob("*.py"))
        if path != PACKAGE / "contact" / "laws.py"
        for hit in _law_type_tests(ast.parse(path.read_text()), str(path.relative_to(PACKAGE)))
    ]
    assert found == []


LONGEST_FUNCTION = 80  # lines, the def's first to its last, its docstring aside


def _docstring_lines(node: ast.AST) -> int:
    body = getattr(node, "body", [])
    first = body[0] if body else None
    is_docstring = (
        isinstance(first, ast.Expr)
        and isinstance(first.value, ast.Constant)
        and isinstance(first.value.value, str)
    )
    return first.end_lineno - first.lineno + 1 if is_docstring else 0


def _says_why_longer(node: ast.AST, lines: list[str]) -> bool:
    """A numba kernel may be longer where a comment above it says why (one fused loop is
    faster than the named steps: docs/contributing.md)."""
    jitted = any("jit" in ast.unparse(d) for d in node.decorator_list)
    top = min([d.lineno for d in node.decorator_list] + [node.lineno])
    above = lines[top - 2] if top >= 2 else ""
    return jitted and above.lstrip().startswith("#") and "longer" in above


def long_functions(source: str, where: str) -> list[str]:
    """'where:line name (n lines)' of every function of ``source`` over LONGEST_FUNCTION."""
    lines = source.splitlines()
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            n = node.end_lineno - node.lineno + 1 - _docstring_lines(node)
            if n > LONGEST_FUNCTION and not _says_why_longer(node, lines):
                found.append(f"{where}:{node.lineno} {node.name} ({n} lines)")
    return found


def test_the_length_check_finds_a_long_function_and_skips_docstrings():
    body = "".join(f"    x{i} = {i}\n" for i in range(LONGEST_FUNCTION))
    assert long_functions(f"def f():\n{body}", "here") == ["here:1 f (81 lines)"]
    docstring = '    """' + "\n" * 30 + '    """\n'
    short = "".join(f"    x{i} = {i}\n" for i in range(LONGEST_FUNCTION - 1))
    assert long_functions(f"def g():\n{docstring}{short}", "here") == []
    kernel = f"# longer: one fused loop\n@numba.njit\ndef k():\n{body}"
    assert long_functions(kernel, "here") == []


def test_no_function_in_the_library_or_the_scripts_is_over_80_lines():
    """A function does one thing; past ~80 lines it is usually two (docs/contributing.md)."""
    files = sorted(PACKAGE.rglob("*.py")) + sorted((REPO / "scripts").glob("*.py"))
    found = [
        hit
        for path in files
        for hit in long_functions(path.read_text(), str(path.relative_to(REPO)))
    ]
    assert found == []


# docs/layout.md's map of the library (its first code block): every package and top-level
# module of src/amontons on it, no module it names missing, and its order the import graph's
# (each entry imports only entries listed below it).
LAYOUT = REPO / "docs" / "layout.md"
MAP_ENTRY = re.compile(r"^(\w+/|\w+\.py)\s")


def map_entries(text: str) -> dict[str, str]:
    """The map's entries in order: entry (``io/`` or ``models.py``) -> its description."""
    block = text.split("```\n")[1]
    entries, current = {}, None
    for line in block.splitlines():
        match = MAP_ENTRY.match(line)
        if match:
            current = match.group(1)
            entries[current] = line[match.end() :]
        elif current is not None:
            entries[current] += " " + line.strip()
    return entries


def _entry_of(module: str) -> str:
    """The map entry of an amontons module: ``amontons.io.tiff`` -> ``io/``."""
    part = module.split(".")[1]
    return f"{part}/" if (PACKAGE / part).is_dir() else f"{part}.py"


def _entry_imports() -> dict[str, set[str]]:
    """Map entry -> the other entries its modules import (the graph above)."""
    graph: dict[str, set[str]] = {}
    for module, names in IMPORTS.items():
        if module == "amontons":
            continue
        source = _entry_of(module)
        targets = {_entry_of(n) for n in names if n.startswith("amontons.")}
        graph.setdefault(source, set()).update(targets - {source})
    return graph


ENTRIES = map_entries(LAYOUT.read_text())


def test_the_map_is_read():
    assert list(ENTRIES)[:2] == ["check.py", "workflow/"]
    assert "models.py" in ENTRIES and "area.py" in ENTRIES["measure/"]


def test_the_map_lists_every_package_and_top_level_module():
    present = {
        f"{p.name}/" if p.is_dir() else p.name
        for p in PACKAGE.iterdir()
        if (p.is_dir() and (p / "__init__.py").exists())
        or (p.suffix == ".py" and p.name != "__init__.py")
    }
    assert set(ENTRIES) == present


def test_every_module_the_map_names_exists():
    for entry, text in ENTRIES.items():
        if entry.endswith("/"):
            for name in re.findall(r"\b(\w+\.py)\b", text):
                assert (PACKAGE / entry / name).exists(), f"{entry}{name}"


def test_every_measurement_module_is_on_the_map():
    named = set(re.findall(r"\b(\w+\.py)\b", ENTRIES["measure/"]))
    present = {p.name for p in (PACKAGE / "measure").glob("*.py") if p.name != "__init__.py"}
    assert named == present


def test_each_entry_imports_only_entries_below_it():
    order = list(ENTRIES)
    upward = [
        (source, target)
        for source, targets in _entry_imports().items()
        for target in targets
        if order.index(target) <= order.index(source)
    ]
    assert upward == []
