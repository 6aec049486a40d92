"""Configuration and sample-sheet validation: bad input fails with a message that names the key,
the value and what was allowed."""

import copy
import re

import pytest
import yaml

from amontons import models
from amontons.config import (
    RESERVED_NAMES,
    ConfigError,
    check_selected_materials,
    merge_config,
    parse_loads_mn,
    read_config,
    read_sample_sheet,
    validate,
)
from amontons.io.export_map import ExportMap
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES
from amontons.workflow.run import WorkflowRun, load_workflow_config


def _config(repo, name="config.yaml"):
    """The configuration a run of ``name`` sees: config.yaml, with test.yaml merged over it."""
    overlays = [] if name == "config.yaml" else [repo / "config" / name]
    return read_config(repo / "config" / "config.yaml", *overlays)


@pytest.mark.parametrize("name", ["config.yaml", "test.yaml", "chain.yaml"])
def test_shipped_configs_are_valid(repo, config_schema, sheet_schema, name, monkeypatch):
    monkeypatch.chdir(repo)
    config = _config(repo, name)
    spheres = load_workflow_config(config, config_schema, sheet_schema, name)
    assert {row["material"] for row in spheres.values()} == set(config["materials"])


def test_the_chain_lab_makes_each_model_apart_from_its_scans_prior(
    repo, config_schema, sheet_schema, monkeypatch
):
    """config/chain.yaml's virtual lab (docs/study.md §7): two spheres of each model solved on
    a grid, each plastic truth's value away from the prior its scan is centred on."""
    monkeypatch.chdir(repo)
    records = load_workflow_config(
        _config(repo, "chain.yaml"), config_schema, sheet_schema, "chain.yaml"
    )
    truths = [(r.get("true_model"), r.get("true_value")) for r in records.values()]
    assert sorted(m for m, _ in truths) == sorted(list(models.field_model_names()) * 2)
    for record in records.values():
        parameter = models.model_named(record["true_model"]).parameter
        if parameter is not None:
            assert record["true_value"] != record[parameter.sheet_column]


def test_test_config_is_an_overlay_of_only_the_keys_it_changes(repo):
    """config/test.yaml holds only what differs from config/config.yaml (Snakemake merges it
    over the full config): no key is repeated with the full config's value."""

    def leaves(mapping, prefix=""):
        out = {}
        for key, value in mapping.items():
            if isinstance(value, dict):
                out |= leaves(value, prefix + key + ".")
            else:
                out[prefix + key] = value
        return out

    full = leaves(_config(repo))
    with open(repo / "config" / "test.yaml") as stream:
        overlay = leaves(yaml.safe_load(stream))
    # a section the small run turns off (rheometer_export: null, our own CSV) is a key too
    sections = {key.rsplit(".", 1)[0] for key in full if "." in key}
    sections |= {key.split(".", 1)[0] for key in full}
    assert set(overlay) <= set(full) | sections
    assert [key for key, value in overlay.items() if full.get(key, ...) == value] == []
    assert overlay["run"] != full["run"]


def test_merged_config_replaces_values_and_lists_and_merges_sections():
    base = {"a": 1, "s": {"x": 1, "y": [1, 2]}, "l": [1]}
    merged = merge_config(base, {"s": {"y": [3]}, "l": [2, 3]})
    assert merged == {"a": 1, "s": {"x": 1, "y": [3]}, "l": [2, 3]}
    assert base["s"]["y"] == [1, 2]  # the base is not changed


def test_misspelled_key_is_named_with_the_allowed_keys(repo, config_schema):
    config = _config(repo)
    config["optics"]["otsu_bin"] = config["optics"].pop("otsu_bins")
    with pytest.raises(ConfigError) as info:
        validate(config, config_schema, "my.yaml")
    message = str(info.value)
    assert "my.yaml" in message
    assert "'otsu_bin'" in message and "optics" in message
    assert (
        "allowed keys: absorbance, images, intensity, lifetime, min_contrast, min_patch_px, "
        "min_separation, newton_rings, otsu_bins" in message
    )


def test_unknown_top_level_key(repo, config_schema):
    config = _config(repo)
    config["virtual_experment"] = {}
    with pytest.raises(
        ConfigError, match="'virtual_experment'.*allowed keys: accuracy, friction, load_area"
    ):
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


def test_line_levelling_takes_yaml_on_and_off_and_names_a_wrong_mode(repo, config_schema):
    """YAML reads an unquoted on/off as true/false: both spellings pass the schema; any other
    value is refused naming the key and the allowed values."""
    config = _config(repo)
    for text in ("auto", "on", "off", "'off'"):
        config["surface"]["line_levelling"] = yaml.safe_load(f"v: {text}")["v"]
        validate(config, config_schema, "my.yaml")
    config["surface"]["line_levelling"] = "always"
    with pytest.raises(ConfigError, match=r"surface\.line_levelling = 'always'.*'auto', 'on'"):
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
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "true", "25,50,100", "200", "synthetic"]])
    text = sheet.read_text().replace("data_source\n", "data_source\tcolour\n")
    sheet.write_text(text.replace("synthetic\n", "synthetic\tred\n"))
    with pytest.raises(ConfigError, match="'colour'"):
        read_sample_sheet(sheet, sheet_schema)


