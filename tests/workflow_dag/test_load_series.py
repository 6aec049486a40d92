"""A measured sphere whose one file holds every load (config optics.images.load_series), as the
DAG reads it: that file is the input of every job that reads fluorescence, the jobs' images
param says which plane is which load, and what cannot be mapped without a guess stops the run
before any job, naming the sphere and the files."""

import numpy as np
import pytest
import tifffile

from amontons.config import ConfigError
from amontons.io.layout import RawDataError
from amontons.workflow.params import image_choice
from amontons.workflow.paths import RunPaths
from amontons.workflow.spheres import Spheres

RECORD = {
    "material": "PS",
    "loads": [10.0, 20.0, 40.0],
    "reflection_load_mn": 20.0,
    "diameter_mm": 0.6,
    "e_star_gpa": 3.7,
}
IMAGES = {"channel": None, "frames": "mean", "series": 0}
FRAMES_IN_ORDER = {"axis": "frames", "planes": "in_load_order"}


def _write_series(path, pixel_um=0.2):
    """An OME-TIFF of three T frames, with its pixel where ``pixel_um`` is given."""
    metadata = {"axes": "TYX"}
    if pixel_um is not None:
        metadata |= {"PhysicalSizeX": pixel_um, "PhysicalSizeY": pixel_um}
    frames = np.arange(1, 3 * 8 * 8 + 1, dtype=np.uint16).reshape(3, 8, 8)
    tifffile.imwrite(path, frames, ome=True, photometric="minisblack", metadata=metadata)


def _spheres(tmp_path, load_series=FRAMES_IN_ORDER, pixel_um=0.2, per_load=False, **row):
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
        "lab": {**RECORD, "data_source": str(lab), **row},
        "old": {**RECORD, "data_source": str(old), "fluorescence_pixel_nm": 200},
        "syn": {**RECORD, "data_source": "synthetic"},
    }
    return Spheres(records, RunPaths("small"), load_series=load_series), lab


def test_the_one_file_is_every_fluorescence_jobs_input_and_the_param_maps_its_planes(tmp_path):
    spheres, lab = _spheres(tmp_path)
    series = str(lab / "fluorescence.ome.tif")
    assert spheres.load_series_file("lab") == series
    assert spheres.per_load_inputs("lab", "fluorescence") == [series]
    assert spheres.reflection_fluorescence("lab") == series
    assert spheres.fluorescence_choice("lab", IMAGES) == {
        **IMAGES,
        "load_series": {"axis": "frames", "plane_loads_mn": [10.0, 20.0, 40.0]},
    }
    # the pixel comes from the file: no sheet pixel needed, none missing
    assert spheres.images_without_pixel("lab") == []
    spheres.check_pixel_sizes()


def test_per_load_and_synthetic_spheres_keep_their_inputs_and_params(tmp_path):
    """Their jobs' inputs and params are those of a run without load-series files, so none of
    them re-runs."""
    spheres, _ = _spheres(tmp_path)
    assert spheres.load_series_file("old") is None and spheres.load_series_file("syn") is None
    for sphere in ("old", "syn"):
        assert spheres.fluorescence_choice(sphere, IMAGES) == IMAGES
        assert spheres.plane_loads(sphere) is None
    old = spheres.per_load_inputs("old", "fluorescence")
    assert old == [str(tmp_path / "old" / "fluorescence" / f"{f}.tif") for f in (10, 20, 40)]
    assert spheres.per_load_inputs("syn", "fluorescence").endswith("syn/fluorescence")


def test_a_planes_list_gives_each_plane_its_load(tmp_path):
    spheres, _ = _spheres(tmp_path, {"axis": "series", "planes": [1, 2, 0]})
    assert spheres.fluorescence_choice("lab", IMAGES)["load_series"] == {
        "axis": "series",
        "plane_loads_mn": [40.0, 10.0, 20.0],
    }


def test_a_planes_list_that_does_not_fit_the_sheets_loads_stops_naming_the_sphere(tmp_path):
    spheres, _ = _spheres(tmp_path, {"axis": "series", "planes": [0, 1]})
    with pytest.raises(RawDataError, match=r"sphere lab: .*planes \[0, 1\] for the sheet's 3"):
        spheres.fluorescence_choice("lab", IMAGES)


def test_a_folder_and_a_load_series_file_both_stop_the_run_naming_both(tmp_path):
    spheres, lab = _spheres(tmp_path, per_load=True)
    message = rf"sphere lab: both {lab}/fluorescence/ .* and {lab}/fluorescence\.ome\.tif"
    with pytest.raises(RawDataError, match=message):
        spheres.per_load_inputs("lab", "fluorescence")


def test_a_load_series_file_without_its_config_is_not_guessed(tmp_path):
    spheres, lab = _spheres(tmp_path, load_series=None)
    message = rf"sphere lab: {lab}/fluorescence\.ome\.tif holds every load, but .*load_series"
    with pytest.raises(RawDataError, match=message):
        spheres.per_load_inputs("lab", "fluorescence")
    assert spheres.per_load_inputs("old", "fluorescence")  # a per-load sphere needs none


def test_a_load_series_file_without_a_pixel_stops_the_run_like_any_image(tmp_path):
    spheres, lab = _spheres(tmp_path, pixel_um=None)
    with pytest.raises(RawDataError, match=rf"sphere lab: {lab}/fluorescence\.ome\.tif"):
        spheres.check_pixel_sizes()
    spheres.records["lab"]["fluorescence_pixel_nm"] = 200
    spheres.check_pixel_sizes()


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
    assert run.spheres.load_series == {"axis": "series", "planes": [0, 2, 1]}
    assert "load_series" not in image_choice(run.config)

    def bad(config):
        config["optics"]["images"]["load_series"] = {"axis": "time", "planes": "in_load_order"}

    with pytest.raises(ConfigError, match="load_series"):
        make_run(edit=bad)
