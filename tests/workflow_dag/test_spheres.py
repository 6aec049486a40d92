"""The selected spheres as the DAG reads them: where their raw files lie and which they are."""

import numpy as np
import pytest
import tifffile

from amontons.io.confocal_writers import write_confocal
from amontons.io.layout import RawDataError
from amontons.workflow.paths import RunPaths
from amontons.workflow.spheres import (
    ABSORBANCE,
    AFM_AFTER,
    AFM_BEFORE,
    BEAD,
    REFLECTION,
    RHEOMETER,
    Spheres,
    names_pattern,
)

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


def _complete_folder(tmp_path) -> dict[str, str]:
    """Every optional file of a measured sphere's folder, as relative path -> text."""
    files = {f"fluorescence/{load}mN.tif": "" for load in (10, 20, 40)}
    files.update({f"rheometer/{load}.csv": "" for load in (10, 20, 40)})
    for name in ("reflection.tif", "bead.tif", "absorbance.csv", "afm_before.tif", "afm_after.npy"):
        files[name] = ""
    return files


@pytest.mark.parametrize(
    ("remove", "kind"),
    [
        ("reflection.tif", REFLECTION),
        ("bead.tif", BEAD),
        ("absorbance.csv", ABSORBANCE),
        ("afm_before.tif", AFM_BEFORE),
        ("afm_after.npy", AFM_AFTER),
    ],
)
def test_a_missing_optional_file_is_found_and_named(tmp_path, remove, kind):
    files = _complete_folder(tmp_path)
    del files[remove]
    spheres, folder = _spheres(tmp_path, **files)
    assert list(spheres.missing("lab")) == [kind]
    assert remove.split(".")[0] in spheres.missing("lab")[kind]
    assert spheres.missing("syn") == {}  # the virtual experiment writes every file
    (line,) = spheres.left_out("lab")
    assert "will not be made" in line


def test_a_sphere_without_rheometer_folder_has_no_friction(tmp_path):
    files = {k: v for k, v in _complete_folder(tmp_path).items() if not k.startswith("rheometer")}
    spheres, _ = _spheres(tmp_path, **files)
    assert list(spheres.missing("lab")) == [RHEOMETER]
    assert spheres.of("PS", having=RHEOMETER) == ["syn"]
    assert spheres.materials_with(["PS"], RHEOMETER) == ["PS"]


def test_a_shared_bead_image_stands_for_the_spheres_own(tmp_path):
    files = _complete_folder(tmp_path)
    del files["bead.tif"]
    spheres, folder = _spheres(tmp_path, **files)
    shared = tmp_path / "shared_bead.tif"
    shared.write_text("")
    spheres.records["lab"]["bead_file"] = str(shared)
    spheres._missing.clear()
    assert spheres.bead_image("lab") == str(shared)
    assert spheres.missing("lab") == {}


def test_without_a_bead_the_psf_is_the_stand_in_or_none(tmp_path):
    files = _complete_folder(tmp_path)
    del files["bead.tif"]
    spheres, _ = _spheres(tmp_path, **files)
    assert spheres.psf_source("lab") is None and not spheres.can_render("lab")
    assert spheres.can_simulate("lab")
    assert "no microscope scene" in spheres.left_out("lab")[0]
    stand_in = Spheres(spheres.records, RunPaths("small"), psf_stand_in=True)
    assert stand_in.psf_source("lab") == "stand_in" and stand_in.can_render("lab")
    assert stand_in.psf_pattern("stand_in") == "lab"
    assert "optics.psf.stand_in" in stand_in.left_out("lab")[0]


def test_confocal_images_are_found_by_any_accepted_suffix(tmp_path):
    files = {"fluorescence/10mN.ome.tif": "", "fluorescence/20.czi": "", "fluorescence/40.tif": ""}
    files |= {"reflection.czi": "", "bead.ome.tif": ""}
    spheres, folder = _spheres(tmp_path, **files)
    assert spheres.per_load_inputs("lab", "fluorescence") == [
        str(folder / name) for name in ("fluorescence/10mN.ome.tif", "fluorescence/20.czi",
                                        "fluorescence/40.tif")
    ]  # fmt: skip
    assert spheres.reflection_image("lab") == str(folder / "reflection.czi")
    assert spheres.bead_image("lab") == str(folder / "bead.ome.tif")
    assert REFLECTION not in spheres.missing("lab") and BEAD not in spheres.missing("lab")


def test_the_virtual_experiments_images_are_named_by_its_format(tmp_path):
    spheres = Spheres({"syn": {**RECORD, "data_source": "synthetic"}}, RunPaths("full"),
                      synthetic_images=".ome.tif")  # fmt: skip
    assert spheres.reflection_image("syn") == "resources/synthetic/full/syn/reflection.ome.tif"
    assert spheres.bead_image("syn") == "resources/synthetic/full/syn/bead.ome.tif"


def test_two_formats_of_one_image_stop_the_run_naming_both(tmp_path):
    spheres, folder = _spheres(tmp_path, **{"reflection.tif": "", "reflection.czi": ""})
    with pytest.raises(RawDataError, match=r"reflection\.tif, reflection\.czi; expected one"):
        spheres.reflection_image("lab")


def test_images_without_a_pixel_and_no_sheet_pixel_stop_the_run_naming_sphere_and_file(
    tmp_path,
):
    files = {f"fluorescence/{load}.tif": "" for load in (10, 20, 40)}
    spheres, folder = _spheres(tmp_path, **files)
    untagged = np.ones((8, 8), np.uint16)
    for load in (10, 20):
        write_confocal(folder / f"fluorescence/{load}.tif", untagged, 200e-9, "ome_tiff")
    tifffile.imwrite(folder / "fluorescence/40.tif", untagged)  # no resolution tags
    spheres.check_pixel_sizes()  # the sheet gives the pixel
    del spheres.records["lab"]["fluorescence_pixel_nm"]
    message = rf"no fluorescence_pixel_nm in the sheet: sphere lab: {folder}/fluorescence/40\.tif;"
    with pytest.raises(RawDataError, match=message):
        spheres.check_pixel_sizes()
    write_confocal(folder / "fluorescence/40.tif", untagged, 200e-9, "tif")
    spheres.check_pixel_sizes()  # every image states its own
    assert spheres.image_pixel_inputs("lab") == ["results/small/PS/lab/measure/contact_area.csv"]
    assert spheres.image_pixel_inputs("syn") == []
