"""Hard cases of the measurements (issue 18): each gives a named error or a flagged result,
never a silent number or a traceback from inside a library.

Cases already covered elsewhere are not repeated: a shot-noise image without contact
(test_area.py), a bead near the edge and a saturated bead (test_psf.py), a noisy ring-free
reflection (test_newton_rings.py, test_rawdata.py), a rheometer trace still rising at its end
(tests/virtual/test_rheometer_friction.py), an all-NaN .npy height map (test_bad_files.py)
and rheometer files that do not match the load list (test_rawdata.py). Here are their
variants that were not covered, each through the reader or measurement the workflow calls.
"""

import dataclasses

import numpy as np
import pytest

from amontons.io.heightmap import TopographyError, read_height_map
from amontons.io.layout import RawDataError, fluorescence_images
from amontons.io.rheometer import RheometerError
from amontons.io.tiff import read_image, write_image
from amontons.measure.area import (
    OtsuSettings,
    contact_area_table,
    image_contact_area,
    separated_contact,
)
from amontons.measure.errors import NoContact
from amontons.measure.friction import static_friction
from amontons.measure.newton_rings import NewtonRingError, newton_ring_gap
from amontons.measure.psf import PsfError, measure_psf
from amontons.virtual.bead import render_bead
from amontons.virtual.rheometer import rheometer_trace

PIXEL = 200e-9  # fluorescence pixel, m
U16_MAX = np.iinfo(np.uint16).max


def _disk_counts(side=128, radius_px=20, inside=1500, outside=120, seed=1):
    """Poisson counts of a bright disk (contact) on a dark background, uint16."""
    rows, cols = np.indices((side, side)) - (side - 1) / 2
    expected = np.where(np.hypot(rows, cols) <= radius_px, inside, outside)
    return np.random.default_rng(seed).poisson(expected).astype(np.uint16)


def _written(tmp_path, name, data, pixel=PIXEL):
    """``data`` written as the TIFF ``name`` in ``tmp_path`` and read back as an Image."""
    write_image(tmp_path / name, data, pixel)
    return read_image(tmp_path / name)


# --- fluorescence images --------------------------------------------------------------------


def test_image_without_contact_is_flagged_and_named(tmp_path):
    """Only background (Poisson, 120 counts): the area is flagged with its reason and the
    call that needs a contact raises NoContact naming the file."""
    image = _written(
        tmp_path, "25.tif", np.random.default_rng(2).poisson(120, (128, 128)).astype(np.uint16)
    )
    area = image_contact_area(image, OtsuSettings())
    assert not area.contact_found and "noise sd above the background" in area.flag
    with pytest.raises(NoContact, match=r"25\.tif: .*expected a contact brighter"):
        separated_contact(image, OtsuSettings())


@pytest.mark.parametrize("value", [0, 400, U16_MAX], ids=["black", "grey", "saturated"])
def test_uniform_image_is_not_measurable_and_named(tmp_path, value):
    """A constant image (also a fully saturated one) has no Otsu threshold: NoContact
    naming the file and the value, not a division by a zero variance."""
    image = _written(tmp_path, "50.tif", np.full((64, 64), value, np.uint16))
    with pytest.raises(NoContact, match=rf"50\.tif: image is constant \({value} everywhere\)"):
        image_contact_area(image, OtsuSettings())


def test_saturated_contact_keeps_its_area_and_is_flagged_in_the_table(tmp_path):
    """A contact clipped at the 16-bit ceiling: its area stands (the threshold lies far
    below the ceiling, so the same pixels are found as without clipping), and the table
    counts the saturated pixels so that no intensity is read from them (intensity.py
    refuses the image)."""
    clean = _disk_counts()
    clipped = clean.copy()
    clipped[clean > 1000] = U16_MAX
    area = image_contact_area(_written(tmp_path, "25.tif", clipped), OtsuSettings())
    reference = image_contact_area(_written(tmp_path, "ref.tif", clean), OtsuSettings())
    assert area.contact_found
    assert area.n_contact_pixels == reference.n_contact_pixels
    table = contact_area_table([25.0], [read_image(tmp_path / "25.tif")], [area])
    assert table["saturated_pixels"].iloc[0] == int(np.count_nonzero(clean > 1000)) > 0


def test_bead_in_the_corner_is_refused():
    """A bead centred on the corner pixel (half of it outside the image): PsfError naming
    the distance to the edge, not a fit of half a bead."""
    image = render_bead((41, 41), PIXEL, 450e-9, (0.0, 0.0), 1000, 50, np.random.default_rng(0))
    with pytest.raises(PsfError, match="from the image edge"):
        measure_psf(image, PIXEL)


