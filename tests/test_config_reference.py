"""Each config key and sample-sheet column is described in one place, its schema's
``description`` (workflow/schemas/); config/README.md's key and column tables are generated from
it (amontons.config.reference), and config/config.yaml's comments say why, not what."""

import copy
import shutil
from pathlib import Path

import pytest
import yaml

from amontons.config.reference import (
    CONFIG_SCHEMA,
    README,
    SHEET_SCHEMA,
    column_table,
    generated,
    key_table,
    main,
    row_key,
    rows,
    tables,
    with_tables,
)
from amontons.config.schema import load_schema
from amontons.models import model_names

REPO = Path(__file__).resolve().parents[1]
STALE = "config/README.md's table is not the schema's: python -m amontons.config.reference --write"


@pytest.fixture(scope="module")
def config_schema():
    return load_schema(REPO / CONFIG_SCHEMA)


@pytest.fixture(scope="module")
def sheet_schema():
    return load_schema(REPO / SHEET_SCHEMA)


@pytest.fixture(scope="module")
def readme():
    return (REPO / README).read_text(encoding="utf-8")


def _keys(value, parts=()):
    """The path of every mapping key in ``value`` at any depth (list items by index)."""
    if isinstance(value, dict):
        for key, child in value.items():
            yield (*parts, key)
            yield from _keys(child, (*parts, key))
    elif isinstance(value, list):
        for index, child in enumerate(value):
            yield from _keys(child, (*parts, index))


def _with_description(schema, path, text):
    edited = copy.deepcopy(schema)
    node = edited
    for key in path:
        node = node["properties"][key]
    node["description"] = text
    return edited


def test_the_readmes_tables_are_rendered_from_the_schemas(config_schema, sheet_schema, readme):
    assert generated(readme, CONFIG_SCHEMA) == key_table(config_schema), STALE
    assert generated(readme, SHEET_SCHEMA) == column_table(sheet_schema), STALE
    assert tables(REPO) == {
        CONFIG_SCHEMA: key_table(config_schema),
        SHEET_SCHEMA: column_table(sheet_schema),
    }


def test_a_description_edited_in_the_schema_only_is_caught(config_schema, sheet_schema, readme):
    edited = _with_description(config_schema, ["optics", "otsu_bins"], "Bins, planted")
    assert "| `optics.otsu_bins` | Bins, planted |" in key_table(edited)
    assert generated(readme, CONFIG_SCHEMA) != key_table(edited)
    edited = _with_description(sheet_schema, ["diameter_mm"], "Diameter, planted")
    assert generated(readme, SHEET_SCHEMA) != column_table(edited)


def test_a_row_edited_in_the_readme_only_is_caught(config_schema, sheet_schema, readme):
    row = next(r for r in rows(config_schema) if r.key == "seed")
    planted = readme.replace(f"| `seed` | {row.description} |", "| `seed` | planted |")
    assert planted != readme
    assert generated(planted, CONFIG_SCHEMA) != key_table(config_schema)
    assert generated(planted, SHEET_SCHEMA) == column_table(sheet_schema)


def test_the_cli_checks_and_rewrites_only_the_tables(tmp_path, readme):
    for path in (CONFIG_SCHEMA, SHEET_SCHEMA, README):
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(REPO / path, tmp_path / path)
    assert main(["--check", "--root", str(tmp_path)]) == 0
    schema_file = tmp_path / CONFIG_SCHEMA
    text = schema_file.read_text(encoding="utf-8")
    planted = "Histogram bins for Otsu's threshold (planted)"
    schema_file.write_text(text.replace("Histogram bins for Otsu's threshold", planted))
    assert main(["--check", "--root", str(tmp_path)]) == 1
    assert main(["--write", "--root", str(tmp_path)]) == 0
    written = (tmp_path / README).read_text(encoding="utf-8")
    assert f"| `optics.otsu_bins` | {planted} |" in written
    assert main(["--check", "--root", str(tmp_path)]) == 0
    # the prose around the tables stays
    outside = readme.split("| key | meaning |")[0], readme.split("## Raw-data layout")[1]
    assert all(part in written for part in outside)


def test_the_tables_stay_between_their_markers(config_schema, sheet_schema, readme):
    assert with_tables(readme, tables(REPO)) == readme
    with pytest.raises(ValueError, match="no table between"):
        generated("no markers here", CONFIG_SCHEMA)


def test_every_key_of_the_shipped_configs_has_a_row(config_schema):
    described = {row.key for row in rows(config_schema)}
    missing = []
    for name in ("config.yaml", "test.yaml"):
        with open(REPO / "config" / name, encoding="utf-8") as stream:
            config = yaml.safe_load(stream)
        missing += [
            f"config/{name}: {'.'.join(map(str, parts))}"
            for parts in _keys(config)
            if row_key(config_schema, parts) not in described
        ]
    assert missing == []


def test_a_config_key_maps_to_its_row(config_schema):
    assert row_key(config_schema, ["seed"]) == "seed"
    assert row_key(config_schema, ["scenes", "elastic", "model"]) == "scenes.<name>.model"
    assert (
        row_key(config_schema, ["scenes", "flat", "synthetic", "hurst"])
        == "scenes.<name>.synthetic.hurst"
    )
    assert row_key(config_schema, ["accuracy", "grid", 0, "tol"]) == "accuracy.grid[].tol"
    assert (
        row_key(config_schema, ["accuracy", "preset_budgets", "draft", "rendered_area"])
        == "accuracy.preset_budgets.<preset>.<measure>"
    )
    assert (
        row_key(config_schema, ["optics", "images", "load_series", "planes"])
        == "optics.images.load_series.planes"
    )
    # a value the schema leaves free is described by its own row
    assert row_key(config_schema, ["rheometer_export", "columns", "time"]) == "rheometer_export"
    with pytest.raises(KeyError, match="optics.otsu_bin"):
        row_key(config_schema, ["optics", "otsu_bin"])


def test_every_column_of_the_sample_sheet_has_a_row(sheet_schema):
    header = (REPO / "config" / "materials.tsv").read_text(encoding="utf-8").splitlines()[0]
    described = {row.key for row in rows(sheet_schema)}
    assert [column for column in header.split("\t") if column not in described] == []


def test_every_key_has_a_description_and_the_models_are_named(config_schema):
    assert all(row.description for row in rows(config_schema))
    model = next(r for r in rows(config_schema) if r.key == "scenes.<name>.model")
    assert all(f"`{name}`" in model.description for name in model_names())
    bare = copy.deepcopy(config_schema)
    del bare["properties"]["seed"]["description"]
    with pytest.raises(ValueError, match="seed: the schema gives no description"):
        rows(bare)


def test_a_cell_escapes_what_markdown_would_read(config_schema, sheet_schema):
    table = key_table(config_schema)
    assert "| `scenes.<name>.synthetic.e_star_gpa` | Contact modulus E\\*, GPa |" in table
    assert "k·\\|h_pl\\|" in column_table(sheet_schema)
    # a table row has exactly its two cells
    for line in table.splitlines() + column_table(sheet_schema).splitlines():
        assert line.replace("\\|", "").count("|") == 3, line
