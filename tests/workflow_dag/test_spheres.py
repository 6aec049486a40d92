"""The selected spheres as the DAG reads them: where their raw files lie and which they are."""

import pytest

from amontons.workflow.paths import RunPaths
from amontons.workflow.spheres import Spheres, names_pattern

RECORD = {
    "material": "PS",
    "loads": [10.0, 20.0, 40.0],
    "fluorescence_pixel_nm": 200,
    "reflection_load_mn": 20.0,
    "diameter_mm": 0.6,
    "e_star_gpa": 3.7,
}


def _spheres(tmp_path, **measured_files):
    """One synthetic sphere and one measured sphere whose folder holds ``measured_files``
    (relative path -> text)."""
    folder = tmp_path / "lab"
    for name, text in measured_files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    records = {
        "syn": {**RECORD, "data_source": "synthetic", "flim_load_mn": 20.0},
        "lab": {**RECORD, "data_source": str(folder)},
    }
    return Spheres(records, RunPaths("small")), folder


def test_synthetic_raw_data_lie_in_the_runs_virtual_experiment(tmp_path):
    spheres, folder = _spheres(tmp_path)
    assert spheres.raw_dir("syn") == "resources/synthetic/small/syn"
    assert spheres.raw_dir("lab") == str(folder)
    assert spheres.per_load_inputs("syn", "fluorescence") == (
        "resources/synthetic/small/syn/fluorescence"
    )


def test_measured_images_are_matched_to_the_sheet_loads(tmp_path):
    images = {f"fluorescence/{load}mN.tif": "" for load in (10, 20, 40)}
    spheres, folder = _spheres(tmp_path, **images)
    found = spheres.per_load_inputs("lab", "fluorescence")
    assert found == [str(folder / f"fluorescence/{load}mN.tif") for load in (10, 20, 40)]
    assert spheres.reflection_fluorescence("lab") == found[1]


def test_an_afm_map_is_named_by_the_format_present_else_by_its_tiff(tmp_path):
    spheres, folder = _spheres(tmp_path, **{"afm_before.npy": ""})
    assert spheres.afm_path("lab", "afm_before") == str(folder / "afm_before.npy")
    assert spheres.afm_path("lab", "afm_after") == f"{folder}/afm_after.tif"


def test_flim_where_the_sheet_asks_or_the_folder_holds_it(tmp_path):
    spheres, _ = _spheres(tmp_path)
    assert spheres.has_flim("syn") and not spheres.has_flim("lab")
    assert spheres.synthetic_pattern(with_flim=True) == "syn"
    assert spheres.synthetic_pattern(with_flim=False) == "(?!)"
    with_map, _ = _spheres(tmp_path / "2", **{"flim.tif": ""})
    assert with_map.has_flim("lab")


def test_data_label_says_synthetic_if_any_sphere_is(tmp_path):
    spheres, _ = _spheres(tmp_path)
    assert spheres.data_label(["syn", "lab"]) == "synthetic data"
    assert spheres.data_label(["lab"]) == "measured data"


@pytest.mark.parametrize(("names", "matches"), [(["a.b", "c"], "a.b|c"), ([], "(?!)")])
def test_names_pattern_escapes_and_never_matches_empty(names, matches):
    assert names_pattern(names) == matches.replace(".", r"\.")
