"""The shape of the package: which module may import which, and where files are looked up.

The measurement (``amontons.measure``) and the virtual experiment (``amontons.virtual``) are
siblings that share only ``amontons.physics`` and ``amontons.io``: only the tests connect them,
so that the analysis can never use what the generator knows. The import graph is read from
the source with ``ast``, every ``import`` and ``from ... import`` at any depth.
"""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "src" / "amontons"


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every amontons module ``path`` imports (relative imports resolved)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    here = _module_name(path).split(".")
    if path.name != "__init__.py":
        here = here[:-1]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(here[: len(here) - node.level + 1] + ([base] if base else []))
            found.add(base)
            found.update(f"{base}.{alias.name}" for alias in node.names)
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


def test_the_workflow_helpers_import_no_numerical_stack():
    """The Snakefile's helpers (workflow/rules/common.smk) import these two modules; parsing
    the DAG must not pay for numpy, pandas or scipy."""
    code = (
        "import sys, amontons.config, amontons.io.layout; "
        "print(sorted(m for m in ('numpy', 'pandas', 'scipy') if m in sys.modules))"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


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
    measured sphere's files to its loads (amontons.io.layout, at DAG time)."""
    sources = [*sorted((REPO / "scripts").glob("*.py")), *sorted(PACKAGE.rglob("*.py"))]
    allowed = {PACKAGE / "io" / "layout.py"}
    found = [call for path in sources if path not in allowed for call in _folder_lookups(path)]
    assert found == []