def test_sheet_with_duplicate_sphere_ids(tmp_path, sheet_schema):
    sheet = tmp_path / "materials.tsv"
    row = ["PS", "PS", "0.6", "3.7", "true", "25,50,100", "200", "synthetic"]
    _write_sheet(sheet, [row, copy.copy(row)])
    with pytest.raises(ConfigError, match="unique; repeated: PS"):
        read_sample_sheet(sheet, sheet_schema)


def test_every_schema_key_is_described_and_closed(config_schema, sheet_schema):
    def walk(node, where):
        if node.get("type") == "object":
            extra = node.get("additionalProperties")
            # a mapping of named entries (scenes) is closed by the schema of each entry
            if isinstance(extra, dict):
                assert extra.get("description"), f"{where}.* has no description"
                walk(extra, f"{where}.*")
                return
            assert extra is False, f"{where} is open"
            for key, child in node.get("properties", {}).items():
                assert child.get("description"), f"{where}.{key} has no description"
                walk(child, f"{where}.{key}")

    walk(config_schema, "config")
    walk(sheet_schema, "sheet")


def test_material_named_like_a_workflow_target_is_refused(tmp_path, sheet_schema):
    # `snakemake optics` must stay the optics stage: a material 'optics' would be a second
    # rule of that name.
    sheet = tmp_path / "materials.tsv"
    _write_sheet(
        sheet, [["optics", "optics", "0.6", "3.7", "true", "25,50,100", "200", "synthetic"]]
    )
    records = read_sample_sheet(sheet, sheet_schema)
    with pytest.raises(ConfigError, match=r"'optics' take the name of a workflow target"):
        check_selected_materials(["optics"], records, "my.yaml")


def test_reserved_names_are_the_workflow_targets(repo):
    """Every wildcard-free target rule of the workflow is reserved (read from the rule files)."""
    rules = "\n".join(p.read_text() for p in (repo / "workflow" / "rules").glob("*.smk"))
    rules += (repo / "Snakefile").read_text()
    targets = set(re.findall(r"^rule (\w+):\n(?:    .*\n)*?    localrule: True", rules, re.M))
    assert targets and targets <= RESERVED_NAMES


def test_reflection_load_must_be_one_of_the_sphere_loads(tmp_path, sheet_schema):
    sheet = tmp_path / "materials.tsv"
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "true", "50,100,200", "200", "synthetic"]])
    with pytest.raises(ConfigError, match=r"sphere PS: reflection_load_mn = 25 is not one of"):
        read_sample_sheet(sheet, sheet_schema)


def test_sheet_values_take_their_schema_types(tmp_path, sheet_schema):
    sheet = tmp_path / "materials.tsv"
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "yes", "25,50,100", "200", "synthetic"]])
    (record,) = read_sample_sheet(sheet, sheet_schema).values()
    assert record["diameter_mm"] == 0.6 and record["roughened"] is True
    assert record["loads"] == [25.0, 50.0, 100.0] and "flim_load_mn" not in record


def test_reference_load_must_be_a_load_of_every_sphere(
    repo, config_schema, sheet_schema, monkeypatch
):
    """A reference load no sphere was measured at stops the run before any job, in mN, naming
    the key and the sphere (it used to surface only in the last figure, in N)."""
    monkeypatch.chdir(repo)
    config = _config(repo, "test.yaml")
    config["load_area"]["reference_load_mn"] = 10.0
    with pytest.raises(
        ConfigError, match=r"load_area\.reference_load_mn = 10 mN is not one of sphere PS's loads"
    ):
        load_workflow_config(config, config_schema, sheet_schema, "my.yaml")


def test_a_sphere_needs_three_loads_for_its_power_laws(tmp_path, sheet_schema):
    sheet = tmp_path / "materials.tsv"
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "true", "25,50", "200", "synthetic"]])
    with pytest.raises(ConfigError, match=r"sphere PS: loads_mn = '25,50' holds 2 load\(s\)"):
        read_sample_sheet(sheet, sheet_schema)


