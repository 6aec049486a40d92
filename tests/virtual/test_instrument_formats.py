"""The virtual experiment writes its FLIM, rheometer and confocal files in the instrument
formats: a PTU of time-tagged photons, a rheometer program's export, OME-TIFF or CZI images. On
the same contact states and seed, every other file is the same bytes as on the TIFF and CSV
route, friction read from the export is the CSV's (to 1e-12, the unit conversion's rounding),
the lifetimes from the photons agree with the map's within their standard errors, and the
confocal images read back as the TIFFs' pixels and pixel sizes, giving the same areas.

Smooth Hertz spheres (analytic contact states) keep the tests free of contact solves."""

import numpy as np
import pandas as pd
import pytest

from amontons.config import read_config
from amontons.io.confocal import read_confocal
from amontons.io.export_map import ExportMap
from amontons.io.layout import fluorescence_names, per_load_files, rheometer_files, rheometer_name
from amontons.io.rawdata import read_bead, read_fluorescence_series, read_rheometer_traces
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES
from amontons.io.tiff import read_image
from amontons.measure.area import OtsuSettings, contact_area_table, image_contact_area
from amontons.measure.friction import static_friction
from amontons.measure.lifetime import measure_lifetime
from amontons.virtual.experiment import write_instruments
from amontons.virtual.flim import TcspcSettings
from amontons.virtual.hertz_contact import hertz_contact_state
from amontons.virtual.settings import InstrumentSettings, OutputFormats

LOADS_N = [0.025, 0.05, 0.1]
PIXEL = 400e-9
TCSPC = TcspcSettings(
    photons_per_pixel=1000, irf_fwhm_s=200e-12, irf_peak_s=2e-9, bin_s=16e-12, sync_period_s=25e-9
)
# 4 standard errors: an unbiased difference falls outside with 6e-5 chance (test_ptu.py)
BOUND_SE = 4.0


@pytest.fixture(scope="module")
def config(repo):
    return read_config(repo / "config" / "config.yaml", repo / "config" / "test.yaml")


def _write(folder, config, formats):
    settings = InstrumentSettings.from_config(
        config["virtual_experiment"], config["optics"]["newton_rings"]
    )
    states = [hertz_contact_state(f, 0.3e-3, 3.7e9, (128, 128), PIXEL, 5e-9) for f in LOADS_N]
    return write_instruments(
        folder,
        sphere="PS",
        states=states,
        pixel_m=PIXEL,
        reflection_load_n=0.025,
        flim_load_n=0.1,
        shear_strength_pa=20e6,
        settings=settings,
        seed=3,
        formats=formats,
    )


@pytest.fixture(scope="module")
def routes(tmp_path_factory, config):
    """The same sphere written twice: TIFF and CSV; PTU, the semicolons export and OME-TIFF
    images. And its images once more as CZI."""
    root = tmp_path_factory.mktemp("formats")
    plain = _write(root / "plain", config, OutputFormats())
    instrument = _write(
        root / "instrument", config, OutputFormats("ptu", "semicolons", TCSPC, "ome_tiff")
    )
    _write(root / "czi", config, OutputFormats(images="czi"))
    return root, plain, instrument


def test_the_other_instruments_write_the_same_bytes(routes):
    root, _, _ = routes
    # (the images: pixel for pixel, test_confocal_images_read_back_as_the_tiffs_...)
    assert (root / "plain" / "absorbance.csv").read_bytes() == (
        root / "instrument" / "absorbance.csv"
    ).read_bytes()
    assert (root / "instrument" / "reflection.ome.tif").is_file()
    assert not (root / "instrument" / "reflection.tif").exists()
    assert (root / "instrument" / "flim.ptu").is_file()
    assert not (root / "instrument" / "flim.tif").exists()


def test_the_truth_says_which_formats(routes):
    _, plain, instrument = routes
    assert plain["rheometer_format"] == "csv" and plain["flim"]["format"] == "tif"
    assert plain["image_format"] == "tif" and instrument["image_format"] == "ome_tiff"
    assert instrument["rheometer_format"] == "semicolons" and instrument["flim"]["format"] == "ptu"
    assert instrument["flim"]["photons"]["per_pixel_mean"] == 1000
    for key in ("static_friction_mn", "dynamic_friction_mn", "area_um2"):
        assert plain[key] == instrument[key]
    assert plain["flim"]["contact_pixels"] == instrument["flim"]["contact_pixels"]


IMAGE_STEMS = [f"fluorescence/{f * 1e3:g}" for f in LOADS_N] + ["reflection", "bead"]


@pytest.mark.parametrize("route, suffix", [("instrument", ".ome.tif"), ("czi", ".czi")])
def test_confocal_images_read_back_as_the_tiffs_pixels_and_pixel_size(routes, route, suffix):
    root, _, _ = routes
    for stem in IMAGE_STEMS:
        tiff = read_image(root / "plain" / f"{stem}.tif")
        confocal = read_confocal(root / route / f"{stem}{suffix}")
        assert confocal.data.dtype == tiff.data.dtype and confocal.data.shape == tiff.data.shape
        assert confocal.data.tobytes() == tiff.data.tobytes(), stem
        assert confocal.pixel_m == tiff.pixel_m == PIXEL and confocal.pixel_source == "file"


