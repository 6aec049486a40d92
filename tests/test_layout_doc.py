"""docs/layout.md's map of the library matches the code: it lists every package and top-level
module of src/amontons, names no module that does not exist, and its order is the import
graph's (each entry imports only entries listed below it)."""

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "src" / "amontons"
LAYOUT = REPO / "docs" / "layout.md"

ENTRY = re.compile(r"^(\w+/|\w+\.py)\s")


def map_entries(text: str) -> dict[str, str]:
    """The map's entries in order: entry (``io/`` or ``models.py``) -> its description."""
    block = text.split("```\n")[1]
    entries, current = {}, None
    for line in block.splitlines():
        match = ENTRY.match(line)
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


def _package_imports() -> dict[str, set[str]]:
    """Map entry -> the entries it imports (at any depth of the file)."""
    graph: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        module = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if module.endswith("__init__") and module.count(".") == 1:
            continue
        source = _entry_of(module)
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
                names = [node.module]
                if node.module == "amontons":
                    names = [f"amontons.{a.name}" for a in node.names]
            for name in names:
                if name.startswith("amontons.") and _entry_of(name) != source:
                    graph.setdefault(source, set()).add(_entry_of(name))
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
        for source, targets in _package_imports().items()
        for target in targets
        if order.index(target) <= order.index(source)
    ]
    assert upward == []
