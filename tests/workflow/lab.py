"""A lab's project for the own-data tests (issues 36 and 52): copies of the small run's virtual
PS sphere as measured data, each less or other than the file its case is about, run once per
session (``lab_run`` in conftest.py), and projects that go on from it (``continued``).
test_own_data.py reads the lab run; test_corrupt_file.py, test_scan_on_cut_scans.py and
test_no_prior.py each go on from it, in whichever test process is free once it is done."""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from amontons.io.ptu import write_ptu_image
from amontons.io.rheometer import read_rheometer_csv
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES, write_rheometer_export
from amontons.io.tiff import read_image, write_image
from amontons.virtual.flim import TcspcSettings, photon_histograms

REPO = Path(__file__).resolve().parents[2]
SMALL = "small"
COMPLETE = "PS-complete"
# case -> (files removed from the sphere's folder, results it then lacks, relative to its
# results folder; "scenes/" stands for every scene's files)
CASES = {
    "PS-noreflection": (["reflection.tif"], ["measure/edge_gap.json", "measure/edge_gap.png",
                                            "measure/edge_gap.pdf"]),
    "PS-nobead": (["bead.tif"], ["measure/psf.png", "measure/psf.pdf"]),
    "PS-noabsorbance": (["absorbance.csv"], ["measure/grafting_density.json",
                                             "measure/absorbance.png", "measure/absorbance.pdf"]),
    "PS-noafmafter": (["afm_after.tif"], ["measure/topography.json", "measure/topography.png",
                                          "measure/topography.pdf",
                                          "measure/topography_fits.h5"]),
    "PS-noafm": (["afm_before.tif", "afm_after.tif"], ["measure/topography.json",
                                                       "measure/topography.png",
                                                       "measure/topography.pdf",
                                                       "measure/topography_fits.h5",
                                                       "measure/afm_before_levelled.h5",
                                                       "measure/afm_before_fit.h5",
                                                       "scenes/"]),
    "PS-norheometer": (["rheometer"], ["measure/friction.csv"]),
}  # fmt: skip
# AFM scans cut about the apex to a side (µm). The elastic scene's window here is 1.5 × the
# Hertz diameter (the template's): 50 µm holds the own windows of 25 and 50 mN (34.5 and
# 43.5 µm) and 100 mN's contact with the solver's margin (1.25 × 36.6 µm, the window clipped
# from 55 µm), not 200 mN's (1.25 × 46 µm); 24 µm holds no contact (23 µm at 25 mN).
CUT_SCANS = {"PS-cutscan": 50.0, "PS-noload": 24.0}
# A scan that holds two loads' contacts with the solver's margin (25 and 50 mN: 1.25 × 23 and
# 1.25 × 29 µm), not 100 mN's (1.25 × 36.6 µm): too few for the scans' criterion.
TWO_LOAD_SCANS = {"PS-twoloads": 40.0}
SCAN_SIDES_UM = CUT_SCANS | TWO_LOAD_SCANS
# The lab's two rheometer programs: RheoCompass, whose exports config/config.yaml's single
# map reads (named 'export'), and TRIOS, whose map the lab's config adds by a name (Snakemake
# merges the two files key by key). PS-trios's row names its map; PS-ptu's RheoCompass files
# are matched to theirs by their header. Every other sphere keeps our own CSV, under both.
EXPORT_MAPS = {"trios": EXPORT_SHAPES["units_row"].column_map()}
EXPORTED = {"PS-trios": ("units_row", "trios"), "PS-ptu": ("semicolons", None)}
# PS-ptu's FLIM is the photons of a PicoQuant PTU (its header states the pixel) and its
# sheet row leaves fluorescence_pixel_nm blank: every image of it states its own.
PTU_SPHERE = "PS-ptu"
# The PTU's photons: the full config's MicroTime 200 settings (config/config.yaml).
TCSPC = TcspcSettings(photons_per_pixel=1000, irf_fwhm_s=200e-12, irf_peak_s=2e-9,
                      bin_s=16e-12, sync_period_s=25e-9)  # fmt: skip
# The stand-in PSF of the sphere without a bead image: another FWHM than the bead gives, so
# that its renderings differ from the complete sphere's and show where the PSF came from.
STAND_IN = {"fwhm_nm": 500.0, "fwhm_se_nm": 25.0}
# The rules that measure a sphere's raw files (and level its AFM maps): what a project that
# goes on from the lab run's does not run again for a sphere the lab run measured.
MEASURING = ("measure_", "level_", "fit_load_area", "check_hertz")


