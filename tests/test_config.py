"""Configuration and sample-sheet validation: bad input fails with a message that names the key,
the value and what was allowed."""

import copy

import pytest
import yaml

from amontons.config import (
    ConfigError,
    load_workflow_config,
    parse_loads_mn,
    read_sample_sheet,
    validate,
)


def _config(repo, name="config.yaml"):
    with open(repo / "config" / name) as stream:
        return yaml.safe_load(stream)


@pytest.mark.parametrize("name", ["config.yaml", "test.yaml"])
def test_shipped_configs_are_valid(repo, config_schema, sheet_schema, name, monkeypatch):
    monkeypatch.chdir(repo)
    config = _config(repo, name)
    spheres = load_workflow_config(config, config_schema, sheet_schema, name)
    assert set(spheres["material"]) == set(config["materials"])


def test_test_config_has_the_same_keys_as_the_full_config(repo):
    def keys(mapping, prefix=""):
        out = set()
        for key, value in mapping.items():
            out.add(prefix + key)
            if isinstance(value, dict):
                out |= keys(value, prefix + key + ".")
        return out

    assert keys(_config(repo, "test.yaml")) == keys(_config(repo, "config.yaml"))


def test_misspelled_key_is_named_with_the_allowed_keys(repo, config_schema):
    config = _config(repo)
    config["optics"]["otsu_bin"] = config["optics"].pop("otsu_bins")
    with pytest.raises(ConfigError) as info:
        validate(config, config_schema, "my.yaml")
    message = str(info.value)
    assert "my.yaml" in message
    assert "'otsu_bin'" in message and "optics" in message
    assert (
        "allowed keys: absorbance, intensity, lifetime, min_contrast, min_patch_px, "
        "min_separation, newton_rings, otsu_bins" in message
    )


def test_unknown_top_level_key(repo, config_schema):
    config = _config(repo)
    config["virtual_experment"] = {}
    with pytest.raises(ConfigError, match="'virtual_experment'.*allowed keys: friction, load_area"):
        validate(config, config_schema, "my.yaml")


def test_unknown_material_lists_the_allowed_ones(repo, config_schema, sheet_schema, monkeypatch):
    monkeypatch.chdir(repo)
    config = _config(repo)
    config["materials"] = ["PS", "PEEK"]
    with pytest.raises(ConfigError) as info:
        load_workflow_config(config, config_schema, sheet_schema, "my.yaml")
    message = str(info.value)
    assert "materials" in message and "'PEEK'" in message
    assert "allowed values (from the sample sheet): PMMA, PS, PTFE, glass" in message


def test_wrong_type_names_key_value_and_expectation(repo, config_schema):
    config = _config(repo)
    config["virtual_experiment"]["psf_fwhm_nm"] = -450
    with pytest.raises(ConfigError, match=r"virtual_experiment\.psf_fwhm_nm = -450.*Full width"):
        validate(config, config_schema, "my.yaml")


@pytest.mark.parametrize("loads", ["25,50,50,100", "25,100,50", "0,25"])
def test_loads_must_be_positive_and_strictly_increasing(loads):
    with pytest.raises(ConfigError, match="loads_mn"):
        parse_loads_mn(loads, "sheet.tsv, sphere PS")


def test_loads_parse():
    assert parse_loads_mn(" 25, 50,100 ", "here") == [25.0, 50.0, 100.0]


def _write_sheet(path, rows):
    """Sheet with the given rows; every row gets reflection load 25 mN, shear strength 20 MPa,
    roughness 80 nm and k 5 MPa/nm (required columns that these tests do not vary)."""
    header = (
        "sphere\tmaterial\tdiameter_mm\te_star_gpa\troughened\tloads_mn\t"
        "reflection_load_mn\tshear_strength_mpa\troughness_rms_nm\thardening_k_mpa_per_nm\t"
        "fluorescence_pixel_nm\tdata_source\n"
    )
    rows = [[*row[:6], "25", "20", "80", "5", *row[6:]] for row in rows]
    path.write_text(header + "".join("\t".join(row) + "\n" for row in rows))


def test_sheet_with_non_increasing_loads_names_file_and_sphere(tmp_path, sheet_schema):
    sheet = tmp_path / "materials.tsv"
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "true", "50,25", "200", "synthetic"]])
    with pytest.raises(ConfigError, match=r"materials.tsv, sphere PS: loads_mn = '50,25'"):
        read_sample_sheet(sheet, sheet_schema)


def test_sheet_with_unknown_column_names_it(tmp_path, sheet_schema):
    sheet = tmp_path / "materials.tsv"
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "true", "25,50", "200", "synthetic"]])
    text = sheet.read_text().replace("data_source\n", "data_source\tcolour\n")
    sheet.write_text(text.replace("synthetic\n", "synthetic\tred\n"))
    with pytest.raises(ConfigError, match="'colour'"):
        read_sample_sheet(sheet, sheet_schema)


def test_sheet_with_duplicate_sphere_ids(tmp_path, sheet_schema):
    sheet = tmp_path / "materials.tsv"
    row = ["PS", "PS", "0.6", "3.7", "true", "25,50", "200", "synthetic"]
    _write_sheet(sheet, [row, copy.copy(row)])
    with pytest.raises(ConfigError, match="unique; repeated: PS"):
        read_sample_sheet(sheet, sheet_schema)


def test_every_schema_key_is_described_and_closed(config_schema, sheet_schema):
    def walk(node, where):
        if node.get("type") == "object":
            assert node.get("additionalProperties") is False, f"{where} is open"
            for key, child in node.get("properties", {}).items():
                assert child.get("description"), f"{where}.{key} has no description"
                walk(child, f"{where}.{key}")

    walk(config_schema, "config")
    walk(sheet_schema, "sheet")
