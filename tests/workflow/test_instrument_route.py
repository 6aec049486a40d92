"""The instrument-format route gives the same measurements as the TIFF/CSV route (issue 37).

The small run (tests/workflow/conftest.py) makes the virtual PS sphere as plain TIFF and our
CSV and measures it. A project of this module makes the same sphere (config/test.yaml, same
seed) in the instruments' own formats of the full run (config/config.yaml: OME-TIFF images,
PicoQuant PTU FLIM, a RheoCompass-style semicolon export read through the full run's column
map) and measures only what the formats reach: the contact areas per load, the PSF, the FLIM
lifetimes and the friction. Each quantity is then held to the small run's with the tolerance
its data allow (comments at each test).
"""

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from amontons.io.export_map import ExportMap
from amontons.io.layout import FLIM_NAME, FLIM_PTU_NAME, IMAGE_FORMATS
from amontons.io.rawdata import read_rheometer_traces
from amontons.io.rheometer import RheometerError, read_rheometer_csv
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES
from amontons.physics.gaussian import FWHM_PER_SIGMA
from amontons.workflow.paths import CONTACT_AREA, FRICTION, LIFETIME, PSF, TRUTH, RunPaths

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[2]
SPHERE = "PS"
PLAIN = "tif_csv"
INSTRUMENT = "instrument"
MEASURED = (CONTACT_AREA, PSF, LIFETIME, FRICTION)
# The full run's formats and column map, read from config/config.yaml so that this test
# follows the config.
FULL = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
FORMATS = FULL["virtual_experiment"]["formats"]
EXPORT = FULL["rheometer_export"]
# Standard errors between a lifetime and the other route's, or the truth: 3 (a two-sided
# 99.7 % band per comparison). The data are seeded, so each run gives the same numbers (all
# within 0.8 standard errors when this test was written); 3 keeps a change of seed or
# photon budget from failing one of the six comparisons by chance (1 would, more often than
# not), while a bias of one TCSPC bin (16 ps) puts the PTU's means 10 or more of their
# standard errors from the truth.
LIFETIME_SE = 3.0
# The friction's relative tolerance (why: test_friction_is_the_same_within_the_rounding_...).
FRICTION_RTOL = 1e-12


def _project(root: Path) -> Path:
    """A project folder from config/ whose test.yaml measures PS only, in the full run's
    formats, with its export column map."""
    project = root / INSTRUMENT
    shutil.copytree(REPO / "config", project / "config")
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    config["materials"] = [SPHERE]
    config["virtual_experiment"]["formats"] = FORMATS
    config["rheometer_export"] = EXPORT
    path.write_text(yaml.safe_dump(config))
    return project


def _route(project: Path, paths: RunPaths) -> dict[str, Path]:
    """The folders of a project's measurements and of its virtual sphere's files."""
    return {
        "measured": project / paths.measured("", SPHERE, SPHERE),
        "sphere": project / paths.synthetic_sphere(SPHERE),
    }


