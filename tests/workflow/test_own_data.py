"""Own data as a lab has it (issues 36 and 52): spheres with a file missing, one bad sphere
among good ones, rheometer files of two programs beside our own CSVs under one config, a
FLIM PTU with the sheet's pixel left blank, scans smaller than the windows, a scan with
nothing to judge, and a sphere scanned without the sheet's priors. Each sphere is a copy of
the small run's virtual PS sphere in a measured folder, less or other than the file the case
is about, so that every output it still makes can be compared with the complete copy's, made
in the same run."""

import json
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from amontons.io.ptu import write_ptu_image
from amontons.io.rheometer import read_rheometer_csv
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES, write_rheometer_export
from amontons.io.tiff import read_image, write_image
from amontons.models import with_parameter
from amontons.virtual.flim import TcspcSettings, photon_histograms

pytestmark = pytest.mark.workflow

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
# What the PSF enters: the sphere without a bead image renders with the stand-in, so these
# records may differ from the complete sphere's (the PSF and the rendered areas must).
PSF_DEPENDENT = {
    "measure/psf.json",
    "scenes/elastic/render.csv",
    "scenes/elastic/comparison.csv",
    "scenes/elastic/registration.json",
    "scenes/scene_fits.json",
}
# The stand-in PSF of the sphere without a bead image: another FWHM than the bead gives, so
# that its renderings differ from the complete sphere's and show where the PSF came from.
STAND_IN = {"fwhm_nm": 500.0, "fwhm_se_nm": 25.0}
# The rules that measure a sphere's raw files (and level its AFM maps): what a project that
# goes on from the lab run's does not run again for a sphere the lab run measured.
MEASURING = ("measure_", "level_", "fit_load_area", "check_hertz")


def _apex_px(heights: np.ndarray) -> tuple[float, float]:
    """The apex (row, col; px) of a sphere's map: the vertex of the least-squares paraboloid
    z = a + b r + c c + d (r² + c²)."""
    rows, cols = np.indices(heights.shape, dtype=float)
    design = np.stack([np.ones(rows.size), rows.ravel(), cols.ravel(),
                       (rows**2 + cols**2).ravel()], axis=1)  # fmt: skip
    _, b, c, d = np.linalg.lstsq(design, heights.ravel(), rcond=None)[0]
    return -b / (2 * d), -c / (2 * d)


