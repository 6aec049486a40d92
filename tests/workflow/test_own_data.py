"""Own data as a lab has it (issues 36 and 52): spheres with a file missing, one bad sphere
among good ones, rheometer files of two programs beside our own CSVs under one config, a
FLIM PTU with the sheet's pixel left blank, scans smaller than the windows, a scan with
nothing to judge, and a sphere scanned without the sheet's priors. Each sphere is a copy of
the small run's virtual PS sphere in a measured folder, less or other than the file the case
is about, so that every output it still makes can be compared with the complete copy's, made
in the same run. The lab run is made once per session (``lab_run``, conftest.py; lab.py);
this module reads it, and test_corrupt_file.py, test_scan_on_cut_scans.py and test_no_prior.py
go on from it."""

import json
import re

import numpy as np
import pandas as pd
import pytest
import yaml

from .lab import CASES, COMPLETE, CUT_SCANS, EXPORTED, PTU_SPHERE, REPO, SMALL, made

pytestmark = pytest.mark.workflow

# What the PSF enters: the sphere without a bead image renders with the stand-in, so these
# records may differ from the complete sphere's (the PSF and the rendered areas must).
PSF_DEPENDENT = {
    "measure/psf.json",
    "scenes/elastic/render.csv",
    "scenes/elastic/comparison.csv",
    "scenes/elastic/registration.json",
    "scenes/scene_fits.json",
}


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
        for name in made(project, COMPLETE)
        if name not in lacking and not any(name.startswith(p) for p in lacking if p[-1] == "/")
    }
    assert made(project, sphere) == expected


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
    records = sorted(n for n in made(project, sphere) if n.endswith((".csv", ".json")))
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
    records = sorted(n for n in made(project, sphere) if n.endswith((".csv", ".json")))
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
        assert planned and planned <= made(project, plan["sphere"])
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