def apex_px(heights: np.ndarray) -> tuple[float, float]:
    """The apex (row, col; px) of a sphere's map: the vertex of the least-squares paraboloid
    z = a + b r + c c + d (r² + c²)."""
    rows, cols = np.indices(heights.shape, dtype=float)
    design = np.stack([np.ones(rows.size), rows.ravel(), cols.ravel(),
                       (rows**2 + cols**2).ravel()], axis=1)  # fmt: skip
    _, b, c, d = np.linalg.lstsq(design, heights.ravel(), rcond=None)[0]
    return -b / (2 * d), -c / (2 * d)


def cut_scans(folder: Path, side_um: float) -> None:
    """The sphere's AFM scans cut to a square of ``side_um`` about the apex of the map before,
    with their pixel size: a smaller scan of the same instrument, centred as a user centres
    it."""
    before = read_image(folder / "afm_before.tif")
    side = int(round(side_um * 1e-6 / before.pixel_m))
    row, col = (int(round(x)) - side // 2 for x in apex_px(before.data))
    for name in ("afm_before.tif", "afm_after.tif"):
        scan = read_image(folder / name)
        write_image(folder / name, scan.data[row : row + side, col : col + side], scan.pixel_m)


def exported_rheometer(folder: Path, shape: str) -> None:
    """The sphere's rheometer CSVs rewritten as a program's export (the same traces)."""
    for path in sorted((folder / "rheometer").glob("*.csv")):
        trace = read_rheometer_csv(path)
        path.unlink()
        write_rheometer_export(path.with_suffix(EXPORT_SHAPES[shape].suffix), trace, shape)


def photons_for_map(folder: Path) -> None:
    """flim.tif (mean arrival times, ns) replaced by flim.ptu: each pixel's photons decay
    with the contact's 1.3 ns where the map is nearer it than the free molecules' 0.5 ns
    (config/config.yaml's virtual FLIM), at the map's pixel."""
    arrival = read_image(folder / "flim.tif")
    lifetime_s = np.where(arrival.data > 0.9, 1.3e-9, 0.5e-9)
    histograms = photon_histograms(lifetime_s, TCSPC, rng=np.random.default_rng(52))
    write_ptu_image(folder / "flim.ptu", histograms, bin_s=TCSPC.bin_s,
                    sync_period_s=TCSPC.sync_period_s, pixel_m=arrival.pixel_m)  # fmt: skip
    (folder / "flim.tif").unlink()


def lab_sphere(small_data, lab: Path, name: str, remove: list[str]) -> Path:
    """A copy of the virtual PS sphere as measured data, less ``remove``, with its AFM scan
    cut where SCAN_SIDES_UM names it, its rheometer files exported where EXPORTED names it,
    and its FLIM as photons for PTU_SPHERE."""
    folder = lab / name
    shutil.copytree(small_data / "resources" / "synthetic" / SMALL / "PS", folder)
    (folder / "truth.json").unlink()
    for entry in remove:
        path = folder / entry
        shutil.rmtree(path) if path.is_dir() else path.unlink()
    if name in SCAN_SIDES_UM:
        cut_scans(folder, SCAN_SIDES_UM[name])
    if name in EXPORTED:
        exported_rheometer(folder, EXPORTED[name][0])
    if name == PTU_SPHERE:
        photons_for_map(folder)
    return folder


def sheet_row(ps: pd.DataFrame, name: str, folder: Path) -> pd.DataFrame:
    """The PS row for sphere ``name`` in ``folder``: PTU_SPHERE leaves its pixel blank, and
    a sphere whose export map EXPORTED names says so in the rheometer_export column."""
    row = ps.assign(sphere=name, data_source=str(folder), rheometer_export="")
    if name == PTU_SPHERE:
        row = row.assign(fluorescence_pixel_nm="")
    if name in EXPORTED and EXPORTED[name][1] is not None:
        row = row.assign(rheometer_export=EXPORTED[name][1])
    return row


def lab_project(folder: Path, small_data, spheres: dict[str, list[str]]) -> Path:
    """``folder``/project, whose sheet lists ``spheres`` (name -> files removed), the PS row's
    values each, with two scenes (one rendered, one not) and no scans to keep the run short."""
    project = folder / "project"
    shutil.copytree(REPO / "config", project / "config")
    sheet = pd.read_csv(project / "config" / "materials.tsv", sep="\t", dtype=str)
    ps = sheet[sheet["sphere"] == "PS"]
    rows = [
        sheet_row(ps, name, lab_sphere(small_data, folder / "lab", name, rm))
        for name, rm in spheres.items()
    ]
    pd.concat(rows).to_csv(project / "config" / "own.tsv", sep="\t", index=False)
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    config["scenes"]["elastic"] = {"window_factor": 1.5}
    config.update(
        materials=["PS"],
        materials_sheet="config/own.tsv",
        run_scenes=["elastic", "greenwood_tripp"],
        run_scans=[],
        study={"run_curvature_pairs": []},
        optics={"psf": {"stand_in": STAND_IN}},
        rheometer_export=EXPORT_MAPS,
    )
    path.write_text(yaml.safe_dump(config))
    return project


def continued(base: Path, tmp_path, small_data, kept: list[str], new: list[str]) -> Path:
    """A project that goes on from the lab run's (``base``): its config, Snakemake's
    records, and the results and logs of the spheres ``kept``, whose rows keep naming the lab
    run's folders; its sheet is theirs and the rows of ``new``, fresh copies of the virtual PS
    sphere (lab_sphere) in this test's lab. What the lab run made of the kept spheres is not
    made again, as in a lab's project whose sheet gains a sphere."""
    project = tmp_path / "project"
    shutil.copytree(base / "config", project / "config")
    shutil.copytree(base / ".snakemake", project / ".snakemake",
                    ignore=shutil.ignore_patterns("log"))  # fmt: skip
    for sphere in kept:
        for folder in ("results", "logs"):
            part = Path(folder) / SMALL / "PS" / sphere
            shutil.copytree(base / part, project / part)
    sheet = pd.read_csv(project / "config" / "own.tsv", sep="\t", dtype=str)
    ps = sheet[sheet["sphere"] == COMPLETE]
    rows = [sheet[sheet["sphere"].isin(kept)]] + [
        sheet_row(ps, name, lab_sphere(small_data, tmp_path / "lab", name, [])) for name in new
    ]
    pd.concat(rows).to_csv(project / "config" / "own.tsv", sep="\t", index=False)
    return project


def jobs_of(run: subprocess.CompletedProcess, sphere: str) -> set[str]:
    """The rules of the jobs that ``run`` (Snakemake's log of them) ran for ``sphere``."""
    blocks = re.split(r"\n(?=(?:local)?rule \w+:)", run.stdout + run.stderr)
    return {
        re.match(r"(?:local)?rule (\w+):", block)[1]
        for block in blocks
        if re.search(rf"wildcards: .*\bsphere={re.escape(sphere)}(?:,|$)", block, re.M)
    }


def run_snakemake(project, *args, targets=()):
    """Snakemake on ``project`` with the test config, ``targets`` (its default: all) and
    ``args`` (the targets go before --configfile, which takes every word after it)."""
    command = [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile"), *targets]
    return subprocess.run(
        [*command, "-d", str(project), "--configfile", "config/test.yaml", *args],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=1800,
    )


def run_check(project):
    """python -m amontons.check on the project, its plans as JSON."""
    return subprocess.run(
        [sys.executable, "-m", "amontons.check", "--configfile", "config/test.yaml", "--json"],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=300,
    )


def made(project, sphere) -> set[str]:
    folder = project / "results" / SMALL / "PS" / sphere
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}


# The lab run's three commands, each kept as a JSON file beside its project so that every
# test process reads what the one that ran them saw.
LAB_COMMANDS = ("dry", "check", "run")


def make_lab_run(small_data: Path, folder: Path) -> None:
    """The run of the complete copy and of one copy per case in ``folder``/project, with its
    dry run and the check command's plan made before it, each command's outcome written
    beside it (read_lab_run)."""
    spheres = {COMPLETE: []} | {n: c[0] for n, c in CASES.items()}
    spheres |= dict.fromkeys([*CUT_SCANS, *EXPORTED], [])
    project = lab_project(folder, small_data, spheres)
    dry = run_snakemake(project, "-n")
    check = run_check(project)
    run = run_snakemake(project, "--cores", "2")
    for name, done in zip(LAB_COMMANDS, (dry, check, run), strict=True):
        outcome = {"args": done.args, "returncode": done.returncode}
        outcome |= {"stdout": done.stdout, "stderr": done.stderr}
        (folder / f"{name}.json").write_text(json.dumps(outcome))


def read_lab_run(folder: Path) -> tuple[Path, ...]:
    """(project, dry run, check, run) of make_lab_run's ``folder``, the commands as
    subprocess.CompletedProcess."""
    done = [
        subprocess.CompletedProcess(**json.loads((folder / f"{name}.json").read_text()))
        for name in LAB_COMMANDS
    ]
    return (folder / "project", *done)