@pytest.fixture(scope="module")
def routes(request, tmp_path_factory):
    """The instrument project after its measurement jobs (the virtual sphere and the four
    measurements, no scenes or scans), beside the small run's PS sphere, which measures the
    same sphere in TIFF and our CSV. The small run is asked for once this project's run is
    done, so that the two run side by side."""
    assert FORMATS != {"images": "tif", "flim": "tif", "rheometer": "csv"}, FORMATS
    project = _project(tmp_path_factory.mktemp("routes"))
    paths = RunPaths(yaml.safe_load((REPO / "config" / "test.yaml").read_text())["run"])
    targets = [paths.measured(name, SPHERE, SPHERE) for name in MEASURED]
    command = [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile")]
    run = subprocess.run(
        [*command, "-d", str(project), "--configfile", "config/test.yaml", "--cores", "2"]
        + targets,
        cwd=project,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        timeout=1200,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    small_run = request.getfixturevalue("small_run")
    return {PLAIN: _route(small_run, paths), INSTRUMENT: _route(project, paths)}


def _text(routes, route: str, name: str) -> str:
    return (routes[route]["measured"] / name).read_text()


def _files(folder: Path) -> list[Path]:
    """The files of ``folder``, less Snakemake's hidden ``.snakemake_timestamp``."""
    return sorted(p for p in folder.iterdir() if not p.name.startswith("."))


def _truth(routes, route: str) -> dict:
    return json.loads((routes[route]["sphere"] / TRUTH).read_text())


def test_the_instrument_route_wrote_and_read_the_instruments_formats(routes):
    """So that the comparisons cannot pass by both projects using TIFF and CSV."""
    plain, instrument = routes[PLAIN]["sphere"], routes[INSTRUMENT]["sphere"]
    suffix = IMAGE_FORMATS[FORMATS["images"]]
    assert FORMATS["flim"] == "ptu" and suffix != ".tif"
    for folder, image_suffix, flim in (
        (plain, ".tif", FLIM_NAME),
        (instrument, suffix, FLIM_PTU_NAME),
    ):
        images = [folder / "bead.tif", folder / "reflection.tif"]
        images = [p.with_name(p.name.replace(".tif", image_suffix)) for p in images]
        images += _files(folder / "fluorescence")
        assert len(images) == 7 and all(p.name.endswith(image_suffix) for p in images), images
        assert all(p.is_file() for p in images) and (folder / flim).is_file()
    assert not (instrument / FLIM_NAME).exists() and not (plain / FLIM_PTU_NAME).exists()
    assert not any(p.name.endswith(suffix) for p in plain.rglob("*"))
    exports = _files(instrument / "rheometer")
    assert len(exports) == 5 and all(
        p.suffix == EXPORT_SHAPES[FORMATS["rheometer"]].suffix for p in exports
    )
    for path in exports:  # an export, not our CSV
        with pytest.raises(RheometerError):
            read_rheometer_csv(path)
    truth = _truth(routes, INSTRUMENT)
    assert (truth["image_format"], truth["rheometer_format"], truth["flim"]["format"]) == (
        FORMATS["images"],
        FORMATS["rheometer"],
        FORMATS["flim"],
    )
    # the measurements read those files
    areas = pd.read_csv(routes[INSTRUMENT]["measured"] / CONTACT_AREA)
    assert all(Path(p).name.endswith(suffix) for p in areas["image"])
    assert json.loads(_text(routes, INSTRUMENT, PSF))["image"].endswith(f"bead{suffix}")
    assert json.loads(_text(routes, INSTRUMENT, LIFETIME))["map"].endswith(FLIM_PTU_NAME)


def test_both_routes_measure_the_same_virtual_sphere(routes):
    """The same seed gives the same contact, loads and friction truth in either format: only
    the truth's format fields and its FLIM record (noise of the map, or the photons) differ."""
    plain, instrument = _truth(routes, PLAIN), _truth(routes, INSTRUMENT)
    for truth in (plain, instrument):
        for key in ("image_format", "rheometer_format", "flim"):
            truth.pop(key)
    assert plain == instrument


def test_contact_areas_and_psf_are_the_same_bytes(routes):
    """The OME-TIFFs hold the TIFFs' pixels and pixel size (0.2 µm read as the same double as
    50000 px/cm), so the contact-area table and the PSF record are the same bytes. Excluded:
    the names of the files read (contact-area column ``image``, PSF key ``image``), whose
    suffix is the format's; ``pixel_source`` ('file') is compared, the same in both."""
    suffix = IMAGE_FORMATS[FORMATS["images"]]
    for name in (CONTACT_AREA, PSF):
        plain, instrument = _text(routes, PLAIN, name), _text(routes, INSTRUMENT, name)
        assert instrument.count(suffix) == plain.count(".tif") > 0, name
        assert instrument.replace(suffix, ".tif") == plain, name


def test_friction_is_the_same_within_the_rounding_of_the_units(routes):
    """Both files hold 9 significant digits of the same trace (our CSV in SI units, the export
    in mrad and mN·m: a power of ten moves no digit), so the readers' doubles differ only by
    the roundings of the text to a double and of the unit conversion, a few of 2^-53 each:
    rtol 1e-15 for the samples (one ulp, 2.2e-16, measured).
    The friction statistics (peaks, means and standard errors of 2000 samples) add a few
    roundings more (1e-15 measured): FRICTION_RTOL, 1e-12, holds them with a margin of 1000,
    while one different digit in a file (1e-9 to 1e-8 of a sample) would stand out in the
    samples' comparison by a factor of 1e6."""
    loads = [25, 50, 100, 200, 300]
    names = [f"rheometer/{load}.csv" for load in loads]
    plain = read_rheometer_traces([routes[PLAIN]["sphere"] / n for n in names], loads)
    instrument = read_rheometer_traces(
        [routes[INSTRUMENT]["sphere"] / n for n in names],
        loads,
        {"export": ExportMap.from_config(EXPORT)},
    )
    for a, b in zip(plain, instrument, strict=True):
        assert a.rotation_radius_m == b.rotation_radius_m
        for field in ("time_s", "angle_rad", "normal_force_n", "torque_n_m"):
            np.testing.assert_allclose(getattr(b, field), getattr(a, field), rtol=1e-15, atol=0)
    plain = pd.read_csv(routes[PLAIN]["measured"] / FRICTION)
    instrument = pd.read_csv(routes[INSTRUMENT]["measured"] / FRICTION)
    assert list(plain.columns) == list(instrument.columns)
    # 'file' names the file read: the same name (the export's suffix is .csv too) here
    numbers = plain.select_dtypes("number").columns
    assert len(numbers) == len(plain.columns) - 1
    np.testing.assert_allclose(instrument[numbers], plain[numbers], rtol=FRICTION_RTOL, atol=0)


def _ptu_standard_error(record: dict, side: str, truth: dict) -> float:
    """The Poisson standard error (ns) of the PTU route's mean arrival time on ``side``: a
    photon's delay after the instrument response's peak has the variance τ² + σ_irf² (the
    exponential decay's and the Gaussian response's), and the side's mean averages the pixels'
    means of N_i photons each, so its variance is (τ² + σ_irf²) Σ(1/N_i) / n² = (τ² +
    σ_irf²) / N_total within 1/N of a pixel (0.1 %); the time origin, fitted to the whole
    image and common to every pixel, adds its own standard error."""
    photons = truth["flim"]["photons"]
    sigma_irf_ns = photons["irf_fwhm_ps"] * 1e-3 / FWHM_PER_SIGMA
    tau_ns = truth["flim"]["contact_ns" if side == "inside" else "outside_ns"]
    total = record["photons"][side]["total"]
    poisson = math.sqrt((tau_ns**2 + sigma_irf_ns**2) / total)
    return math.hypot(poisson, record["time_origin"]["standard_error_ns"])


def test_lifetimes_agree_within_their_standard_errors_and_with_the_truth(routes):
    """The PTU holds Poisson photons drawn from the decays, the TIFF map a Gaussian scatter of
    0.1 ns per pixel standing in for them: other noise, so the means differ. Each side's mean
    is held to the other route's, and to the truth, within LIFETIME_SE standard errors: the
    PTU's the Poisson one of its photon counts (_ptu_standard_error), the TIFF map's the
    record's (the pixels' sd / √n)."""
    plain = json.loads(_text(routes, PLAIN, LIFETIME))
    instrument = json.loads(_text(routes, INSTRUMENT, LIFETIME))
    truth = _truth(routes, INSTRUMENT)
    assert _truth(routes, PLAIN)["flim"]["noise_ns"] > 0 and "photons" not in plain
    for side, true_ns in (
        ("inside", truth["flim"]["contact_ns"]),
        ("outside", truth["flim"]["outside_ns"]),
    ):
        tif_ns, tif_se = plain[f"{side}_ns"]["mean"], plain[f"{side}_ns"]["standard_error"]
        ptu_ns, ptu_se = (
            instrument[f"{side}_ns"]["mean"],
            _ptu_standard_error(instrument, side, truth),
        )
        # the photons behind the record: about photons_per_pixel in each of its pixels
        per_pixel = instrument["photons"][side]["total"] / instrument[f"{side}_ns"]["n"]
        assert per_pixel == pytest.approx(truth["flim"]["photons"]["per_pixel_mean"], rel=0.01)
        assert abs(ptu_ns - tif_ns) <= LIFETIME_SE * math.hypot(tif_se, ptu_se), side
        assert abs(ptu_ns - true_ns) <= LIFETIME_SE * ptu_se, side
        assert abs(tif_ns - true_ns) <= LIFETIME_SE * tif_se, side
    origin = instrument["time_origin"]
    irf_peak_ns = truth["flim"]["photons"]["irf_peak_ns"]
    assert abs(origin["after_sync_ns"] - irf_peak_ns) <= LIFETIME_SE * origin["standard_error_ns"]
