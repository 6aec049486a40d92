"""The selected spheres as the DAG reads them: where their raw files lie and which they are."""

import numpy as np
import ptufile
import pytest
import tifffile

from amontons.config import ConfigError
from amontons.io.confocal_writers import write_confocal
from amontons.io.layout import RawDataError
from amontons.io.tiff import write_image
from amontons.workflow.optional_inputs import (
    ABSORBANCE,
    AFM_AFTER,
    AFM_BEFORE,
    BEAD,
    REFLECTION,
    RHEOMETER,
)
from amontons.workflow.params import image_choice
from amontons.workflow.paths import RunPaths
from amontons.workflow.run import check_rheometer_exports
from amontons.workflow.spheres import Spheres
from amontons.workflow.wildcards import names_pattern

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


def test_the_parts_share_one_sheet_and_spheres_holds_only_the_selection(tmp_path):
    """Spheres composes its parts over one SheetRows, and holds nothing of theirs: beyond
    the parts, only the selection they share (of, materials_with, held_out); the rule files
    and the library ask the parts."""
    spheres, _ = _spheres(tmp_path, **_complete_folder(tmp_path))
    parts = [spheres.series, spheres.files, spheres.pixels, spheres.inputs, spheres.hold_outs]
    assert all(part.rows is spheres.rows for part in parts)
    assert spheres.files.series is spheres.series
    own = {name for name in vars(Spheres) if not name.startswith("_")}
    assert own == {"of", "materials_with", "held_out"}


def test_synthetic_raw_data_lie_in_the_runs_virtual_experiment(tmp_path):
    spheres, folder = _spheres(tmp_path)
    assert spheres.rows.raw_dir("syn") == "resources/synthetic/small/syn"
    assert spheres.rows.raw_dir("lab") == str(folder)
    assert spheres.files.per_load_inputs("syn", "fluorescence") == (
        "resources/synthetic/small/syn/fluorescence"
    )


def test_measured_images_are_matched_to_the_sheet_loads(tmp_path):
    images = {f"fluorescence/{load}mN.tif": "" for load in (10, 20, 40)}
    spheres, folder = _spheres(tmp_path, **images)
    found = spheres.files.per_load_inputs("lab", "fluorescence")
    assert found == [str(folder / f"fluorescence/{load}mN.tif") for load in (10, 20, 40)]
    assert spheres.files.reflection_fluorescence("lab") == found[1]


def test_an_afm_map_is_named_by_the_format_present_else_by_its_tiff(tmp_path):
    spheres, folder = _spheres(tmp_path, **{"afm_before.npy": ""})
    assert spheres.files.afm_path("lab", "afm_before") == str(folder / "afm_before.npy")
    assert spheres.files.afm_path("lab", "afm_after") == f"{folder}/afm_after.tif"


def test_flim_where_the_sheet_asks_or_the_folder_holds_it(tmp_path):
    spheres, _ = _spheres(tmp_path)
    assert spheres.files.has_flim("syn") and not spheres.files.has_flim("lab")
    assert spheres.files.synthetic_pattern(with_flim=True) == "syn"
    assert spheres.files.synthetic_pattern(with_flim=False) == "(?!)"
    with_map, _ = _spheres(tmp_path / "2", **{"flim.tif": ""})
    assert with_map.files.has_flim("lab")


def test_data_label_says_synthetic_if_any_sphere_is(tmp_path):
    spheres, _ = _spheres(tmp_path)
    assert spheres.rows.data_label(["syn", "lab"]) == "synthetic data"
    assert spheres.rows.data_label(["lab"]) == "measured data"


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
    assert list(spheres.inputs.missing("lab")) == [kind]
    assert remove.split(".")[0] in spheres.inputs.missing("lab")[kind]
    assert spheres.inputs.missing("syn") == {}  # the virtual experiment writes every file
    (line,) = spheres.inputs.left_out("lab")
    assert "will not be made" in line


def test_a_sphere_without_rheometer_folder_has_no_friction(tmp_path):
    files = {k: v for k, v in _complete_folder(tmp_path).items() if not k.startswith("rheometer")}
    spheres, _ = _spheres(tmp_path, **files)
    assert list(spheres.inputs.missing("lab")) == [RHEOMETER]
    assert spheres.of("PS", having=RHEOMETER) == ["syn"]
    assert spheres.materials_with(["PS"], RHEOMETER) == ["PS"]