@pytest.mark.parametrize("value", [0, 400, U16_MAX], ids=["black", "grey", "saturated"])
def test_reflection_without_rings_is_refused(value):
    """A uniform reflection image has no intensity range; before the fix, round-off of the
    smoothing passed for ring maxima on some profiles (prominence threshold 0) and a fully
    saturated image was refused for a 'ring inside the contact'. Now NewtonRingError says
    the image is uniform."""
    image = np.full((256, 256), value, np.uint16)
    with pytest.raises(NewtonRingError, match=rf"uniform \({value} counts"):
        newton_ring_gap(image, PIXEL, (128.0, 128.0), 5e-6)


# --- rheometer traces -----------------------------------------------------------------------


def _trace(seed=0):
    """A 20 s, 100 Hz virtual trace: 25 mN, static 10 mN, dynamic 8 mN, radius 5 mm."""
    return rheometer_trace(
        0.025, 0.010, 0.008, 5e-3, 1e-5, 20.0, 100.0, rng=np.random.default_rng(seed)
    )


@pytest.mark.parametrize("shape", ["constant", "falling"])
def test_rheometer_trace_without_a_peak_is_refused(shape):
    """A constant torque (a stuck sensor offset) or a falling one has its maximum at the
    start: before the fix, the constant trace gave a static friction of 2 mN (its offset)
    and the noise test passed (noise 0). Now RheometerError says there is no peak."""
    trace = _trace()
    n = trace.time_s.size
    torque = np.full(n, 1e-5) if shape == "constant" else np.linspace(5e-5, 1e-5, n)
    with pytest.raises(RheometerError, match="no static friction peak .* start of the record"):
        static_friction(dataclasses.replace(trace, torque_n_m=torque))


@pytest.mark.parametrize("column", ["torque_n_m", "angle_rad", "normal_force_n"])
def test_rheometer_trace_with_non_finite_dropouts_is_refused(column):
    """Five NaN samples (a logger dropout) in any column: before the fix the static friction
    (torque) or the sliding speed (angle) came out NaN without a word."""
    trace = _trace()
    values = getattr(trace, column).copy()
    values[700:705] = np.nan
    with pytest.raises(RheometerError, match="5 non-finite .* first is sample 700"):
        static_friction(dataclasses.replace(trace, **{column: values}))


def test_rheometer_trace_with_missing_samples_is_refused():
    """2 s of samples missing (t = 6-8 s): longer than the 0.05 s median window, so a peak
    could lie in it; refused naming where the record stops, instead of a number from the
    samples that are left."""
    trace = _trace()
    keep = np.ones(trace.time_s.size, dtype=bool)
    keep[600:800] = False
    cut = dataclasses.replace(
        trace,
        time_s=trace.time_s[keep],
        angle_rad=trace.angle_rad[keep],
        normal_force_n=trace.normal_force_n[keep],
        torque_n_m=trace.torque_n_m[keep],
    )
    with pytest.raises(RheometerError, match=r"2\.01 s without samples after t = 5\.99 s"):
        static_friction(cut)


def test_rheometer_trace_with_a_short_gap_is_measured():
    """The dropout test is not over-eager: two missing samples (0.03 s, under the median
    window) leave the static friction within the 2 % of the intact trace's accuracy
    (tests/virtual/test_rheometer_friction.py)."""
    trace = _trace()
    keep = np.ones(trace.time_s.size, dtype=bool)
    keep[[900, 901]] = False
    cut = dataclasses.replace(
        trace,
        time_s=trace.time_s[keep],
        angle_rad=trace.angle_rad[keep],
        normal_force_n=trace.normal_force_n[keep],
        torque_n_m=trace.torque_n_m[keep],
    )
    assert static_friction(cut).static_friction_n == pytest.approx(0.010, rel=0.02)


# --- AFM maps and the sample sheet ----------------------------------------------------------


@pytest.mark.parametrize("policy", ["fail", "fill"])
def test_all_nan_afm_tiff_is_refused_under_either_policy(tmp_path, policy):
    """A float TIFF of nothing but NaN: TopographyError naming the file, also when NaN
    pixels are to be filled (there is nothing to fill them from)."""
    path = tmp_path / "afm.tif"
    write_image(path, np.full((64, 64), np.nan, np.float32), 40e-9)
    with pytest.raises(TopographyError, match=r"afm\.tif: every pixel is NaN"):
        read_height_map(path, fallback_pixel_m=40e-9, nan_policy=policy)


def test_sheet_loads_that_do_not_match_the_images_name_both(tmp_path):
    """The sheet lists 25, 50, 100 mN; the folder holds 25, 50 and 75 mN images. The error
    names the folder, the load without an image and the image without a load."""
    for load in (25, 50, 75):
        write_image(tmp_path / f"{load}.tif", _disk_counts(side=32, radius_px=5), PIXEL)
    expected = r"no image for \[100\.0\]; images not in the list: \[75\.0\]"
    with pytest.raises(RawDataError, match=expected):
        fluorescence_images(tmp_path, [25.0, 50.0, 100.0])
