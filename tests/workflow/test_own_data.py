"""Own data as a lab has it (issue 36): spheres with a file missing, and one bad sphere among
good ones. Each sphere is a copy of the small run's virtual PS sphere in a measured folder,
less the file the case is about, so that every output it still makes can be compared with
the complete copy's, made in the same run."""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from amontons.io.tiff import read_image, write_image

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
                                          "measure/topography.pdf"]),
    "PS-noafm": (["afm_before.tif", "afm_after.tif"], ["measure/topography.json",
                                                       "measure/topography.png",
                                                       "measure/topography.pdf",
                                                       "measure/afm_before_levelled.h5",
                                                       "scenes/"]),
    "PS-norheometer": (["rheometer"], ["measure/friction.csv"]),
}  # fmt: skip
# AFM scans cut about the apex to a side (µm) that holds the elastic scene's windows of the
# three smaller loads (44 µm at 100 mN; 55 µm at 200 mN), and none (28 µm at 25 mN).
CUT_SCANS = {"PS-cutscan": 50.0, "PS-noload": 24.0}
# What the PSF enters: the sphere without a bead image renders with the stand-in, so these
# records may differ from the complete sphere's (the PSF and the rendered areas must).
PSF_DEPENDENT = {
    "measure/psf.json",
    "scenes/elastic/render.csv",
    "scenes/elastic/comparison.csv",
    "scenes/elastic/registration.json",
    "scenes/elastic/scene_fit.json",
}
# The stand-in PSF of the sphere without a bead image: another FWHM than the bead gives, so
# that its renderings differ from the complete sphere's and show where the PSF came from.
STAND_IN = {"fwhm_nm": 500.0, "fwhm_se_nm": 25.0}


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


def _lab_sphere(small_data, lab: Path, name: str, remove: list[str]) -> Path:
    """A copy of the virtual PS sphere as measured data, less ``remove``, and with its AFM scan
    cut where CUT_SCANS names it."""
    folder = lab / name
    shutil.copytree(small_data / "resources" / "synthetic" / SMALL / "PS", folder)
    (folder / "truth.json").unlink()
    for entry in remove:
        path = folder / entry
        shutil.rmtree(path) if path.is_dir() else path.unlink()
    if name in CUT_SCANS:
        _cut_scans(folder, CUT_SCANS[name])
    return folder


def _project(tmp_path, small_data, spheres: dict[str, list[str]]) -> Path:
    """A project folder whose sheet lists ``spheres`` (name -> files removed), the PS row's
    values each, with two scenes (one rendered, one not) and no scans to keep the run short."""
    project = tmp_path / "project"
    shutil.copytree(REPO / "config", project / "config")
    sheet = pd.read_csv(project / "config" / "materials.tsv", sep="\t", dtype=str)
    ps = sheet[sheet["sphere"] == "PS"]
    rows = [
        ps.assign(sphere=name, data_source=str(_lab_sphere(small_data, tmp_path / "lab", name, rm)))
        for name, rm in spheres.items()
    ]
    pd.concat(rows).to_csv(project / "config" / "own.tsv", sep="\t", index=False)
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    config.update(
        materials=["PS"],
        materials_sheet="config/own.tsv",
        run_scenes=["elastic", "greenwood_tripp"],
        run_scans=[],
        study={"run_curvature_pairs": []},
        optics={"psf": {"stand_in": STAND_IN}},
    )
    path.write_text(yaml.safe_dump(config))
    return project


def _snakemake(project, *args):
    command = [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile")]
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
    spheres = {COMPLETE: []} | {n: c[0] for n, c in CASES.items()} | dict.fromkeys(CUT_SCANS, [])
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
    assert set(amontons["sphere"]) == {COMPLETE, *CASES, *CUT_SCANS} - {"PS-norheometer"}
    scenes = pd.read_csv(material / "scenes.csv")
    assert set(scenes["sphere"]) == {COMPLETE, *CASES, *CUT_SCANS} - {"PS-noafm"}


def _spheres_in(project, table: str) -> set[str]:
    return set(pd.read_csv(project / "results" / SMALL / "PS" / table)["sphere"])


def test_one_corrupt_file_stops_only_its_sphere_until_it_is_fixed(small_data, tmp_path):
    """Two spheres, one with a truncated fluorescence image: every output of the other is
    made, and the run exits non-zero naming the file. A rerun makes PS's tables and the
    summary without the failed sphere, marked failed, and still exits non-zero; once the file
    is fixed, the next run puts the sphere back and exits 0 (amontons.workflow.ledger)."""
    project = _project(tmp_path, small_data, {COMPLETE: [], "PS-corrupt": []})
    image = tmp_path / "lab" / "PS-corrupt" / "fluorescence" / "100.tif"
    intact = image.read_bytes()
    image.write_bytes(intact[:2000])
    run = _snakemake(project, "--cores", "2")
    assert run.returncode != 0
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
    fit = _scene_record(project, "PS-cutscan", "scene_fit.json")
    assert fit["loads_mn"] == pytest.approx([25, 50, 100], rel=1e-6)
    assert fit["not_fitted"] is None
    assert fit["rendered_area"]["exponent"]["estimate"] > 0
    scenes = pd.read_csv(project / "results" / SMALL / "PS" / "scenes.csv")
    row = scenes[(scenes["sphere"] == "PS-cutscan") & (scenes["scene"] == "elastic")].iloc[0]
    assert row["left_out"] == "outside_scan: 200, 300 mN"
    complete = scenes[(scenes["sphere"] == COMPLETE)]
    assert complete["left_out"].isna().all()  # an empty note: nothing left out


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
    fit = _scene_record(project, "PS-noload", "scene_fit.json")
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


def test_a_scan_on_a_cut_scan_judges_the_loads_it_holds(small_data, tmp_path):
    """The p_Y scan (three values, to keep it short) of the sphere whose AFM scan holds three
    loads: every value is solved and compared on those three, the best value's fit is over
    them, and best.json and the model table list 200 and 300 mN as outside_scan."""
    project = _project(tmp_path, small_data, {"PS-cutscan": []})
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    config.update(run_scenes=["penetration_hardness"], run_scans=["p_y"])
    config["scans"] = {"p_y": {"steps": 3}}
    path.write_text(yaml.safe_dump(config))
    run = _snakemake(project, "--cores", "2")
    assert run.returncode == 0, run.stderr[-3000:]
    scan = project / "results" / SMALL / "PS" / "PS-cutscan" / "scans" / "p_y"
    best = json.loads((scan / "best.json").read_text())
    assert [row["load_mn"] for row in best["outside_scan"]] == [200.0, 300.0]
    assert [row["load_mn"] for row in best["best_loads"]] == pytest.approx([25, 50, 100])
    points = pd.read_csv(scan / "scan.csv")
    # a value soft enough that its contact leaves the window is recorded, never judged
    judged = points[~points["contact_leaves_window"]]
    assert len(points) == 3 and len(judged) >= 2 and judged["log_area_distance"].notna().all()
    for value in judged["value"]:
        point = json.loads((scan / f"{value:g}" / "scan_point.json").read_text())
        assert [row["load_mn"] for row in point["loads"]] == pytest.approx([25, 50, 100])
    models = pd.read_csv(project / "results" / SMALL / "PS" / "models.csv")
    assert set(models["left_out"]) == {"outside_scan: 200, 300 mN"}
