"""Readers of the raw-data layout: a bad file stops with an error naming the file and what was
expected, never a silent number."""

import numpy as np
import pytest

from amontons.io.layout import (
    RawDataError,
    fluorescence_name,
    per_load_files,
    rheometer_files,
    rheometer_name,
)
from amontons.io.rawdata import read_absorbance, read_flim, read_reflection, read_rheometer_traces
from amontons.io.tiff import read_image, write_image
from amontons.measure.area import OtsuSettings
from amontons.measure.edge_gap import measure_edge_gap
from amontons.measure.errors import NoContact
from amontons.measure.friction import measure_friction
from amontons.measure.psf import measure_bead
from amontons.physics.newton_rings import APPENDIX_WAVELENGTH_M, FORMAMIDE_REFRACTIVE_INDEX
from amontons.virtual.bead import render_bead
from amontons.virtual.rheometer import rheometer_trace, write_rheometer_trace

PIXEL = 200e-9
LOADS_MN = [25.0, 50.0]


def _rheometer_folder(folder, loads_mn=LOADS_MN, recorded_mn=None):
    """One rheometer file per load; ``recorded_mn`` overrides the normal force written."""
    recorded_mn = recorded_mn or loads_mn
    for name, load in zip(loads_mn, recorded_mn, strict=True):
        trace = rheometer_trace(
            load * 1e-3, 0.01, 0.008, 5e-3, 1e-5, rng=np.random.default_rng(int(load))
        )
        write_rheometer_trace(folder / f"{name:g}.csv", trace)
    return folder


def test_rheometer_files_follow_the_load_list(tmp_path):
    folder = _rheometer_folder(tmp_path)
    assert [p.name for p in rheometer_files(folder, LOADS_MN)] == ["25.csv", "50.csv"]
    traces = read_rheometer_traces(rheometer_files(folder, LOADS_MN), LOADS_MN)
    # 0.2 mN noise over 2000 samples: the mean normal force is the load to 0.05 mN.
    assert np.mean(traces[1].normal_force_n) == pytest.approx(0.05, abs=5e-5)


def test_load_list_not_matching_the_rheometer_files(tmp_path):
    folder = _rheometer_folder(tmp_path)
    with pytest.raises(
        RawDataError, match=r"does not match the rheometer files.*no file for \[100.0\]"
    ):
        rheometer_files(folder, [*LOADS_MN, 100.0])
    with pytest.raises(RawDataError, match=r"rheometer files not in the list: \[50.0\]"):
        rheometer_files(folder, [25.0])


def test_rheometer_file_missing_a_column_names_file_and_column(tmp_path):
    folder = _rheometer_folder(tmp_path)
    path = folder / "50.csv"
    path.write_text(path.read_text().replace("torque_N_m", "torque"))
    with pytest.raises(RawDataError, match=r"50\.csv: no column 'torque_N_m'"):
        read_rheometer_traces(rheometer_files(folder, LOADS_MN), LOADS_MN)


def test_rheometer_file_without_rotation_radius(tmp_path):
    folder = _rheometer_folder(tmp_path)
    path = folder / "25.csv"
    lines = [line for line in path.read_text().splitlines() if "rotation_radius" not in line]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(RawDataError, match=r"25\.csv: no '# rotation_radius_mm: <value>'"):
        measure_friction(
            rheometer_files(folder, LOADS_MN), LOADS_MN, median_window_s=0.05, plateau_fraction=0.5
        )


def test_rheometer_file_recorded_at_another_load(tmp_path):
    # 50.csv holds a 100 mN test: refused (beyond the 10 % tolerance), not silently used.
    folder = _rheometer_folder(tmp_path, recorded_mn=[25.0, 100.0])
    with pytest.raises(RawDataError, match=r"50\.csv: mean normal force 100 mN.*say 50 mN"):
        read_rheometer_traces(rheometer_files(folder, LOADS_MN), LOADS_MN)


def test_bead_off_the_edge_names_the_file(tmp_path):
    image = render_bead((41, 41), PIXEL, 450e-9, (1e-6, 4e-6), 2000, 120, np.random.default_rng(0))
    write_image(tmp_path / "bead.tif", image, PIXEL)
    with pytest.raises(RawDataError, match=r"bead\.tif: bead centre .* from the image edge"):
        measure_bead(tmp_path / "bead.tif", None, profile_radius_m=2e-6, centroid_radius_m=6e-7)


def test_missing_bead_names_the_expected_file(tmp_path):
    with pytest.raises(RawDataError, match=r"bead\.tif: no bead image"):
        measure_bead(tmp_path / "bead.tif", PIXEL, profile_radius_m=2e-6, centroid_radius_m=6e-7)


