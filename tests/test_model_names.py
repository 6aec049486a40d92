"""The contact models' records (amontons.models) hold their names: no model name, parameter
key or sheet column is written as a literal in the package, the scripts or the rules outside
the records (the configs, the docs and the tests may name them). The solver
(amontons.contact) keeps its routes' own names and is not read. docs/contributing.md.

A literal is a string constant (an f-string's text parts included; docstrings are docs) that
names a model by its one-word name (``"hardening"``, ``": hardening"``, ``"hardening model"``;
the same word in prose, "the elastic end", is physics), or in which a compound name or
label appears as a whole token (``"penetration_hardness"``, ``"contact hardening"``,
``"Greenwood–Tripp"``), or a parameter key or sheet column appears at all
(``"best_k_mpa_per_nm"``); but not
``"elastic_displacement"`` or ``"hardening_sphere"`` (another name that begins with a
model's)."""

import ast
import re
from pathlib import Path

import pytest
import yaml

from amontons import models
from amontons.accuracy.timing import plastic_ratio
from amontons.config.scenes import sheet_prior
from amontons.config.schema import load_schema, with_models
from amontons.contact import laws
from amontons.contact.options import resolve_route
from amontons.contact.routes import ROUTES
from amontons.simulate.scan import scene_config_at
from amontons.simulate.scene import scene_for_sphere

REPO = Path(__file__).resolve().parents[1]
RECORDS = REPO / "src" / "amontons" / "models.py"
SOLVER = REPO / "src" / "amontons" / "contact"


def _compound_words() -> set[str]:
    """Names that count as a whole token anywhere in a literal: the models' names and
    labels that are not one plain word (``penetration_hardness``, ``Greenwood–Tripp``)."""
    names = {m.name for m in models.MODELS} | {m.label for m in models.MODELS}
    return {name for name in names if not name.isalpha()}


def _plain_words() -> set[str]:
    """The models' names that are one plain word (``elastic``, ``hardening``): they count
    where a literal names the model by it (the word alone, between punctuation as in
    ``": hardening"``, or as ``"hardening model"``), not in prose ("the elastic end")."""
    return {m.name for m in models.MODELS if m.name.isalpha()}


def _names_by_plain_word(text: str, word: str) -> bool:
    """Whether ``text``, its punctuation and spaces at either end aside, is ``word`` alone or
    ``word`` followed by "model"."""
    return re.fullmatch(rf"[\W_]*{re.escape(word)}(?: model)?[\W_]*", text) is not None


def _inner_words() -> set[str]:
    """Names that count inside a longer token too: the parameters' keys and sheet columns."""
    return {
        name
        for m in models.with_parameter()
        for name in (m.parameter.key, m.parameter.sheet_column)
    }


def named_in(text: str) -> list[str]:
    """The model, label, parameter or sheet-column names ``text`` writes out."""
    found = [word for word in _plain_words() if _names_by_plain_word(text, word)]
    for word in _compound_words():
        if re.search(rf"(?<![\w]){re.escape(word)}(?![\w])", text, flags=re.IGNORECASE):
            found.append(word)
    for word in _inner_words():
        if re.search(rf"(?<![A-Za-z0-9]){re.escape(word)}(?![A-Za-z0-9])", text):
            found.append(word)
    return sorted(found)


def _docstrings(tree: ast.AST) -> set[int]:
    """The ids of the docstring constants of a module, class or function."""
    ids = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                ids.add(id(body[0].value))
    return ids


def python_literals(source: str) -> list[tuple[int, str]]:
    """(line, text) of every string constant of a Python source but its docstrings."""
    tree = ast.parse(source)
    skip = _docstrings(tree)
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip
    ]


_SMK_STRING = re.compile(r"""("(?:[^"\\\n]|\\.)*"|'(?:[^'\\\n]|\\.)*')""")


def rule_literals(source: str) -> list[tuple[int, str]]:
    """(line, text) of every one-line string of a rule file, its comments left out."""
    out = []
    for number, line in enumerate(source.splitlines(), 1):
        code = line.split("#", 1)[0] if not line.lstrip().startswith("#") else ""
        out += [(number, match[1:-1]) for match in _SMK_STRING.findall(code)]
    return out


def _code_files() -> list[Path]:
    files = [p for p in (REPO / "src" / "amontons").rglob("*.py") if SOLVER not in p.parents]
    files += sorted((REPO / "scripts").glob("*.py"))
    files += sorted((REPO / "workflow" / "rules").glob("*.smk")) + [REPO / "Snakefile"]
    return [p for p in files if p != RECORDS]


def literal_names(path: Path) -> list[str]:
    """Each literal of ``path`` that writes out a model's name, as 'path:line: names'."""
    source = path.read_text()
    literals = python_literals(source) if path.suffix == ".py" else rule_literals(source)
    return [
        f"{path.relative_to(REPO)}:{line}: {', '.join(found)}"
        for line, text in literals
        if (found := named_in(text))
    ]


def test_no_model_name_is_written_outside_its_record():
    found = [hit for path in _code_files() for hit in literal_names(path)]
    assert found == [], "model names outside amontons.models:\n" + "\n".join(found)


@pytest.mark.parametrize(
    "planted",
    [
        'MODEL = "hardening"\n',
        'COLUMN = f"best_{x}" if x else "best_k_mpa_per_nm"\n',
        'label = f"{sphere}: Greenwood–Tripp area"\n',
        'rows = {"elastic": [], "x": []}\n',
        'prior = row.get("hardness_mpa")\n',
        'label = f"{sphere}: hardening"\n',
        'row = {"series": "hardening model"}\n',
    ],
)
def test_a_planted_literal_is_found(tmp_path, planted):
    path = tmp_path / "planted.py"
    path.write_text('"""A module whose docstring may say hardening."""\n' + planted)
    assert literal_names_at(path)