def test_a_shared_bead_image_stands_for_the_spheres_own(tmp_path):
    files = _complete_folder(tmp_path)
    del files["bead.tif"]
    spheres, folder = _spheres(tmp_path, **files)
    shared = tmp_path / "shared_bead.tif"
    shared.write_text("")
    spheres.rows.records["lab"]["bead_file"] = str(shared)
    spheres.inputs._missing.clear()
    assert spheres.files.bead_image("lab") == str(shared)
    assert spheres.inputs.missing("lab") == {}


def test_without_a_bead_the_psf_is_the_stand_in_or_none(tmp_path):
    files = _complete_folder(tmp_path)
    del files["bead.tif"]
    spheres, _ = _spheres(tmp_path, **files)
    assert spheres.inputs.psf_source("lab") is None and not spheres.inputs.can_render("lab")
    assert spheres.inputs.can_simulate("lab")
    assert "no microscope scene" in spheres.inputs.left_out("lab")[0]
    stand_in = Spheres(spheres.rows.records, RunPaths("small"), psf_stand_in=True)
    assert stand_in.inputs.psf_source("lab") == "stand_in" and stand_in.inputs.can_render("lab")
    assert stand_in.inputs.psf_pattern("stand_in") == "lab"
    assert "optics.psf.stand_in" in stand_in.inputs.left_out("lab")[0]


def test_confocal_images_are_found_by_any_accepted_suffix(tmp_path):
    files = {"fluorescence/10mN.ome.tif": "", "fluorescence/20.czi": "", "fluorescence/40.tif": ""}
    files |= {"reflection.czi": "", "bead.ome.tif": ""}
    spheres, folder = _spheres(tmp_path, **files)
    assert spheres.files.per_load_inputs("lab", "fluorescence") == [
        str(folder / name) for name in ("fluorescence/10mN.ome.tif", "fluorescence/20.czi",
                                        "fluorescence/40.tif")
    ]  # fmt: skip
    assert spheres.files.reflection_image("lab") == str(folder / "reflection.czi")
    assert spheres.files.bead_image("lab") == str(folder / "bead.ome.tif")
    assert REFLECTION not in spheres.inputs.missing("lab") and BEAD not in spheres.inputs.missing(
        "lab"
    )


def test_the_virtual_experiments_images_are_named_by_its_format(tmp_path):
    spheres = Spheres({"syn": {**RECORD, "data_source": "synthetic"}}, RunPaths("full"),
                      synthetic_images=".ome.tif")  # fmt: skip
    assert (
        spheres.files.reflection_image("syn") == "resources/synthetic/full/syn/reflection.ome.tif"
    )
    assert spheres.files.bead_image("syn") == "resources/synthetic/full/syn/bead.ome.tif"


def test_two_formats_of_one_image_stop_the_run_naming_both(tmp_path):
    spheres, folder = _spheres(tmp_path, **{"reflection.tif": "", "reflection.czi": ""})
    with pytest.raises(RawDataError, match=r"reflection\.tif, reflection\.czi; expected one"):
        spheres.files.reflection_image("lab")


def test_images_without_a_pixel_and_no_sheet_pixel_stop_the_run_naming_sphere_and_file(
    tmp_path,
):
    files = {f"fluorescence/{load}.tif": "" for load in (10, 20, 40)}
    spheres, folder = _spheres(tmp_path, **files)
    untagged = np.ones((8, 8), np.uint16)
    for load in (10, 20):
        write_confocal(folder / f"fluorescence/{load}.tif", untagged, 200e-9, "ome_tiff")
    tifffile.imwrite(folder / "fluorescence/40.tif", untagged)  # no resolution tags
    spheres.pixels.check()  # the sheet gives the pixel
    del spheres.rows.records["lab"]["fluorescence_pixel_nm"]
    message = rf"no fluorescence_pixel_nm in the sheet: sphere lab: {folder}/fluorescence/40\.tif;"
    with pytest.raises(RawDataError, match=message):
        spheres.pixels.check()
    write_confocal(folder / "fluorescence/40.tif", untagged, 200e-9, "tif")
    spheres.pixels.check()  # every image states its own
    assert spheres.pixels.image_pixel_inputs("lab") == [
        "results/small/PS/lab/measure/contact_area.csv"
    ]
    assert spheres.pixels.image_pixel_inputs("syn") == []