def _cut_scans(folder: Path, side_um: float) -> None:
    """The sphere's AFM scans cut to a square of ``side_um`` about the apex of the map before,
    with their pixel size: a smaller scan of the same instrument, centred as a user centres
    it."""
    before = read_image(folder / "afm_before.tif")
    side = int(round(side_um * 1e-6 / before.pixel_m))
    row, col = (int(round(x)) - side // 2 for x in _apex_px(before.data))
    for name in ("afm_before.tif", "afm_after.tif"):
        scan = read_image(folder / name)
        write_image(folder / name, scan.data[row : row + side, col : col + side], scan.pixel_m)


def _exported_rheometer(folder: Path, shape: str) -> None:
    """The sphere's rheometer CSVs rewritten as a program's export (the same traces)."""
    for path in sorted((folder / "rheometer").glob("*.csv")):
        trace = read_rheometer_csv(path)
        path.unlink()
        write_rheometer_export(path.with_suffix(EXPORT_SHAPES[shape].suffix), trace, shape)


def _photons_for_map(folder: Path) -> None:
    """flim.tif (mean arrival times, ns) replaced by flim.ptu: each pixel's photons decay
    with the contact's 1.3 ns where the map is nearer it than the free molecules' 0.5 ns
    (config/config.yaml's virtual FLIM), at the map's pixel."""
    arrival = read_image(folder / "flim.tif")
    lifetime_s = np.where(arrival.data > 0.9, 1.3e-9, 0.5e-9)
    histograms = photon_histograms(lifetime_s, TCSPC, rng=np.random.default_rng(52))
    write_ptu_image(folder / "flim.ptu", histograms, bin_s=TCSPC.bin_s,
                    sync_period_s=TCSPC.sync_period_s, pixel_m=arrival.pixel_m)  # fmt: skip
    (folder / "flim.tif").unlink()


def _lab_sphere(small_data, lab: Path, name: str, remove: list[str]) -> Path:
    """A copy of the virtual PS sphere as measured data, less ``remove``, with its AFM scan
    cut where CUT_SCANS names it, its rheometer files exported where EXPORTED names it, and
    its FLIM as photons for PTU_SPHERE."""
    folder = lab / name
    shutil.copytree(small_data / "resources" / "synthetic" / SMALL / "PS", folder)
    (folder / "truth.json").unlink()
    for entry in remove:
        path = folder / entry
        shutil.rmtree(path) if path.is_dir() else path.unlink()
    if name in CUT_SCANS | TWO_LOAD_SCANS:
        _cut_scans(folder, (CUT_SCANS | TWO_LOAD_SCANS)[name])
    if name in EXPORTED:
        _exported_rheometer(folder, EXPORTED[name][0])
    if name == PTU_SPHERE:
        _photons_for_map(folder)
    return folder


def _sheet_row(ps: pd.DataFrame, name: str, folder: Path) -> pd.DataFrame:
    """The PS row for sphere ``name`` in ``folder``: PTU_SPHERE leaves its pixel blank, and
    a sphere whose export map EXPORTED names says so in the rheometer_export column."""
    row = ps.assign(sphere=name, data_source=str(folder), rheometer_export="")
    if name == PTU_SPHERE:
        row = row.assign(fluorescence_pixel_nm="")
    if name in EXPORTED and EXPORTED[name][1] is not None:
        row = row.assign(rheometer_export=EXPORTED[name][1])
    return row


def _project(tmp_path, small_data, spheres: dict[str, list[str]]) -> Path:
    """A project folder whose sheet lists ``spheres`` (name -> files removed), the PS row's
    values each, with two scenes (one rendered, one not) and no scans to keep the run short."""
    project = tmp_path / "project"
    shutil.copytree(REPO / "config", project / "config")
    sheet = pd.read_csv(project / "config" / "materials.tsv", sep="\t", dtype=str)
    ps = sheet[sheet["sphere"] == "PS"]
    rows = [
        _sheet_row(ps, name, _lab_sphere(small_data, tmp_path / "lab", name, rm))
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


def _continued(lab_project: Path, tmp_path, small_data, kept: list[str], new: list[str]) -> Path:
    """A project that goes on from the lab run's (``lab_project``): its config, Snakemake's
    records, and the results and logs of the spheres ``kept``, whose rows keep naming the lab
    run's folders; its sheet is theirs and the rows of ``new``, fresh copies of the virtual PS
    sphere (_lab_sphere) in this test's lab. What the lab run made of the kept spheres is not
    made again, as in a lab's project whose sheet gains a sphere."""
    project = tmp_path / "project"
    shutil.copytree(lab_project / "config", project / "config")
    shutil.copytree(lab_project / ".snakemake", project / ".snakemake",
                    ignore=shutil.ignore_patterns("log"))  # fmt: skip
    for sphere in kept:
        for folder in ("results", "logs"):
            part = Path(folder) / SMALL / "PS" / sphere
            shutil.copytree(lab_project / part, project / part)
    sheet = pd.read_csv(project / "config" / "own.tsv", sep="\t", dtype=str)
    ps = sheet[sheet["sphere"] == COMPLETE]
    rows = [sheet[sheet["sphere"].isin(kept)]] + [
        _sheet_row(ps, name, _lab_sphere(small_data, tmp_path / "lab", name, [])) for name in new
    ]
    pd.concat(rows).to_csv(project / "config" / "own.tsv", sep="\t", index=False)
    return project


def _jobs_of(run: subprocess.CompletedProcess, sphere: str) -> set[str]:
    """The rules of the jobs that ``run`` (Snakemake's log of them) ran for ``sphere``."""
    blocks = re.split(r"\n(?=(?:local)?rule \w+:)", run.stdout + run.stderr)
    return {
        re.match(r"(?:local)?rule (\w+):", block)[1]
        for block in blocks
        if re.search(rf"wildcards: .*\bsphere={re.escape(sphere)}(?:,|$)", block, re.M)
    }


def _snakemake(project, *args, targets=()):
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


def _check(project):
    """python -m amontons.check on the project, its plans as JSON."""
    return subprocess.run(
        [sys.executable, "-m", "amontons.check", "--configfile", "config/test.yaml", "--json"],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=300,
    )


def _made(project, sphere) -> set[str]:
    folder = project / "results" / SMALL / "PS" / sphere
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def lab_run(small_data, tmp_path_factory):
    """The run of the complete copy and of one copy per case, with its dry run and the check
    command's plan made before it."""
    tmp_path = tmp_path_factory.mktemp("own_data")
    spheres = {COMPLETE: []} | {n: c[0] for n, c in CASES.items()}
    spheres |= dict.fromkeys([*CUT_SCANS, *EXPORTED], [])
    project = _project(tmp_path, small_data, spheres)
    dry = _snakemake(project, "-n")
    check = _check(project)
    run = _snakemake(project, "--cores", "2")
    return project, dry, check, run


def test_a_missing_file_stops_nothing_else(lab_run):
    _, dry, _, run = lab_run
    assert dry.returncode == 0, dry.stderr[-3000:]
    assert run.returncode == 0, run.stderr[-3000:]


@pytest.mark.parametrize("sphere", sorted(CASES))
def test_a_sphere_lacks_exactly_what_needed_its_missing_file(lab_run, sphere):
    project = lab_run[0]
    lacking = CASES[sphere][1]
    expected = {
        name
        for name in _made(project, COMPLETE)
        if name not in lacking and not any(name.startswith(p) for p in lacking if p[-1] == "/")
    }
    assert _made(project, sphere) == expected


# A solve's record holds its wall time, which no two runs share: compared without it.
TIMINGS = ("wall_time_s",)


def _without_timings(value):
    if isinstance(value, dict):
        return {k: _without_timings(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [_without_timings(v) for v in value]
    return value


def _same_bytes(project, sphere, name) -> bool:
    """A record of ``sphere`` against the complete sphere's: the same bytes, once the sphere's
    name and its folder's (which records cite) are the complete sphere's; a JSON record with
    a wall time, the same values but that."""
    root = project / "results" / SMALL / "PS"
    text = (root / sphere / name).read_text().replace(sphere, COMPLETE)
    complete = (root / COMPLETE / name).read_text()
    if name.endswith(".json") and any(f'"{key}"' in complete for key in TIMINGS):
        return _without_timings(json.loads(text)) == _without_timings(json.loads(complete))
    return text == complete


@pytest.mark.parametrize("sphere", sorted(CASES))
def test_every_other_record_is_the_complete_spheres(lab_run, sphere):
    """Tables and records (CSV, JSON) byte for byte; figures carry the sphere's name in their
    titles, and the stand-in PSF changes the renderings of the sphere without a bead (they are
    checked to differ, which shows the stand-in was used)."""
    project = lab_run[0]
    records = sorted(n for n in _made(project, sphere) if n.endswith((".csv", ".json")))
    rendered = [n for n in records if n in PSF_DEPENDENT] if sphere == "PS-nobead" else []
    same = [n for n in records if n not in rendered]
    assert records and [n for n in same if not _same_bytes(project, sphere, n)] == []
    if sphere == "PS-nobead":
        # the solve is the complete sphere's; its PSF and what is rendered with it are not
        assert "scenes/elastic/solve.json" in same
        assert not _same_bytes(project, sphere, "measure/psf.json")
        assert not _same_bytes(project, sphere, "scenes/elastic/render.csv")
        psf = json.loads(
            (project / "results" / SMALL / "PS" / sphere / "measure/psf.json").read_text()
        )
        assert psf["fwhm_nm"] == {"estimate": 500.0, "standard_error": 25.0}
        assert psf["source"] == "config optics.psf.stand_in"


# The exports hold the traces' 9 significant digits in other units than our CSV's SI: one
# rounding of the unit conversion each way (~1e-16 relative) reaches the friction, well
# inside 1e-12, while one digit more or less in a file (1e-9 of a sample) would be outside.
SAME_FRICTION = 1e-12
# What PS-ptu's records may differ in from the complete sphere's: its lifetime comes from
# photons, not from a map.
FROM_PHOTONS = {"measure/lifetime.json"}


@pytest.mark.parametrize("sphere", sorted(EXPORTED))
def test_the_exports_of_two_programs_give_our_csvs_friction(lab_run, sphere):
    """One config reads our CSVs (every other sphere) and two programs' exports (one named
    by its sheet row, one matched by its header): the friction of the same traces, and every
    other record of the complete sphere (PS-ptu's lifetime aside)."""
    project = lab_run[0]
    root = project / "results" / SMALL / "PS"
    ours = pd.read_csv(root / COMPLETE / "measure/friction.csv")
    theirs = pd.read_csv(root / sphere / "measure/friction.csv")
    assert list(theirs.columns) == list(ours.columns) and len(theirs) == len(ours) == 5
    numbers = ours.select_dtypes("number").columns
    np.testing.assert_allclose(theirs[numbers], ours[numbers], rtol=SAME_FRICTION, atol=0)
    records = sorted(n for n in _made(project, sphere) if n.endswith((".csv", ".json")))
    skip = {"measure/friction.csv"} | (FROM_PHOTONS if sphere == PTU_SPHERE else set())
    differ = [n for n in records if n not in skip and not _same_bytes(project, sphere, n)]
    assert len(records) > 10 and differ == []


def test_the_check_names_the_reader_of_every_rheometer_file(lab_run):
    """Before the run, python -m amontons.check says which reader takes each rheometer file:
    our CSV whatever the maps, else the map the row names or the header matches."""
    plans = {plan["sphere"]: plan for plan in json.loads(lab_run[2].stdout)}
    expected = {COMPLETE: "our CSV", "PS-trios": "export map 'trios'",
                "PS-ptu": "export map 'export'"}  # fmt: skip
    for sphere, reader in expected.items():
        files = [f for f in plans[sphere]["files"] if "/rheometer/" in f["path"]]
        assert len(files) == 5 and {f.get("reader") for f in files} == {reader}, files
        assert all(f["rows"] >= 10 for f in files)
    (flim,) = [f for f in plans[PTU_SPHERE]["files"] if f["path"].endswith("flim.ptu")]
    assert flim["pixel_from"] == "file" and flim["pixel_nm"] > 0


def test_a_ptu_with_a_blank_sheet_pixel_gives_the_lifetimes_of_its_photons(lab_run):
    """The sheet leaves PS-ptu's pixel blank and its FLIM is photons: the header's pixel
    serves, and the lifetimes are the photons' (1.3 ns in contact, 0.5 ns outside; within
    0.05 ns, several standard errors of 1000 photons a pixel over the regions' pixels)."""
    project = lab_run[0]
    record = json.loads(
        (project / "results" / SMALL / "PS" / PTU_SPHERE / "measure/lifetime.json").read_text()
    )
    assert record["map"].endswith("flim.ptu") and record["photons"]["inside"]["total"] > 0
    assert record["inside_ns"]["mean"] == pytest.approx(1.3, abs=0.05)
    assert record["outside_ns"]["mean"] == pytest.approx(0.5, abs=0.05)


def test_the_dry_run_says_what_each_sphere_will_not_get_and_why(lab_run):
    said = lab_run[1].stdout + lab_run[1].stderr  # Snakemake logs a dry run to stdout
    for sphere, (removed, _) in CASES.items():
        line = next(line for line in said.splitlines() if f"sphere {sphere} (PS):" in line)
        assert "will not be made" in line
        assert removed[0].split(".")[0] in line  # names what it looked for
    assert f"sphere {COMPLETE} " not in said


def test_the_check_lists_what_the_run_then_makes(lab_run):
    project, _, check, _ = lab_run
    assert check.returncode == 0, check.stderr
    for plan in json.loads(check.stdout):
        folder = f"results/{SMALL}/PS/{plan['sphere']}/"
        planned = {path.removeprefix(folder) for path in plan["outputs"]}
        # the plan names what the targets ask for; intermediate files (fields, renders) are
        # the run's own business
        assert planned and planned <= _made(project, plan["sphere"])
        lacking = CASES.get(plan["sphere"], ([], []))[1]
        assert not planned & set(lacking)
        assert bool(plan["left_out"]) == (plan["sphere"] in CASES)
        assert all("pixel_nm" not in f or f["pixel_nm"] for f in plan["files"])


def test_the_material_tables_hold_the_spheres_that_have_their_inputs(lab_run):
    project = lab_run[0]
    material = project / "results" / SMALL / "PS"
    amontons = pd.read_csv(material / "amontons.csv")
    everyone = {COMPLETE, *CASES, *CUT_SCANS, *EXPORTED}
    assert set(amontons["sphere"]) == everyone - {"PS-norheometer"}
    scenes = pd.read_csv(material / "scenes.csv")
    assert set(scenes["sphere"]) == everyone - {"PS-noafm"}


def _spheres_in(project, table: str) -> set[str]:
    return set(pd.read_csv(project / "results" / SMALL / "PS" / table)["sphere"])


def test_one_corrupt_file_stops_only_its_sphere_until_it_is_fixed(lab_run, small_data, tmp_path):
    """Two spheres, one with a truncated fluorescence image: every output of the other is
    made, and the run exits non-zero naming the file. A rerun makes PS's tables and the
    summary without the failed sphere, marked failed, and still exits non-zero; once the file
    is fixed, the next run puts the sphere back and exits 0 (amontons.workflow.ledger). The
    project goes on from the lab run's (_continued): the complete sphere's outputs are that
    run's, and no job of it runs again."""
    project = _continued(lab_run[0], tmp_path, small_data, [COMPLETE], ["PS-corrupt"])
    image = tmp_path / "lab" / "PS-corrupt" / "fluorescence" / "100.tif"
    intact = image.read_bytes()
    image.write_bytes(intact[:2000])
    run = _snakemake(project, "--cores", "2")
    assert run.returncode != 0
    assert _jobs_of(run, COMPLETE) == set() and _jobs_of(run, "PS-corrupt")
    assert str(image) in run.stderr
    check = _check(project)
    plans = {plan["sphere"]: plan for plan in json.loads(check.stdout)}
    for path in plans[COMPLETE]["outputs"]:
        assert (project / path).is_file(), path
    errors = [f["error"] for f in plans["PS-corrupt"]["files"] if "error" in f]
    assert errors and str(image) in errors[0]
    # the check reads the run's record too: the next run holds the sphere out
    assert plans[COMPLETE]["failed"] == [] and str(image) in plans["PS-corrupt"]["failed"][0]
    # the failure, per sphere, with its error, in the run's record and at the end of its log
    record = project / "results" / SMALL / "failed_jobs.csv"
    failed = pd.read_csv(record)
    assert set(failed["sphere"]) == {"PS-corrupt"} and set(failed["material"]) == {"PS"}
    assert failed["error"].str.contains(str(image), regex=False).all()
    assert all((project / log).is_file() for log in failed["log"])
    assert f"sphere PS-corrupt (PS): {failed['rule'].iloc[0]} failed:" in run.stderr
    # PS's tables read every sphere, so this run could not make them; it says what a rerun does
    summary = project / "results" / SMALL / "summary.md"
    assert not (project / "results" / SMALL / "PS" / "load_area.csv").exists()
    assert "run again to make PS's tables, figures, summary and report without PS-corrupt" in (
        run.stderr
    )

    rerun = _snakemake(project, "--cores", "2")
    assert rerun.returncode != 0  # the failed jobs ran again, and failed again
    assert "sphere PS-corrupt (PS): failed in an earlier run: " in rerun.stderr
    assert _spheres_in(project, "load_area.csv") == _spheres_in(project, "scenes.csv") == {COMPLETE}
    text = summary.read_text()
    held = text[text.index("## Failed: held out of every table and figure") :]
    assert "sphere PS-corrupt (PS): failed in an earlier run: measure_contact_area: " in held
    assert str(image) in held
    assert set(pd.read_csv(record)["sphere"]) == {"PS-corrupt"}

    image.write_bytes(intact)  # the file fixed: the sphere's data stamp changes
    fixed = _snakemake(project, "--cores", "2")
    assert fixed.returncode == 0, fixed.stderr[-3000:]
    assert (
        _spheres_in(project, "load_area.csv")
        == _spheres_in(project, "scenes.csv")
        == {
            COMPLETE,
            "PS-corrupt",
        }
    )
    assert "Failed" not in summary.read_text()
    assert not record.exists()


def _scene_record(project, sphere, name):
    path = project / "results" / SMALL / "PS" / sphere / "scenes" / "elastic" / name
    return json.loads(path.read_text()) if name.endswith(".json") else pd.read_csv(path)


def _elastic_fit(project, sphere):
    """The elastic scene's load-area fit, from its sphere's fits file."""
    path = project / "results" / SMALL / "PS" / sphere / "scenes" / "scene_fits.json"
    return json.loads(path.read_text())["elastic"]


def test_a_scan_smaller_than_the_contact_simulates_the_loads_it_holds(lab_run):
    """The cut scan holds the three smaller loads' windows: the scene simulates those, lists
    200 and 300 mN as outside_scan with the window each needs (larger than the scan holds),
    compares and fits on the three, and the tables say what was left out."""
    project = lab_run[0]
    solve = _scene_record(project, "PS-cutscan", "solve.json")
    assert solve["loads_mn"] == [25.0, 50.0, 100.0]
    # the solver's load meets the target to its tolerance, not to the bit
    assert [row["load_mn"] for row in solve["loads"]] == pytest.approx([25, 50, 100], rel=1e-6)
    assert [row["load_mn"] for row in solve["outside_scan"]] == [200.0, 300.0]
    held = solve["largest_window_in_scan_um"]
    assert solve["window_um"] <= held < min(row["window_um"] for row in solve["outside_scan"])
    assert held <= min(solve["scan_um"]) <= CUT_SCANS["PS-cutscan"]
    comparison = _scene_record(project, "PS-cutscan", "comparison.csv")
    assert comparison["status"].tolist() == ["compared"] * 3 + ["outside_scan"] * 2
    outside = comparison[comparison["status"] == "outside_scan"]
    assert outside["iou"].isna().all() and outside["measured_area_um2"].gt(0).all()
    fit = _elastic_fit(project, "PS-cutscan")
    assert fit["loads_mn"] == pytest.approx([25, 50, 100], rel=1e-6)
    assert fit["not_fitted"] is None
    assert fit["rendered_area"]["exponent"]["estimate"] > 0
    scenes = pd.read_csv(project / "results" / SMALL / "PS" / "scenes.csv")
    row = scenes[(scenes["sphere"] == "PS-cutscan") & (scenes["scene"] == "elastic")].iloc[0]
    assert row["left_out"] == "outside_scan: 200, 300 mN"
    complete = scenes[(scenes["sphere"] == COMPLETE)]
    assert complete["left_out"].isna().all()  # an empty note: nothing left out


def test_a_window_clipped_to_the_scan_gives_the_complete_spheres_areas(lab_run):
    """PS-cutscan's 100 mN window (55 µm) is clipped to the 50 µm scan, where its contact
    fits with the solver's margin: the record says so, and the areas of its three loads are
    the complete sphere's (solved on their own windows) within the draft preset's stated
    rendered-area error (config accuracy.preset_budgets.draft) for the rendered area, and
    within 5 % for the solver's true area: the cut scan's own sphere fit puts the apex, and
    so the 411 nm solver grid, a fraction of a pixel off the complete scan's, which moves a
    rough contact's edge pixels (2.4 % at 25 mN, ~1000 pixels in contact, on 2026-11-27).
    That the clipped window itself changes nothing is tests/simulate/test_clipped_window.py's
    (the same grid: the same contact, pixel for pixel)."""
    project = lab_run[0]
    solve = _scene_record(project, "PS-cutscan", "solve.json")
    clipped = solve["window_clipped"]
    assert clipped["own_window_um"] > min(solve["scan_um"]) >= clipped["clipped_to_um"]
    assert clipped["clipped_to_um"] == pytest.approx(solve["window_um"], rel=1e-12)
    assert 0.8 < clipped["fraction"] < 1.0
    assert "window_clipped" not in _scene_record(project, COMPLETE, "solve.json")
    complete = _scene_record(project, COMPLETE, "comparison.csv").set_index("load_mn")
    cut = _scene_record(project, "PS-cutscan", "comparison.csv").set_index("load_mn")
    budget = yaml.safe_load((REPO / "config" / "config.yaml").read_text())["accuracy"][
        "preset_budgets"]["draft"]["rendered_area"]  # fmt: skip
    for load in (25.0, 50.0, 100.0):
        rendered = cut.loc[load, "simulated_area_um2"] / complete.loc[load, "simulated_area_um2"]
        assert abs(rendered - 1) <= budget, (load, rendered)
    # the solver meets the load to its tolerance, not to the bit: keyed by the load rounded
    areas = {round(row["load_mn"], 6): row["area_um2"] for row in solve["loads"]}
    complete_areas = {
        round(row["load_mn"], 6): row["area_um2"]
        for row in _scene_record(project, COMPLETE, "solve.json")["loads"]
    }
    for load, area in areas.items():
        assert area == pytest.approx(complete_areas[load], rel=0.05), load


def test_a_scan_that_holds_no_load_gets_a_record_and_no_failed_job(lab_run):
    """The scan too small for any load's window: the scene's records say so (no load solved,
    every load outside_scan, no fit and why), its greenwood_tripp scene (no window) is
    whole, and the run exits 0 (test_a_missing_file_stops_nothing_else)."""
    project = lab_run[0]
    solve = _scene_record(project, "PS-noload", "solve.json")
    assert solve["status"] == "outside_scan" and solve["loads"] == []
    assert [row["load_mn"] for row in solve["outside_scan"]] == [25, 50, 100, 200, 300]
    comparison = _scene_record(project, "PS-noload", "comparison.csv")
    assert set(comparison["status"]) == {"outside_scan"} and len(comparison) == 5
    fit = _elastic_fit(project, "PS-noload")
    assert fit["solver_area"] is None and "0 loads simulated" in fit["not_fitted"]
    scenes = pd.read_csv(project / "results" / SMALL / "PS" / "scenes.csv")
    row = scenes[(scenes["sphere"] == "PS-noload") & (scenes["scene"] == "elastic")].iloc[0]
    assert pd.isna(row["exponent"]) and "not fitted: 0 loads simulated" in row["left_out"]
    gt = project / "results" / SMALL / "PS" / "PS-noload" / "scenes" / "greenwood_tripp"
    assert len(json.loads((gt / "solve.json").read_text())["loads"]) == 5


def test_the_check_and_the_dry_run_predict_the_loads_outside_the_scan(lab_run):
    """The check reads each scan's size and, with the apex at its centre, names the loads the
    run then leaves out; so does the dry run, from the TIFF scans' headers."""
    project, dry, check, _ = lab_run
    plans = {plan["sphere"]: plan for plan in json.loads(check.stdout)}
    said = dry.stdout + dry.stderr
    for sphere in (*CUT_SCANS, COMPLETE):
        predicted = plans[sphere]["scenes"]["elastic"]
        solve = _scene_record(project, sphere, "solve.json")
        assert predicted["simulated_mn"] == solve["loads_mn"], sphere
        left_out = [r["load_mn"] for r in solve["outside_scan"]]
        assert [r["load_mn"] for r in predicted["outside_scan"]] == left_out, sphere
        named = re.findall(rf"sphere {sphere} \(PS\): scene elastic: (\S+) mN outside_scan", said)
        assert [float(load) for load in named] == left_out, sphere
        # and where the window will be clipped to the scan, as the run then records it
        clipped = _scene_record(project, sphere, "solve.json").get("window_clipped")
        assert (predicted["clipped_from_um"] is None) == (clipped is None), sphere
        said_clipped = f"sphere {sphere} (PS): scene elastic: window clipped from" in said
        assert said_clipped == (clipped is not None), sphere


def test_a_scan_on_a_cut_scan_judges_the_loads_it_holds(lab_run, small_data, tmp_path):
    """The p_Y scan (three values, to keep it short) of the sphere whose AFM scan holds three
    loads: every value is solved and compared on those three, the best value's fit is over
    them, and best.json and the model table list 200 and 300 mN as outside_scan. Beside it,
    a sphere whose scan holds no load's contact: its scan is not decided, an answer that
    says why, and the run exits 0 (test_a_scan_with_nothing_to_judge_says_why). The project
    goes on from the lab run's (_continued), with the scan switched on: the two cut spheres'
    measurements are that run's, and only their new scene and scan run."""
    project = _continued(lab_run[0], tmp_path, small_data, [*CUT_SCANS], [*TWO_LOAD_SCANS])
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    config.update(run_scenes=["penetration_hardness"], run_scans=["p_y"])
    config["scans"] = {"p_y": {"steps": 3}}
    path.write_text(yaml.safe_dump(config))
    check = _check(project)
    run = _snakemake(project, "--cores", "2")
    assert run.returncode == 0, run.stderr[-3000:]
    again = _jobs_of(run, "PS-cutscan")
    assert "scan_scene" in again and not {r for r in again if r.startswith(MEASURING)}, again
    scan = project / "results" / SMALL / "PS" / "PS-cutscan" / "scans" / "p_y"
    best = json.loads((scan / "best.json").read_text())
    assert [row["load_mn"] for row in best["outside_scan"]] == [200.0, 300.0]
    assert [row["load_mn"] for row in best["best_loads"]] == pytest.approx([25, 50, 100])
    points = pd.read_csv(scan / "scan.csv")
    # a value soft enough that its contact leaves the window is recorded, never judged; the
    # values refinement added (issue 65) are solved on the same loads
    judged = points[~points["contact_leaves_window"]]
    grid = points[~points["refined"]]
    assert len(grid) == 3 and len(judged) >= 2 and judged["log_area_distance"].notna().all()
    assert sorted(points[points["refined"]]["value"]) == sorted(best["refined_values"])
    for value in judged["value"]:
        point = json.loads((scan / "values" / f"{value:g}" / "scan_point.json").read_text())
        assert [row["load_mn"] for row in point["loads"]] == pytest.approx([25, 50, 100])
    models = pd.read_csv(project / "results" / SMALL / "PS" / "models.csv")
    cut = models[models["sphere"] == "PS-cutscan"]
    assert set(cut["left_out"]) == {"outside_scan: 200, 300 mN"}
    _a_scan_with_nothing_to_judge_says_why(project, models)
    _a_scan_with_too_few_loads_says_why(project, models)
    # the data check said so before the run, and of those spheres only
    plans = {plan["sphere"]: plan for plan in json.loads(check.stdout)}
    assert list(plans["PS-noload"]["undecided_scans"]) == ["p_y"]
    assert plans["PS-twoloads"]["undecided_scans"]["p_y"] == (
        "scan p_y: not decided (its scene penetration_hardness keeps 2 loads inside the AFM "
        "scan, 25, 50 mN; the criterion needs at least 3)"
    )
    assert plans["PS-cutscan"]["undecided_scans"] == {}


def _a_scan_with_too_few_loads_says_why(project, models):
    """PS-twoloads' 40 µm scan holds two loads' contacts (issue 65: a lab's sphere whose scan
    held one load stopped the run with a ScanError): its values are solved on them, but two
    loads leave the measured scatter no degree of freedom, so the scan is not decided, with
    the loads it holds and the loads the criterion needs, in best.json, the model table, the
    verdict and summary.md; and the run exits 0."""
    scan = project / "results" / SMALL / "PS" / "PS-twoloads" / "scans" / "p_y"
    best = json.loads((scan / "best.json").read_text())
    assert "estimate" not in best and "grid_best" not in best
    assert best["measured_loads_mn"] == pytest.approx([25, 50]) and best["loads_needed"] == 3
    assert best["not_decided"].startswith("too few loads to judge: 2 measured loads (25, 50 mN)")
    assert [row["load_mn"] for row in best["outside_scan"]] == [100.0, 200.0, 300.0]
    points = pd.read_csv(scan / "scan.csv")
    assert len(points) == 3 and not points["best"].any()
    own = models[(models["sphere"] == "PS-twoloads") & models["source"].str.startswith("scan")]
    (row,) = own.to_dict("records")
    assert row["source"] == "scan p_y, not decided"
    assert row["left_out"] == f"not decided: {best['not_decided']}"
    verdict = pd.read_csv(project / "results" / SMALL / "verdict.csv").set_index("sphere")
    assert verdict.loc["PS-twoloads", "penetration_hardness_source"] == "scan p_y, not decided"
    summary = (project / "results" / SMALL / "summary.md").read_text()
    assert f"not decided: {best['not_decided']}" in summary


def _a_scan_with_nothing_to_judge_says_why(project, models):
    """PS-noload's 24 µm scan holds none of the loads' windows, nor any contact: best.json
    says 'not decided' and why (the loads left out with their windows, the scan's size and
    the largest window in it), every value's row is there unjudged, and the model table, the
    verdict and summary.md show it in the sphere's place, the verdict's other columns still
    the sphere's own."""
    scan = project / "results" / SMALL / "PS" / "PS-noload" / "scans" / "p_y"
    best = json.loads((scan / "best.json").read_text())
    assert "estimate" not in best and "grid_best" not in best
    assert [row["load_mn"] for row in best["outside_scan"]] == [25, 50, 100, 200, 300]
    assert best["largest_window_in_scan_um"] <= min(best["scan_um"]) <= CUT_SCANS["PS-noload"]
    assert "holds no load's window" in best["not_decided"]
    assert (
        f"largest window it holds is {best['largest_window_in_scan_um']:.1f} µm"
        in (best["not_decided"])
    )
    points = pd.read_csv(scan / "scan.csv")
    assert len(points) == 3 and points["log_area_distance"].isna().all()
    assert not points["best"].any()
    own = models[(models["sphere"] == "PS-noload") & models["source"].str.startswith("scan")]
    (row,) = own.to_dict("records")
    assert row["source"] == "scan p_y, not decided" and pd.isna(row["exponent"])
    assert row["left_out"] == f"not decided: {best['not_decided']}"
    verdict = pd.read_csv(project / "results" / SMALL / "verdict.csv").set_index("sphere")
    assert verdict.loc["PS-noload", "penetration_hardness_source"] == "scan p_y, not decided"
    assert pd.isna(verdict.loc["PS-noload", "p_y_estimate"])
    assert pd.notna(verdict.loc["PS-cutscan", "p_y_estimate"])
    summary = (project / "results" / SMALL / "summary.md").read_text()
    assert f"not decided: {best['not_decided']}" in summary


# The sheet's priors of the plastic models (issue 36), as their records name them: the
# columns a lab leaves blank when it does not know them.
PRIORS = tuple(model.parameter.sheet_column for model in with_parameter())


@pytest.fixture(scope="module")
def no_prior_run(lab_run, small_data, tmp_path_factory):
    """The lab's project gone on from (_continued) with the complete sphere's sheet row
    without hardness_mpa and hardening_k_mpa_per_nm, and its scans run with the small
    config's (target ``scans``: their best values, with the elastic scene the sphere
    registers on, as the small run has it): a lab that measured a sphere, then scans it
    without knowing its priors. Its measurements are the lab run's."""
    tmp_path = tmp_path_factory.mktemp("no_prior")
    project = _continued(lab_run[0], tmp_path, small_data, [COMPLETE], [])
    sheet_path = project / "config" / "own.tsv"
    sheet = pd.read_csv(sheet_path, sep="\t", dtype=str)
    sheet.assign(**dict.fromkeys(PRIORS, "")).to_csv(sheet_path, sep="\t", index=False)
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    # Only what the tests read: the scans and the scenes whose prior is missing, with the
    # small config's scenes and scans (the lab's widens the elastic window and runs none).
    del config["scenes"]["elastic"], config["run_scans"]
    config.update(run_scenes=["elastic", "penetration_hardness", "hardening"])
    path.write_text(yaml.safe_dump(config))
    run = _snakemake(project, "--cores", "2", targets=["scans"])
    assert run.returncode == 0, run.stderr[-3000:]
    return project, run


def _best(project, sphere, scan) -> dict:
    path = project / "results" / SMALL / "PS" / sphere / "scans" / scan / "best.json"
    return json.loads(path.read_text())


@pytest.mark.parametrize("scan", ["p_y", "k"])
def test_a_scan_without_prior_finds_what_the_scan_about_the_prior_finds(
    small_run, no_prior_run, scan
):
    """Its scans run over the prior-free ranges (docs/study.md, "Scans without a prior") and
    find what the small run's PS scans about the sheet's values find, within one step of the
    prior-free scan (a factor of its grid's ratio, 1.47 for p_Y and 1.78 for k by default):
    the two scans judge the same images on different grids."""
    project, _ = no_prior_run
    free = pd.read_csv(project / "results" / SMALL / "PS" / COMPLETE / "scans" / scan / "scan.csv")
    values = free[~free["refined"]]["value"].to_numpy()  # the grid's, not refinement's
    step = math.log(values[1] / values[0])
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())["scans"][scan]
    assert len(values) == config["prior_free_steps"]
    with_prior = _best(small_run, "PS", scan)["best"]
    without = _best(project, COMPLETE, scan)["best"]
    assert abs(math.log(without / with_prior)) <= step * (1 + 1e-9)


def test_the_scenes_at_the_missing_prior_are_left_out_and_said(no_prior_run):
    """The plastic scenes need the prior the sheet lacks: they are left out, and the run says
    so; the scans run prior-free, on the lab run's measurements."""
    project, run = no_prior_run
    scenes = project / "results" / SMALL / "PS" / COMPLETE / "scenes"
    assert (scenes / "elastic" / "comparison.csv").is_file()
    assert not (scenes / "hardening").exists() and not (scenes / "penetration_hardness").exists()
    assert "no hardening_k_mpa_per_nm in the sheet: scene hardening" in run.stderr
    assert "scan k runs over its prior-free range" in run.stderr
    again = _jobs_of(run, COMPLETE)
    assert "scan_scene" in again and not {r for r in again if r.startswith(MEASURING)}, again
