"""The virtual experiment writes its FLIM and rheometer files in the instrument formats: a PTU
of time-tagged photons and a rheometer program's export. On the same contact states and seed,
every other file is the same bytes as on the TIFF and CSV route, friction read from the export
is the CSV's (to 1e-12, the unit conversion's rounding), and the lifetimes from the photons
agree with the map's within their standard errors.

Smooth Hertz spheres (analytic contact states) keep the tests free of contact solves."""

import numpy as np
import pytest

from amontons.config import read_config
from amontons.io.layout import per_load_files, rheometer_files, rheometer_name
from amontons.io.rawdata import read_rheometer_traces
from amontons.io.rheometer_export import EXPORT_SHAPES, ExportMap
from amontons.measure.area import OtsuSettings
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
    """The same sphere written twice: TIFF and CSV; PTU and the semicolons export."""
    root = tmp_path_factory.mktemp("formats")
    plain = _write(root / "plain", config, OutputFormats())
    instrument = _write(root / "instrument", config, OutputFormats("ptu", "semicolons", TCSPC))
    return root, plain, instrument


def test_the_other_instruments_write_the_same_bytes(routes):
    root, _, _ = routes
    names = ["reflection.tif", "bead.tif", "absorbance.csv"]
    names += [f"fluorescence/{f * 1e3:g}.tif" for f in LOADS_N]
    for name in names:
        assert (root / "plain" / name).read_bytes() == (root / "instrument" / name).read_bytes()
    assert (root / "instrument" / "flim.ptu").is_file()
    assert not (root / "instrument" / "flim.tif").exists()


def test_the_truth_says_which_formats(routes):
    _, plain, instrument = routes
    assert plain["rheometer_format"] == "csv" and plain["flim"]["format"] == "tif"
    assert instrument["rheometer_format"] == "semicolons" and instrument["flim"]["format"] == "ptu"
    assert instrument["flim"]["photons"]["per_pixel_mean"] == 1000
    for key in ("static_friction_mn", "dynamic_friction_mn", "area_um2"):
        assert plain[key] == instrument[key]
    assert plain["flim"]["contact_pixels"] == instrument["flim"]["contact_pixels"]


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
        rheometer_files(root / "instrument" / "rheometer", loads_mn), loads_mn, export
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
    with pytest.raises(ValueError, match="shorter than the laser period"):
        TcspcSettings(1000, 200e-12, 2e-9, 30e-9, 25e-9)
    settings = {
        "formats": {"flim": "ptu", "rheometer": "brackets"},
        "flim_photons_per_pixel": 1000,
        "flim_irf_fwhm_ps": 200.0,
        "flim_irf_peak_ns": 2.0,
        "flim_tcspc_bin_ps": 16.0,
        "flim_sync_rate_mhz": 40.0,
    }
    assert OutputFormats.from_config(settings) == OutputFormats("ptu", "brackets", TCSPC)