@pytest.mark.parametrize("name", ["flim.ptu", "flim.tif"])
def test_a_flim_file_without_a_pixel_stops_the_run_like_any_image(tmp_path, name):
    """The FLIM file is read at the fluorescence pixel too: a PTU takes its pixel from its
    header (ImgHdr_PixResol), a map from its TIFF tags; neither there nor in the sheet stops
    the run before any job, naming the file (not a TypeError in the lifetime job)."""
    files = {f"fluorescence/{load}.tif": "" for load in (10, 20, 40)}
    spheres, folder = _spheres(tmp_path, **files)
    image = np.ones((8, 8), np.uint16)
    for load in (10, 20, 40):
        write_confocal(folder / f"fluorescence/{load}.tif", image, 200e-9, "ome_tiff")
    del spheres.rows.records["lab"]["fluorescence_pixel_nm"]
    flim = folder / name
    if name == "flim.ptu":
        histograms = np.ones((8, 8, 16), np.uint16)
        ptufile.imwrite(flim, histograms, 25e-9, 16e-12, pixel_resolution=0.2)
    else:
        write_image(flim, np.full((8, 8), 1.5), 200e-9)
    assert spheres.pixels.images_without_pixel("lab") == []
    spheres.pixels.check()  # the file states its pixel: the sheet may stay blank
    if name == "flim.ptu":
        ptufile.imwrite(flim, histograms, 25e-9, 16e-12, tags={"ImgHdr_PixResol": 0.0})
    else:
        tifffile.imwrite(flim, np.full((8, 8), 1.5))
    assert spheres.pixels.images_without_pixel("lab") == [str(flim)]
    with pytest.raises(RawDataError, match=rf"sphere lab: {flim};"):
        spheres.pixels.check()


# A measured sphere whose one file holds every load (config optics.images.load_series), as
# the DAG reads it: that file is the input of every job that reads fluorescence, the jobs'
# images param says which plane is which load, and what cannot be mapped without a guess
# stops the run before any job, naming the sphere and the files.
NO_PIXEL = {key: value for key, value in RECORD.items() if key != "fluorescence_pixel_nm"}

IMAGES = {"channel": None, "frames": "mean", "series": 0}
FRAMES_IN_ORDER = {"axis": "frames", "planes": "in_load_order"}


def _write_series(path, pixel_um=0.2):
    """An OME-TIFF of three T frames, with its pixel where ``pixel_um`` is given."""
    metadata = {"axes": "TYX"}
    if pixel_um is not None:
        metadata |= {"PhysicalSizeX": pixel_um, "PhysicalSizeY": pixel_um}
    frames = np.arange(1, 3 * 8 * 8 + 1, dtype=np.uint16).reshape(3, 8, 8)
    tifffile.imwrite(path, frames, ome=True, photometric="minisblack", metadata=metadata)


def _series_spheres(tmp_path, load_series=FRAMES_IN_ORDER, pixel_um=0.2, per_load=False, **row):
    """A measured sphere 'lab' whose folder holds fluorescence.ome.tif (and with
    ``per_load`` a fluorescence/ folder too), a per-load measured sphere 'old' and a synthetic
    one."""
    lab, old = tmp_path / "lab", tmp_path / "old"
    lab.mkdir()
    _write_series(lab / "fluorescence.ome.tif", pixel_um)
    for folder in [old, lab] if per_load else [old]:
        (folder / "fluorescence").mkdir(parents=True)
        for load in (10, 20, 40):
            (folder / "fluorescence" / f"{load}.tif").write_text("")
    records = {
        "lab": {**NO_PIXEL, "data_source": str(lab), **row},
        "old": {**RECORD, "data_source": str(old)},
        "syn": {**RECORD, "data_source": "synthetic"},
    }
    return Spheres(records, RunPaths("small"), load_series=load_series), lab


def test_the_one_file_is_every_fluorescence_jobs_input_and_the_param_maps_its_planes(tmp_path):
    spheres, lab = _series_spheres(tmp_path)
    series = str(lab / "fluorescence.ome.tif")
    assert spheres.series.file("lab") == series
    assert spheres.files.per_load_inputs("lab", "fluorescence") == [series]
    assert spheres.files.reflection_fluorescence("lab") == series
    assert spheres.series.fluorescence_choice("lab", IMAGES) == {
        **IMAGES,
        "load_series": {"axis": "frames", "plane_loads_mn": [10.0, 20.0, 40.0]},
    }
    # the pixel comes from the file: no sheet pixel needed, none missing
    assert spheres.pixels.images_without_pixel("lab") == []
    spheres.pixels.check()