@pytest.mark.parametrize("route", ["instrument", "czi"])
def test_areas_and_psf_from_the_confocal_images_are_the_tiffs(routes, config, route):
    root, _, _ = routes
    loads_mn = [f * 1e3 for f in LOADS_N]
    otsu = OtsuSettings.from_config(config["optics"])
    tables = []
    for folder in (root / "plain", root / route):
        paths = per_load_files(folder / "fluorescence", loads_mn, fluorescence_names)
        images = read_fluorescence_series(paths, PIXEL)
        tables.append(
            contact_area_table(loads_mn, images, [image_contact_area(i, otsu) for i in images])
        )
    assert tables[0]["area_um2"].gt(0).all()
    pd.testing.assert_frame_equal(tables[0].drop(columns="image"), tables[1].drop(columns="image"))
    beads = [read_bead(next(f.glob("bead.*")), PIXEL) for f in (root / "plain", root / route)]
    assert beads[0].data.tobytes() == beads[1].data.tobytes()


def test_friction_from_the_export_is_the_csvs(routes):
    # The same trace (the rheometer's noise stream does not depend on the format), 9 digits in
    # both files: equal to the unit conversion's rounding, 1e-12 relative
    root, _, _ = routes
    loads_mn = [f * 1e3 for f in LOADS_N]
    csv = read_rheometer_traces(
        per_load_files(root / "plain" / "rheometer", loads_mn, rheometer_name), loads_mn
    )
    export = ExportMap.from_config(EXPORT_SHAPES["semicolons"].column_map())
    exported = read_rheometer_traces(
        rheometer_files(root / "instrument" / "rheometer", loads_mn), loads_mn, {"export": export}
    )
    for ours, theirs in zip(csv, exported, strict=True):
        a, b = static_friction(ours), static_friction(theirs)
        assert b.static_friction_n == pytest.approx(a.static_friction_n, rel=1e-12)
        assert b.dynamic_friction_n == pytest.approx(a.dynamic_friction_n, rel=1e-12)
        assert b.sliding_speed_m_s == pytest.approx(a.sliding_speed_m_s, rel=1e-12)


def test_lifetimes_from_the_photons_agree_with_the_map(routes, config):
    root, plain, _ = routes
    otsu = OtsuSettings.from_config(config["optics"])
    band = config["optics"]["lifetime"]["exclude_edge_px"]
    from_map = measure_lifetime(root / "plain" / "flim.tif", None, otsu=otsu, exclude_edge_px=band)
    from_photons = measure_lifetime(
        root / "instrument" / "flim.ptu", None, otsu=otsu, exclude_edge_px=band
    )
    origin_se = from_photons.time_origin.standard_error_ns
    for side in ("inside", "outside"):
        a, b = (getattr(s, f"{side}_mean_ns") for s in (from_map, from_photons))
        se_a, se_b = (getattr(s, f"{side}_se_ns") for s in (from_map, from_photons))
        assert abs(a - b) <= BOUND_SE * np.sqrt(se_a**2 + se_b**2 + origin_se**2), side
        truth = plain["flim"]["contact_ns" if side == "inside" else "outside_ns"]
        assert abs(b - truth) <= BOUND_SE * np.hypot(se_b, origin_se), side
    assert from_photons.photons["inside"]["per_pixel_min"] > 0


def test_the_same_seed_writes_the_same_ptu(tmp_path, config, routes):
    root, _, _ = routes
    _write(tmp_path, config, OutputFormats("ptu", "units_row", TCSPC))
    assert (tmp_path / "flim.ptu").read_bytes() == (root / "instrument" / "flim.ptu").read_bytes()
    assert sorted(p.name for p in (tmp_path / "rheometer").iterdir()) == [
        "100.txt",
        "25.txt",
        "50.txt",
    ]


def test_formats_are_checked():
    with pytest.raises(ValueError, match="formats.flim = 'lif'"):
        OutputFormats("lif")
    with pytest.raises(ValueError, match="formats.rheometer = 'xlsx'; expected one of"):
        OutputFormats("tif", "xlsx")
    with pytest.raises(ValueError, match="needs the photon-counting settings"):
        OutputFormats("ptu")
    with pytest.raises(ValueError, match="formats.images = 'lif'; expected one of"):
        OutputFormats(images="lif")
    with pytest.raises(ValueError, match="shorter than the laser period"):
        TcspcSettings(1000, 200e-12, 2e-9, 30e-9, 25e-9)
    settings = {
        "formats": {"flim": "ptu", "rheometer": "brackets", "images": "czi"},
        "flim_photons_per_pixel": 1000,
        "flim_irf_fwhm_ps": 200.0,
        "flim_irf_peak_ns": 2.0,
        "flim_tcspc_bin_ps": 16.0,
        "flim_sync_rate_mhz": 40.0,
    }
    assert OutputFormats.from_config(settings) == OutputFormats("ptu", "brackets", TCSPC, "czi")