def test_reflection_on_another_field_than_the_fluorescence(tmp_path):
    write_image(tmp_path / "25.tif", np.ones((64, 64), np.uint16), PIXEL)
    write_image(tmp_path / "reflection.tif", np.ones((96, 96), np.uint16), PIXEL)
    like = read_image(tmp_path / "25.tif")
    with pytest.raises(RawDataError, match=r"reflection\.tif: \(96, 96\) px.*expected the field"):
        read_reflection(tmp_path / "reflection.tif", like=like)


def _edge_gap_of(folder):
    """The Newton-ring edge gap of ``folder``'s reflection.tif at 25.tif, 4 profiles."""
    return measure_edge_gap(
        folder / "reflection.tif",
        folder / "25.tif",
        None,
        load_mn=25.0,
        otsu=OtsuSettings(),
        n_profiles=4,
        edge_model="hertz_free_radius",
        wavelength_m=APPENDIX_WAVELENGTH_M,
        n_medium=FORMAMIDE_REFRACTIVE_INDEX,
    )


def test_reflection_without_rings_names_the_file(tmp_path):
    # A contact in the fluorescence image but a ring-free reflection: no gap can be read.
    rows, cols = np.indices((128, 128))
    contact = np.hypot(rows - 64, cols - 64) < 20
    rng = np.random.default_rng(1)
    write_image(
        tmp_path / "25.tif", rng.poisson(np.where(contact, 1500, 120)).astype(np.uint16), PIXEL
    )
    write_image(tmp_path / "reflection.tif", rng.poisson(400, (128, 128)).astype(np.uint16), PIXEL)
    with pytest.raises(RawDataError, match=r"reflection\.tif: .*profile at .*ring maxima"):
        _edge_gap_of(tmp_path)


def test_edge_gap_of_an_image_without_contact_is_not_measurable(tmp_path):
    """No contact stands out (Otsu separation of pure shot noise ≈ 2/π): a NoContact error
    naming the image, which the rule turns into a flagged null."""
    rng = np.random.default_rng(5)
    write_image(tmp_path / "25.tif", rng.poisson(120, (128, 128)).astype(np.uint16), PIXEL)
    write_image(tmp_path / "reflection.tif", np.full((128, 128), 400, np.uint16), PIXEL)
    with pytest.raises(NoContact, match=r"25\.tif: the upper class is only 1\.\d noise sd"):
        _edge_gap_of(tmp_path)


def test_flim_map_of_counts_is_refused(tmp_path):
    write_image(tmp_path / "flim.tif", np.ones((16, 16), np.uint16), PIXEL)
    with pytest.raises(RawDataError, match=r"flim\.tif: pixel dtype uint16; expected floating"):
        read_flim(tmp_path / "flim.tif")


def test_flim_map_with_non_positive_times_is_refused(tmp_path):
    write_image(tmp_path / "flim.tif", np.zeros((16, 16), np.float32), PIXEL)
    with pytest.raises(RawDataError, match=r"flim\.tif: 256 pixels ≤ 0 ns"):
        read_flim(tmp_path / "flim.tif")


def test_absorbance_missing_a_column_names_file_and_column(tmp_path):
    path = tmp_path / "absorbance.csv"
    path.write_text("wavelength_nm,A\n" + "".join(f"{400 + i},0.001\n" for i in range(20)))
    with pytest.raises(RawDataError, match=r"absorbance\.csv: no column 'absorbance'"):
        read_absorbance(path)


def test_per_load_files_of_a_folder_are_named_by_load_and_never_searched(tmp_path):
    # The virtual experiment's folder: files named by the layout (25.tif); a user's 25mN.tif
    # in it is not looked for (the workflow matches a measured sphere's files itself).
    write_image(tmp_path / "25.tif", np.ones((8, 8), np.uint16), PIXEL)
    assert per_load_files(tmp_path, [25.0], fluorescence_name) == [tmp_path / "25.tif"]
    write_image(tmp_path / "50mN.tif", np.ones((8, 8), np.uint16), PIXEL)
    with pytest.raises(RawDataError, match=r"50\.tif: no such file"):
        per_load_files(tmp_path, [25.0, 50.0], fluorescence_name)


def test_per_load_files_given_as_files_keep_their_order_and_count(tmp_path):
    paths = [tmp_path / "50mN.csv", tmp_path / "25mN.csv"]
    for path in paths:
        path.write_text("x")
    assert per_load_files([str(p) for p in paths], [50.0, 25.0], rheometer_name) == paths
    assert per_load_files(str(paths[0]), [50.0], rheometer_name) == [paths[0]]
    with pytest.raises(RawDataError, match=r"2 files .* for 1 loads"):
        per_load_files(paths, [50.0], rheometer_name)