def test_per_load_and_synthetic_spheres_keep_their_inputs_and_params(tmp_path):
    """Their jobs' inputs and params are those of a run without load-series files, so none of
    them re-runs."""
    spheres, _ = _series_spheres(tmp_path)
    assert spheres.series.file("old") is None and spheres.series.file("syn") is None
    for sphere in ("old", "syn"):
        assert spheres.series.fluorescence_choice(sphere, IMAGES) == IMAGES
        assert spheres.series.plane_loads(sphere) is None
    old = spheres.files.per_load_inputs("old", "fluorescence")
    assert old == [str(tmp_path / "old" / "fluorescence" / f"{f}.tif") for f in (10, 20, 40)]
    assert spheres.files.per_load_inputs("syn", "fluorescence").endswith("syn/fluorescence")


def test_a_planes_list_gives_each_plane_its_load(tmp_path):
    spheres, _ = _series_spheres(tmp_path, {"axis": "series", "planes": [1, 2, 0]})
    assert spheres.series.fluorescence_choice("lab", IMAGES)["load_series"] == {
        "axis": "series",
        "plane_loads_mn": [40.0, 10.0, 20.0],
    }


def test_a_planes_list_that_does_not_fit_the_sheets_loads_stops_naming_the_sphere(tmp_path):
    spheres, _ = _series_spheres(tmp_path, {"axis": "series", "planes": [0, 1]})
    with pytest.raises(RawDataError, match=r"sphere lab: .*planes \[0, 1\] for the sheet's 3"):
        spheres.series.fluorescence_choice("lab", IMAGES)


def test_a_folder_and_a_load_series_file_both_stop_the_run_naming_both(tmp_path):
    spheres, lab = _series_spheres(tmp_path, per_load=True)
    message = rf"sphere lab: both {lab}/fluorescence/ .* and {lab}/fluorescence\.ome\.tif"
    with pytest.raises(RawDataError, match=message):
        spheres.files.per_load_inputs("lab", "fluorescence")


def test_a_load_series_file_without_its_config_is_not_guessed(tmp_path):
    spheres, lab = _series_spheres(tmp_path, load_series=None)
    message = rf"sphere lab: {lab}/fluorescence\.ome\.tif holds every load, but .*load_series"
    with pytest.raises(RawDataError, match=message):
        spheres.files.per_load_inputs("lab", "fluorescence")
    assert spheres.files.per_load_inputs("old", "fluorescence")  # a per-load sphere needs none


def test_a_load_series_file_without_a_pixel_stops_the_run_like_any_image(tmp_path):
    spheres, lab = _series_spheres(tmp_path, pixel_um=None)
    with pytest.raises(RawDataError, match=rf"sphere lab: {lab}/fluorescence\.ome\.tif"):
        spheres.pixels.check()
    spheres.rows.records["lab"]["fluorescence_pixel_nm"] = 200
    spheres.pixels.check()


@pytest.mark.parametrize(("axis", "choice"), [("frames", {"frames": 0}), ("series", {"series": 1})])
def test_a_choice_along_the_load_axis_is_a_config_error(make_run, axis, choice):
    def edit(config):
        images = config["optics"]["images"]
        images.update(choice, load_series={"axis": axis, "planes": "in_load_order"})

    key = next(iter(choice))
    with pytest.raises(ConfigError, match=rf"optics\.images\.{key} is .*axis is '{axis}'"):
        make_run(edit=edit)


def test_the_config_accepts_a_mapping_and_the_rules_images_stay_as_they_were(make_run):
    def edit(config):
        config["optics"]["images"]["load_series"] = {"axis": "series", "planes": [0, 2, 1]}

    run = make_run(edit=edit)
    assert run.spheres.series.config == {"axis": "series", "planes": [0, 2, 1]}
    assert "load_series" not in image_choice(run.config)

    def bad(config):
        config["optics"]["images"]["load_series"] = {"axis": "time", "planes": "in_load_order"}

    with pytest.raises(ConfigError, match="load_series"):
        make_run(edit=bad)


def test_a_load_series_file_with_a_plane_too_many_stops_the_run_naming_sphere_and_file(tmp_path):
    spheres, lab = _series_spheres(tmp_path, {"axis": "frames", "planes": "in_load_order"})
    spheres.series.check()  # three frames, three loads
    spheres.rows.records["lab"]["loads"] = [10.0, 20.0]
    message = (
        rf"sphere lab: {lab}/fluorescence\.ome\.tif: it holds 3 frames \(its header says\), "
        r"but .* sheet's 2 loads \[10\.0, 20\.0\] mN along its frames, one each; expected exactly 2"
    )
    with pytest.raises(RawDataError, match=message):
        spheres.series.check()
    spheres.series.config["axis"] = "series"  # one series: as many as one load needs, not two
    with pytest.raises(RawDataError, match=r"it holds 1 series \(its header says\)"):
        spheres.series.check()