def _scene_config(repo, edit):
    config = _config(repo, "test.yaml")
    edit(config["scenes"])
    return config


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (
            lambda s: s["elastic"].update(model="plastic"),
            r"scenes\.elastic\.model = 'plastic' is not allowed",
        ),
        (
            lambda s: s["penetration_hardness"].update(p_y_mpa=0.0),
            r"scenes\.penetration_hardness\.p_y_mpa = 0\.0",
        ),
        (
            lambda s: s["penetration_hardness"].update(p_y_mpa=-5.0),
            r"scenes\.penetration_hardness\.p_y_mpa = -5\.0",
        ),
        (
            lambda s: s["elastic"].update(
                surface="synthetic",
                loads=[1.0, 2.0, 4.0],
                synthetic={"hurst": 0.8, "rms_slope": 0.1, "seed": 1, "e_star_gpa": 3.0},
                geometry="flat_periodic",
                side_px=128,
            ),
            r"scene elastic: optics = 'microscope' on a synthetic surface",
        ),
        (
            lambda s: s["hardening"].update(window_factor=0.8),
            r"scene hardening: the solver window \(window_factor\) is .* µm, smaller than sphere "
            r"PS's Hertz contact diameter",
        ),
        (
            lambda s: s["elastic"].update(side_px=64, pixel_nm=256.0),
            r"scene elastic: the solver window \(side_px\) is 16\.4 µm, smaller",
        ),
        (
            lambda s: s["greenwood_tripp"].update(optics="microscope"),
            r"scene greenwood_tripp: optics = 'microscope' with model greenwood_tripp",
        ),
        (
            lambda s: s["hardening"].update(increment="volume_conserving"),
            r"scene hardening: increment = 'volume_conserving' with alpha = 1",
        ),
    ],
)
def test_bad_scenes_stop_before_any_job_naming_scene_and_key(
    repo, config_schema, sheet_schema, monkeypatch, edit, expected
):
    monkeypatch.chdir(repo)
    config = _scene_config(repo, edit)
    with pytest.raises(ConfigError, match=expected):
        load_workflow_config(config, config_schema, sheet_schema, "my.yaml")


def test_a_scene_without_its_model_parameter_anywhere_is_left_out_naming_the_sphere(
    repo, config_schema, sheet_schema, monkeypatch, tmp_path
):
    """Issue 36 turned this stop into a skip: a sphere without the sheet value a scene takes
    (hardness_mpa here) runs every other scene, and the run says which scene it does not get,
    naming the key and the column (the message the stop gave). Its scans run over the
    prior-free range (tests/workflow_dag/test_scenes.py)."""
    monkeypatch.chdir(repo)
    sheet = (repo / "config" / "materials.tsv").read_text().splitlines()
    column = sheet[0].split("\t").index("hardness_mpa")
    rows = [line.split("\t") for line in sheet]
    for row in rows[1:]:
        row[column] = ""
    path = tmp_path / "materials.tsv"
    path.write_text("\n".join("\t".join(row) for row in rows) + "\n")
    config = _config(repo, "test.yaml")
    config["materials_sheet"] = str(path)
    load_workflow_config(config, config_schema, sheet_schema, "my.yaml")
    run = WorkflowRun.from_config(config, repo / "workflow", "my.yaml")
    assert (
        "sphere PS (PS): no hardness_mpa in the sheet: scene penetration_hardness (p_y_mpa "
        "null, at the sheet's value) will not be made"
    ) in run.left_out()
    assert "penetration_hardness" not in run.scenes.runnable("PS")
    assert "hardening" in run.scenes.runnable("PS")


def test_run_scenes_must_name_defined_scenes(repo, config_schema, sheet_schema, monkeypatch):
    monkeypatch.chdir(repo)
    config = _config(repo, "test.yaml")
    config["run_scenes"] = ["elastic", "plastic"]
    with pytest.raises(ConfigError, match=r"run_scenes names 'plastic', not in scenes"):
        load_workflow_config(config, config_schema, sheet_schema, "my.yaml")


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (
            lambda c: c.update(run_scans=["k", "q"]),
            r"run_scans names 'q', not in scans",
        ),
        (
            lambda c: c.update(run_scenes=["elastic", "hardening", "greenwood_tripp"]),
            r"scan p_y: scene 'penetration_hardness' is not in run_scenes",
        ),
        (
            lambda c: c["scans"]["k"].update(scene="penetration_hardness"),
            r"scan k: parameter k_mpa_per_nm belongs to model hardening, but base scene "
            r"penetration_hardness has model penetration_hardness",
        ),
        (
            lambda c: c["scenes"]["hardening"].update(optics="none"),
            r"scan k: base scene hardening has optics = 'none'; expected 'microscope'",
        ),
        (
            lambda c: c["scans"]["p_y"].update(range_factor=[2.0, 0.5]),
            r"scan p_y: range_factor = \[2, 0\.5\]; expected low < high",
        ),
        (
            lambda c: c["scans"]["p_y"].update(parameter="hurst"),
            r"scans\.p_y\.parameter = 'hurst' is not allowed",
        ),
        (
            lambda c: c["study"].update(run_curvature_pairs=["elastic", "plastic"]),
            r"study\.run_curvature_pairs names 'plastic', not in study\.curvature_pairs",
        ),
        (
            lambda c: c["study"]["curvature_pairs"].update(
                elastic=["curved_elastic", "flat_elastic"]
            ),
            r"study\.curvature_pairs\.elastic: scene curved_elastic has surface synthetic and "
            r"geometry sphere; expected a synthetic flat_periodic scene",
        ),
        (
            lambda c: c["study"]["curvature_pairs"].update(
                elastic=["flat_elastic", "curved_hardening"]
            ),
            r"study\.curvature_pairs\.elastic: scenes flat_elastic and curved_hardening have "
            r"models \['elastic', 'hardening'\]",
        ),
    ],
)
def test_bad_scans_and_study_pairs_stop_before_any_job(
    repo, config_schema, sheet_schema, monkeypatch, edit, expected
):
    monkeypatch.chdir(repo)
    config = _config(repo, "test.yaml")
    edit(config)
    with pytest.raises(ConfigError, match=expected):
        load_workflow_config(config, config_schema, sheet_schema, "my.yaml")