def test_a_docstring_or_a_longer_name_is_not_a_literal(tmp_path):
    path = tmp_path / "clean.py"
    path.write_text(
        '"""Contact hardening and penetration_hardness, in words."""\n'
        'FIELD = "elastic_displacement"\nPROBLEM = "hardening_sphere"\n'
        'WHY = "the elastic limit"\nFLOW = "no plastic model improves on the elastic model"\n'
    )
    assert literal_names_at(path) == []


def test_a_rule_files_strings_are_read_and_its_comments_are_not():
    source = (
        'rule a:\n    # the "elastic" scene\n    input:\n        x=lambda wc: f(wc)["elastic"],\n'
    )
    assert [named_in(text) for _, text in rule_literals(source)] == [["elastic"]]


def literal_names_at(path: Path) -> list[str]:
    """:func:`literal_names` of a file anywhere (the planted ones live outside the repo)."""
    literals = python_literals(path.read_text())
    return [f"{line}: {found}" for line, text in literals if (found := named_in(text))]


def _schema_enum(schema: dict, *keys: str) -> list:
    node = schema
    for key in keys:
        node = node[key]
    return node["enum"]


def test_the_schemas_allowed_models_and_parameters_come_from_the_records():
    schema = with_models(load_schema(REPO / "workflow" / "schemas" / "config.schema.yaml"))
    scene = schema["properties"]["scenes"]["additionalProperties"]
    scan = schema["properties"]["scans"]["additionalProperties"]
    assert _schema_enum(scene["properties"], "model") == list(models.model_names())
    assert _schema_enum(scan["properties"], "parameter") == list(models.parameter_keys())
    for key in models.parameter_keys():
        assert key in scene["properties"]


def test_the_shipped_config_runs_every_model_it_names_from_a_record():
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    named = {scene["model"] for scene in config["scenes"].values()}
    assert named <= set(models.model_names())
    assert {scan["parameter"] for scan in config["scans"].values()} <= set(models.parameter_keys())


def test_each_law_and_route_a_record_names_is_the_solvers():
    for model in models.MODELS:
        if model.law is None:
            continue
        law = getattr(laws, model.law)(1.0)
        assert resolve_route(law, None) == model.route
        assert model.route in ROUTES
    assert models.ELASTIC.route in ROUTES


PLANTED = models.ContactModel(
    name="capped_hardness",
    label="capped hardness",
    law="PenetrationHardness",
    route="bounded",
    kind=models.FIELD,
    parameter=models.Parameter(
        key="cap_mpa",
        symbol="p_c",
        unit="MPa",
        to_si=1e6,
        law_field="p_y",
        sheet_column="cap_mpa_prior",
        stem="cap",
        prior_free_scale="p_c/E*",
        prior_free_pixel_power=0,
        chain_order=-1,
        description="A planted cap pressure, MPa",
    ),
    timing_ratio=None,
    verdict_rank=4,
)

PROBE = {
    "surface": "afm_before",
    "geometry": "sphere",
    "model": PLANTED.name,
    "loads": "measured",
    "pixel_nm": 256.0,
    "window_factor": 1.5,
    "side_px": None,
    "max_side_px": 512,
    "tol": 1.0e-6,
    "optics": "none",
    "rendering": "emission",
    "confinement_floor_mpa": 0.0,
    "increment": "local",
    "alpha": 1.0,
}


def test_a_planted_record_is_all_the_pipeline_needs_of_a_new_model(monkeypatch):
    """docs/contributing.md's trace, its pipeline part checked in-process: with one record
    more in MODELS (its law one the solver has), the config
    schema allows the model and its scan parameter, a scene takes the parameter from the
    sheet's column where its own is null and solves with the record's law, a scan sets it,
    and the timing model gives it the elastic count."""
    monkeypatch.setattr(models, "MODELS", (*models.MODELS, PLANTED))
    schema = load_schema(REPO / "workflow" / "schemas" / "config.schema.yaml")
    scene_schema = schema["properties"]["scenes"]["additionalProperties"]
    assert PLANTED.name in scene_schema["properties"]["model"]["enum"]
    assert "cap_mpa" in scene_schema["properties"]
    scan_schema = schema["properties"]["scans"]["additionalProperties"]["properties"]
    assert "cap_mpa" in scan_schema["parameter"]["enum"]
    sheet = load_schema(REPO / "workflow" / "schemas" / "materials.schema.yaml")
    assert "cap_mpa_prior" in sheet["properties"]

    record = {"diameter_mm": 1.0, "e_star_gpa": 3.5, "loads": [10.0, 20.0, 40.0]}
    record["cap_mpa_prior"] = 80.0
    assert sheet_prior({**PROBE, "cap_mpa": None}) == ("cap_mpa", "cap_mpa_prior")
    scene = scene_for_sphere("probe", {**PROBE, "cap_mpa": None}, "PS", record)
    assert isinstance(scene.plasticity, laws.PenetrationHardness)
    assert scene.plasticity.p_y == pytest.approx(80e6, rel=1e-12)
    assert scene.to_record()["cap_mpa"] == pytest.approx(80.0, rel=1e-12)
    assert scene_config_at({**PROBE, "cap_mpa": None}, "cap_mpa", 120.0)["cap_mpa"] == 120.0
    assert plastic_ratio(PLANTED.name, pixel_m=1e-7, e_star_pa=3.5e9, parameter_si=8e7) is None