# Two programs' export maps (config rheometer_export), as a lab with two rheometers has them.
TWO_MAPS = {
    program: {
        "columns": {
            "time": {"column": "Time", "unit": "s"},
            "angle": {"column": "Angle", "unit": "mrad"},
            "normal_force": {"column": "Normal force", "unit": "N"},
            "torque": {"column": torque, "unit": "mN·m"},
        },
        "rotation_radius": {"key": "Radius", "unit": "mm"},
    }
    for program, torque in (("rheocompass", "Torque"), ("trios", "Torque (motor)"))
}


def test_a_sheet_row_may_name_the_export_map_of_its_spheres_files(tmp_path):
    """The friction job of a sphere whose row names a map gets that map alone (the DAG's
    param); a sphere whose row names none gets every map, matched to each file by its
    header; a single map passes as it is, whatever the row says."""
    spheres, _ = _spheres(tmp_path)
    spheres.rows.records["lab"]["rheometer_export"] = "trios"
    assert spheres.files.rheometer_export("lab", TWO_MAPS) == {"trios": TWO_MAPS["trios"]}
    assert spheres.files.rheometer_export("syn", TWO_MAPS) == TWO_MAPS
    assert spheres.files.rheometer_export("syn", None) is None
    single = TWO_MAPS["trios"]
    spheres.rows.records["lab"]["rheometer_export"] = "export"
    assert spheres.files.rheometer_export("lab", single) == single
    check_rheometer_exports(TWO_MAPS, {"lab": {"rheometer_export": "trios"}}, "mine.yaml")
    check_rheometer_exports(single, {"lab": {"rheometer_export": "export"}}, "mine.yaml")


def test_a_map_the_config_lacks_or_cannot_read_stops_the_run_before_any_job():
    message = (
        r"sphere lab: rheometer_export = 'rspace' in the sheet; expected one of the export "
        r"maps of mine\.yaml's rheometer_export: \['rheocompass', 'trios'\]"
    )
    with pytest.raises(ConfigError, match=message):
        check_rheometer_exports(TWO_MAPS, {"lab": {"rheometer_export": "rspace"}}, "mine.yaml")
    with pytest.raises(ConfigError, match=r"rheometer_export: none"):
        check_rheometer_exports(None, {"lab": {"rheometer_export": "trios"}}, "mine.yaml")
    bad = {"trios": {**TWO_MAPS["trios"], "decimal": ";"}}
    with pytest.raises(ConfigError, match=r"mine\.yaml: rheometer_export\.trios\.decimal = ';'"):
        check_rheometer_exports(bad, {}, "mine.yaml")


def test_a_virtual_sphere_is_made_with_the_model_and_value_its_row_names(tmp_path):
    """Contact hardening at the sheet's k where the row names no true model (the
    reproduction's spheres); another model at ``true_value``, or else at its prior column;
    elastic with no value; a model with neither value stops the DAG, naming the sphere."""
    rows = {
        "default": {**RECORD, "hardening_k_mpa_per_nm": 5.0},
        "hardness": {**RECORD, "true_model": "penetration_hardness", "hardness_mpa": 200.0},
        "given": {
            **RECORD,
            "true_model": "penetration_hardness",
            "hardness_mpa": 200.0,
            "true_value": 110.0,
        },
        "elastic": {**RECORD, "true_model": "elastic", "hardness_mpa": 200.0},
        "missing": {**RECORD, "true_model": "penetration_hardness"},
    }
    sheet = Spheres({k: {**v, "data_source": "synthetic"} for k, v in rows.items()}, RunPaths("s"))
    found = {
        name: (sheet.rows.true_model(name), sheet.rows.true_value(name))
        for name in ("default", "hardness", "given", "elastic")
    }
    assert found == {
        "default": ("hardening", 5.0),
        "hardness": ("penetration_hardness", 200.0),
        "given": ("penetration_hardness", 110.0),
        "elastic": ("elastic", None),
    }
    with pytest.raises(ConfigError, match="sphere missing: .*neither true_value nor hardness_mpa"):
        sheet.rows.true_value("missing")