def test_scenes_take_their_preset_where_they_give_no_solver_key(
    repo, config_schema, sheet_schema, monkeypatch
):
    """docs/accuracy.md, "Presets": a scene's own key wins, then its preset, then
    solver_preset; the small data set runs draft."""
    monkeypatch.chdir(repo)
    config = _config(repo, "test.yaml")
    config["scenes"]["hardening"]["preset"] = "publication"
    config["scenes"]["elastic"]["tol"] = 1e-9
    load_workflow_config(config, config_schema, sheet_schema, "my.yaml")
    presets = config["solver_presets"]
    assert config["solver_preset"] == "draft"
    hardening, elastic = config["scenes"]["hardening"], config["scenes"]["elastic"]
    assert {k: hardening[k] for k in presets["publication"]} == presets["publication"]
    assert elastic["tol"] == 1e-9
    assert elastic["pixel_nm"] == presets["draft"]["pixel_nm"]
    assert elastic["preset"] == "draft"


def test_an_unknown_preset_is_refused_naming_the_scene(
    repo, config_schema, sheet_schema, monkeypatch
):
    monkeypatch.chdir(repo)
    config = _config(repo)
    config["scenes"]["elastic"]["preset"] = "fastest"
    with pytest.raises(
        ConfigError, match=r"scene elastic: preset 'fastest' is not in solver_presets"
    ):
        load_workflow_config(config, config_schema, sheet_schema, "my.yaml")


def test_the_accuracy_sphere_must_be_selected(repo, config_schema, sheet_schema, monkeypatch):
    monkeypatch.chdir(repo)
    config = _config(repo, "test.yaml")
    config["accuracy"]["sphere"] = "PTFE"
    with pytest.raises(
        ConfigError, match=r"accuracy.sphere = 'PTFE' is not a sphere of the selected"
    ):
        load_workflow_config(config, config_schema, sheet_schema, "my.yaml")


def test_the_full_runs_rheometer_map_reads_the_exports_its_virtual_rheometer_writes(repo):
    """The full run writes its rheometer files in an export shape and reads them through
    config rheometer_export, as a lab would: the two must name the same columns and units."""
    config = _config(repo)
    shape = config["virtual_experiment"]["formats"]["rheometer"]
    assert shape in EXPORT_SHAPES
    assert ExportMap.from_config(config["rheometer_export"]) == ExportMap.from_config(
        EXPORT_SHAPES[shape].column_map()
    )


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("frames", "median", r"optics\.images\.frames = 'median'"),
        ("frames", -1, r"optics\.images\.frames = -1"),
        ("channel", -1, r"optics\.images\.channel = -1"),
        ("series", "first", r"optics\.images\.series = 'first'"),
    ],
)
def test_a_bad_image_choice_is_refused_naming_the_key(repo, config_schema, key, value, message):
    config = _config(repo)
    for good in ("fluorescence", 2, None):
        config["optics"]["images"]["channel"] = good
        validate(config, config_schema, "my.yaml")
    config["optics"]["images"][key] = value
    with pytest.raises(ConfigError, match=message):
        validate(config, config_schema, "my.yaml")


def test_the_sheet_pixel_may_be_left_to_measured_images_but_not_to_the_virtual_experiment(
    tmp_path, sheet_schema
):
    sheet = tmp_path / "materials.tsv"
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "true", "25,50,100", "", "lab/PS"]])
    assert "fluorescence_pixel_nm" not in read_sample_sheet(sheet, sheet_schema)["PS"]
    _write_sheet(sheet, [["PS", "PS", "0.6", "3.7", "true", "25,50,100", "", "synthetic"]])
    with pytest.raises(ConfigError, match="'fluorescence_pixel_nm' is a required property"):
        read_sample_sheet(sheet, sheet_schema)
