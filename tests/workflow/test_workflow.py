"""The workflow as a user runs it: static checks, dry runs, targets, bad configs, a small real run.

Each Snakemake call runs in a fresh working directory holding a copy of config/, as a user's
project folder would, with the repository's Snakefile.
"""

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
from SurfaceTopography import Topography

from amontons.io.layout import afm_file
from amontons.io.tiff import read_image, write_image
from amontons.measure.scan_lines import line_levelling_mode
from amontons.measure.topography import measure_topography
from amontons.simulate.scan_best import point_from_record
from amontons.simulate.scan_criterion import Criterion, ModelError
from amontons.simulate.scan_grid import value_label
from amontons.workflow.paths import SCAN_POINT

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent
# The run names of config/config.yaml and of its overlay config/test.yaml.
FULL, SMALL = "full", "small"
# The small run's overlay as the rerun test edits it (a copy of config/test.yaml).
RERUN = "rerun.yaml"
# How the AFM scans are read and levelled (config/config.yaml's surface section).
SURFACE = yaml.safe_load((REPO / "config" / "config.yaml").read_text())["surface"]


def measured(project, material, sphere, name, run=SMALL):
    """A measurement file of one sphere: results/<run>/<material>/<sphere>/measure/<name>."""
    return project / "results" / run / material / sphere / "measure" / name


def truth_of(project, sphere, run=SMALL):
    """The virtual experiment's truth of a sphere."""
    return json.loads((project / "resources/synthetic" / run / sphere / "truth.json").read_text())


def run(args, cwd, timeout=600):
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=timeout)


def snakemake(workdir, *args, timeout=600):
    command = [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile"), "-d", str(workdir)]
    return run([*command, *args], cwd=workdir, timeout=timeout)


@pytest.fixture
def project(tmp_path):
    shutil.copytree(REPO / "config", tmp_path / "config")
    return tmp_path


def _edit_config(project, edit, name="test.yaml"):
    path = project / "config" / name
    config = yaml.safe_load(path.read_text())
    edit(config)
    path.write_text(yaml.safe_dump(config))
    return path


@pytest.mark.parametrize(
    "command",
    [
        [str(BIN / "snakefmt"), "--check", "."],
        [str(BIN / "ruff"), "check", "."],
        [str(BIN / "ruff"), "format", "--check", "."],
        [sys.executable, "-m", "snakemake", "--lint"],
    ],
    ids=["snakefmt", "ruff-check", "ruff-format", "snakemake-lint"],
)
def test_static_checks_are_clean(command):
    result = run(command, cwd=REPO)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize("name", ["config.yaml", "test.yaml"])
def test_dry_run(project, name):
    result = snakemake(project, "-n", "--configfile", f"config/{name}")
    assert result.returncode == 0, result.stderr
    assert "This was a dry-run" in result.stdout
    assert "plot_load_area" in result.stdout


def test_material_target_builds_only_its_jobs(project):
    result = snakemake(project, "PS", "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    assert "resources/synthetic/small/PS/" in result.stdout
    assert "glass" not in result.stdout


def test_lifetime_job_only_where_a_flim_map_exists(project):
    # The sheet gives PS a FLIM load and glass none: the DAG holds PS's lifetime job only.
    result = snakemake(project, "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    assert "results/small/PS/PS/measure/lifetime.json" in result.stdout
    assert "results/small/glass/glass/measure/lifetime.json" not in result.stdout
    assert result.stdout.count("rule measure_lifetime:") == 1
    assert "resources/synthetic/small/PS/flim.tif" in result.stdout
    assert "resources/synthetic/small/glass/flim.tif" not in result.stdout


def _planned_outputs(project, configfile):
    """Every file a full run of ``configfile`` would write (dry run of every job)."""
    result = snakemake(project, "-n", "--forceall", "--configfile", configfile)
    assert result.returncode == 0, result.stderr
    lines = re.findall(r"^\s+(?:output|log|benchmark): (.+)$", result.stdout, re.M)
    return {path.strip() for line in lines for path in line.split(", ")}


def test_runs_write_apart_so_the_small_run_never_touches_the_full_one(project):
    """config/test.yaml (run 'small') writes results, logs and virtual raw data only below
    its own run name: no file of the full reproduction (run 'full') is in its plan."""
    full = _planned_outputs(project, "config/config.yaml")
    small = _planned_outputs(project, "config/test.yaml")
    assert full and small and not full & small
    assert all(f"/{SMALL}/" in path for path in small)
    assert any(path.startswith(f"resources/synthetic/{FULL}/") for path in full)


@pytest.mark.parametrize(
    ("target", "expected"),
    [
        ("optics", ["psf.json", "grafting_density.json", "edge_gap.json", "lifetime.json"]),
        ("friction", ["friction.csv", "amontons.png"]),
    ],
)
def test_stage_targets_include_the_measurements(project, target, expected):
    result = snakemake(project, target, "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    for name in expected:
        assert name in result.stdout


def _slurm_jobs(project, configfile, *extra):
    """(rule, wildcards, resources) of every cluster job of a dry run with the SLURM profile."""
    result = snakemake(
        project,
        "-n",
        "--forceall",
        "--profile",
        str(REPO / "profiles" / "slurm"),
        "--configfile",
        configfile,
        *extra,
    )
    assert result.returncode == 0, result.stderr
    jobs = []
    # group jobs list their members indented
    for block in re.split(r"\n(?=\s*\[.*\]\n\s*(?:local)?rule )", result.stdout):
        rule = re.search(r"^\s*(local)?rule (\w+):", block, re.M)
        if rule is None or rule.group(1) or rule.group(2) == "all":
            continue  # local rules (targets) run in the submitting process
        wildcards = re.search(r"^\s+wildcards: (.+)$", block, re.M)
        resources = re.search(r"^\s+resources: (.+)$", block, re.M)
        jobs.append(
            (
                rule.group(2),
                wildcards.group(1) if wildcards else "",
                dict(kv.split("=", 1) for kv in resources.group(1).split(", ")),
            )
        )
    return jobs, result.stdout


def test_slurm_dry_run_gives_every_job_measured_resources_that_grow_with_the_grid(project):
    """Every cluster job of the full config carries mem_mb and runtime from the measured
    runs (workflow/resources.json, no profile default stands in), every rule declares its
    threads, and a solve asks for more the larger its FFT grid (the timing model of
    docs/accuracy.md on each job's own grid)."""
    jobs, stdout = _slurm_jobs(project, "config/config.yaml")
    assert len(jobs) > 150
    # the few-second jobs go in bundles (the profile's groups), the solves (each sphere's
    # scan among them) on their own
    assert "Group job figures" in stdout and "Group job measurements" in stdout
    grouped = re.findall(r"^    rule (\w+):", stdout, re.M)
    assert "fit_sphere_scenes" in grouped
    assert not {"simulate_scene", "scan_scene"} & set(grouped)
    for rule, wildcards, resources in jobs:
        assert int(resources["mem_mb"]) >= 500 and int(resources["runtime"]) >= 2, (rule, wildcards)
        assert resources["slurm_partition"] == "YOUR_PARTITION"
    profile = yaml.safe_load((REPO / "profiles" / "slurm" / "config.yaml").read_text())
    assert not {"mem_mb", "runtime"} & set(profile["default-resources"])
    for path in (REPO / "workflow" / "rules").glob("*.smk"):
        for block in re.split(r"\n(?=rule \w+:)", path.read_text())[1:]:
            if "localrule: True" not in block:
                assert "    threads:" in block, block.splitlines()[0]
    # the solves ask for what the timing model predicts on their own grid: under the
    # publication preset (well above the 2 min / 500 MB floors) PMMA-4mm's scene runs on a
    # 2048² window, PS's on 1536²
    jobs, _ = _slurm_jobs(project, "config/config.yaml", "--config", "solver_preset=publication")
    scenes = {
        wildcards: resources
        for rule, wildcards, resources in jobs
        if rule == "simulate_scene" and "scene=penetration_hardness" in wildcards
    }
    large = next(r for w, r in scenes.items() if "sphere=PMMA-4mm" in w)
    small = next(r for w, r in scenes.items() if "sphere=PS," in w)
    assert int(large["mem_mb"]) > int(small["mem_mb"]) > 500
    assert int(large["runtime"]) > int(small["runtime"]) > 2


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda c: c.update(materials=["PS", "PEEK"]), "allowed values (from the sample sheet)"),
        (lambda c: c.setdefault("optics", {}).update(otsu_bin=256), "'otsu_bin'"),
        (lambda c: c.update(materials_sheet="config/bad.tsv"), "loads_mn = '25,100,50'"),
    ],
    ids=["unknown-material", "misspelled-key", "non-increasing-loads"],
)
def test_bad_config_fails_before_any_job(project, edit, expected):
    sheet = (project / "config" / "materials.tsv").read_text()
    (project / "config" / "bad.tsv").write_text(sheet.replace("25,50,100,200,300", "25,100,50"))
    _edit_config(project, edit)
    result = snakemake(project, "--cores", "1", "--configfile", "config/test.yaml")
    assert result.returncode != 0
    assert expected in result.stderr
    assert not (project / "results").exists() and not (project / "resources").exists()


def test_small_data_run(small_run):
    project = small_run
    for material in ("PS", "glass"):
        for ext in ("png", "pdf", "csv"):
            path = project / "results" / SMALL / material / f"load_area.{ext}"
            assert path.stat().st_size > 0
    for sphere in ("PS", "glass"):
        fit = json.loads(measured(project, sphere, sphere, "load_area_fit.json").read_text())
        truth = truth_of(project, sphere)
        # Rough spheres under contact hardening: the true exponent is the solver's (PS ~0.85,
        # glass ~0.75: its 3 nm roughness against E* = 33 GPa). Otsu keeps 89-100 % of the
        # true area, nearly the same share at every load: 0.03 on the exponent.
        assert fit["exponent"]["estimate"] == pytest.approx(truth["area_exponent"], abs=0.03)
        assert fit["n"] == len(truth["loads_mn"])
        check_measurements_against_truth(project, sphere, sphere)
    lifetime = json.loads(measured(project, "PS", "PS", "lifetime.json").read_text())
    flim = truth_of(project, "PS")["flim"]
    # > 1000 pixels on each side with 0.1 ns scatter: standard errors ≈ 0.003 ns, so 0.02 ns
    # is > 5 σ.
    assert lifetime["inside_ns"]["mean"] == pytest.approx(flim["contact_ns"], abs=0.02)
    assert lifetime["outside_ns"]["mean"] == pytest.approx(flim["outside_ns"], abs=0.02)
    assert not measured(project, "glass", "glass", "lifetime.json").exists()
    # The roughened PS sphere scatters its Newton rings: the edge gap is a flagged null with
    # the reason, not a number (and the run goes on).
    gap = json.loads(measured(project, "PS", "PS", "edge_gap.json").read_text())
    assert gap["edge_gap_nm"] is None and "missed a ring" in gap["flag"]


def test_intensity_exponent_on_the_rough_ps_sphere_within_0_05_of_the_truth(small_run):
    """Small data, PS: 0.486 against a true 0.528 (2026-11-23). The margin is thin: the error
    is the Otsu area exponent's (+0.009 here) amplified ~4× (test below); on the earlier virtual
    sphere (+0.021 on the area exponent) it missed by 0.009."""
    project = small_run
    intensity = json.loads(measured(project, "PS", "PS", "intensity_pressure_fit.json").read_text())
    truth = truth_of(project, "PS")
    assert intensity["exponent"]["estimate"] == pytest.approx(
        truth["intensity_pressure_exponent"], abs=0.05
    )


@pytest.mark.parametrize("sphere", ["PS", "glass"])
def test_intensity_exponent_follows_from_the_light_and_the_otsu_area(small_run, sphere):
    """Mean intensity L/A and mean pressure F/A share the Otsu area A, so I/p = L/F whatever A
    is: with A ∝ F^β, α − 1 = d ln(L/F) / d ln p = (α_true − 1)(1 − β_true)/(1 − β). The
    intensity exponent is therefore right exactly when the light is all counted and the area
    exponent is right; its error is the area exponent's error amplified by (1 − α)/(1 − β), 2-4.
    Measured off this prediction by 0.000 (glass) and 0.017 (PS) here, ≤ 0.017 on the five
    full-run spheres (the OLS lines through five points that are not exact power laws); 0.03,
    which a lost rim of light (the mask-only sum: +0.1) or a wrong background still breaks."""
    truth = truth_of(small_run, sphere)
    fit = json.loads(measured(small_run, sphere, sphere, "intensity_pressure_fit.json").read_text())
    alpha = fit["exponent"]
    area_fit = json.loads(measured(small_run, sphere, sphere, "load_area_fit.json").read_text())
    beta = area_fit["exponent"]["estimate"]
    alpha_true, beta_true = truth["intensity_pressure_exponent"], truth["area_exponent"]
    predicted = 1 + (alpha_true - 1) * (1 - beta_true) / (1 - beta)
    assert alpha["estimate"] == pytest.approx(predicted, abs=0.03)


def test_small_run_figures_show_the_otsu_separation_and_the_intensity_law(small_run):
    """The per-load Otsu figure (image with its contact edge, histogram with threshold and η)
    and the intensity-pressure figure exist for every sphere, as PNG and PDF."""
    for sphere in ("PS", "glass"):
        for name in ("contact_area", "intensity_pressure"):
            for ext in ("png", "pdf"):
                path = measured(small_run, sphere, sphere, f"{name}.{ext}")
                assert path.stat().st_size > 10_000, path


def _job_stats(stdout: str) -> dict[str, str]:
    """Rule → job count, from the 'Job stats' table of a dry run."""
    stats = stdout.split("Job stats:", 1)[1].split("total", 1)[0]
    return dict(re.findall(r"(\w+)\s+(\d+)\n", stats))


def test_rerun_is_a_no_op_and_a_setting_reruns_only_its_jobs(small_run):
    """Dry runs on the session's small run. Its overlay is edited as a copy, rerun.yaml,
    which is the same config under another name (the name only enters error messages):
    other tests read the same folder's test.yaml at the same time."""
    project = small_run
    path = project / "config" / RERUN
    shutil.copyfile(project / "config" / "test.yaml", path)
    again = snakemake(project, "-n", "--configfile", f"config/{RERUN}")
    assert "Nothing to be done" in again.stdout + again.stderr
    # The same overlay with its keys in another order is the same config: nothing re-runs.
    overlay = yaml.safe_load(path.read_text())
    reordered = {key: overlay[key] for key in reversed(overlay)}
    reordered["virtual_experiment"] = dict(reversed(overlay["virtual_experiment"].items()))
    path.write_text(yaml.safe_dump(reordered, sort_keys=False))
    same = snakemake(project, "-n", "--configfile", f"config/{RERUN}")
    assert "Nothing to be done" in same.stdout + same.stderr
    # A changed setting re-runs exactly the jobs that use it: params hold only their slice.
    # (Key order is kept: Snakemake compares params dicts in order.)
    _edit_config(project, lambda c: c.update(optics={"psf": {"profile_radius_nm": 1800.0}}), RERUN)
    changed = snakemake(project, "-n", "--configfile", f"config/{RERUN}")
    # The PSF also renders the three optics scenes of each sphere and every scan value
    # (2 spheres x 2 scans, a job each): they follow it, and so do the study built on them and
    # the run's answer built on the study (verdict, summary, the report's first page).
    study = {
        "best_scan_value": "4",
        "plot_amontons_study": "1",
        "plot_flattening_maps": "2",
        "plot_load_series_maps": "2",
        "plot_model_curves": "2",
        "plot_scan_maps": "2",
        "tabulate_models": "2",
        "tabulate_verdict": "1",
        "summarise_study": "1",
        "write_report_page": "1",
    }
    assert _job_stats(changed.stdout) == {
        "measure_psf": "2",
        "render_scene": "6",
        "compare_scene": "6",
        "fit_sphere_scenes": "2",
        "tabulate_scenes": "2",
        "scan_scene": "4",
        **study,
        "all": "1",
    }

    # A changed scene re-runs its own jobs only: one scene, two spheres.
    def retune_hardening(config):
        config.pop("optics")
        config["scenes"] = {"hardening": {"tol": 1.0e-7}}

    # The k scan presses its base scene (hardening) at every value: its 2 scan jobs (one
    # per sphere) follow, the p_Y scan's do not.
    _edit_config(project, retune_hardening, RERUN)
    changed = snakemake(project, "-n", "--configfile", f"config/{RERUN}")
    assert _job_stats(changed.stdout) == {
        "simulate_scene": "2",
        "render_scene": "2",
        "compare_scene": "2",
        "fit_sphere_scenes": "2",
        "tabulate_scenes": "2",
        "scan_scene": "2",
        **study,
        "best_scan_value": "2",
        "all": "1",
    }


def test_own_data_is_measured_and_a_replaced_image_reruns_its_jobs(small_data, tmp_path):
    """A sphere whose data_source is a folder of measured files (here a copy of the virtual
    PS sphere, names as a user writes them: 25mN.tif): its measurements run on it, and
    overwriting one image in place re-runs exactly the jobs that read the images - a folder
    input would not see it, since a folder's time does not change when a file in it is
    overwritten. The overwritten image shows no contact: it is flagged and left out of the
    fit, and the run goes on."""
    own = tmp_path / "my_data" / "PS-own"
    shutil.copytree(small_data / "resources" / "synthetic" / SMALL / "PS", own)
    (own / "truth.json").unlink()
    for image in (own / "fluorescence").glob("*.tif"):
        image.rename(image.with_name(f"{image.stem}mN.tif"))
    shutil.copytree(REPO / "config", tmp_path / "config")
    sheet = pd.read_csv(tmp_path / "config" / "materials.tsv", sep="\t", dtype=str)
    row = sheet[sheet["sphere"] == "PS"].assign(sphere="PS-own", data_source=str(own))
    row.to_csv(tmp_path / "config" / "own.tsv", sep="\t", index=False)
    _edit_config(tmp_path, lambda c: c.update(materials=["PS"], materials_sheet="config/own.tsv"))
    target = "results/small/PS/PS-own/measure/load_area_fit.json"
    args = (target, "--cores", "2", "--configfile", "config/test.yaml")
    first = snakemake(tmp_path, *args)
    assert first.returncode == 0, first.stderr[-3000:]

    image = own / "fluorescence" / "50mN.tif"
    pixel = read_image(image).pixel_m
    noise = np.random.default_rng(0).poisson(120, read_image(image).data.shape)
    write_image(image, noise.astype(np.uint16), pixel)
    dry = snakemake(tmp_path, *args, "-n")
    assert _job_stats(dry.stdout) == {
        "measure_contact_area": "1",
        "fit_load_area": "1",
    }
    second = snakemake(tmp_path, *args)
    assert second.returncode == 0, second.stderr[-3000:]
    area = pd.read_csv(measured(tmp_path, "PS", "PS-own", "contact_area.csv"))
    assert area["contact_found"].tolist() == [True, False, True, True, True]
    assert "noise sd above the background" in area["flag"].iloc[1]
    fit = json.loads((tmp_path / target).read_text())
    assert fit["excluded_loads_mn"] == [50.0] and fit["n"] == 4


def check_measurements_against_truth(project, material, sphere):
    """Each measurement of the small-data run recovers the virtual experiment's truth."""
    results = measured(project, material, sphere, "")
    truth = truth_of(project, sphere)

    # PSF: shot noise scatters the FWHM by ~1 % at these counts (tests/measure), so 3 % (the
    # brief's tolerance) is a ~3 σ bound that a missing pixel correction (+4 %) breaks.
    psf = json.loads((results / "psf.json").read_text())
    assert psf["fwhm_nm"]["estimate"] == pytest.approx(truth["psf_fwhm_nm"], rel=0.03)
    assert psf["n"] > 100

    # Grafting density: LOWESS maximum scatters by 1.3 % at 6 % noise (tests/measure); 5 %.
    density = json.loads((results / "grafting_density.json").read_text())
    assert density["density_per_um2"] == pytest.approx(truth["grafting_density_per_um2"], rel=0.05)

    # Newton rings, where they can be numbered: the first bright ring is at λ/4n = 84.3 nm by
    # eq. B.1 (0.1 nm rounding); 40 half-profiles less those refused.
    gap = json.loads((results / "edge_gap.json").read_text())
    if gap["edge_gap_nm"] is not None:
        assert gap["first_ring_gap_nm"] == pytest.approx(truth["first_ring_gap_nm"], abs=0.1)
        assert gap["first_ring_gap_nm"] == pytest.approx(84.3, abs=0.1)
        assert gap["edge_gap_nm"]["n"] + len(gap["rejected_half_profiles"]) == 40
    if sphere == "glass":
        # The glass sphere (the appendix's Newton-ring sphere, Fig. B.6): a number, not
        # undetermined, and the mean gap at the profiles' own edges within 2 nm of the truth
        # there (the forward model's average gap at each ray's true edge, truth.json's
        # edge_profiles). Measured: 2.74 nm against 1.29 nm here; 1.33 against the full run's
        # 1.51 nm (before the per-profile edge, against the equal-area edge's truth: 2.47 vs
        # 0.59 and 1.32 vs 0.72 nm).
        assert gap["flag"] is None or not gap["flag"].startswith("undetermined")
        assert gap["edge_gap_nm"]["mean"] == pytest.approx(
            truth["edge_profiles"]["mean_ring_gap_nm"], abs=2.0
        )
        # The sheet-radius model's sensitivity to E*: a stiffer sheet shrinks the Hertz radius
        # and lowers the gap (measured −2.4 nm per +10 %, the issue's −12.6/+18.3 nm per
        # ∓20 % on a larger contact).
        assert -5.0 < gap["edge_gap_change_nm_per_10pct_e_star"] < -0.5

    # Static friction: the torque-peak median scatters by 0.5 % at 1 % torque noise
    # (tests/virtual); 2 % per load. Speed from the angle slope to 2 % as well.
    friction = pd.read_csv(results / "friction.csv")
    np.testing.assert_allclose(
        friction["static_friction_mn"], truth["static_friction_mn"], rtol=0.02
    )
    np.testing.assert_allclose(
        friction["dynamic_friction_mn"], truth["dynamic_friction_mn"], rtol=0.02
    )
    np.testing.assert_allclose(
        friction["sliding_speed_um_s"], truth["sliding_speed_um_s"], rtol=0.02
    )
    np.testing.assert_allclose(friction["load_mn"], truth["loads_mn"])

    # Intensity-pressure exponent against the true mean-intensity exponent (truth.json
    # explains it); the glass sphere meets ±0.05 (PS: its own test above, issue 6).
    if sphere == "glass":
        intensity = json.loads((results / "intensity_pressure_fit.json").read_text())
        assert intensity["exponent"]["estimate"] == pytest.approx(
            truth["intensity_pressure_exponent"], abs=0.05
        )

    # Hertz check: the Hertz radius is recomputed exactly, the measured radius is that of the
    # Otsu area, and on a rough sphere the measured/Hertz ratio grows with load (roughness
    # matters less as the contact grows) and stays below 1.
    hertz = pd.read_csv(results / "hertz_check.csv")
    np.testing.assert_allclose(hertz["hertz_radius_um"], truth["hertz_contact_radius_um"])
    area = pd.read_csv(results / "contact_area.csv")
    np.testing.assert_allclose(hertz["measured_radius_um"], np.sqrt(area["area_um2"] / np.pi))
    assert np.all(np.diff(hertz["radius_ratio"]) > 0) and hertz["radius_ratio"].max() < 1.0

    # AFM: the levelled scans give back the sphere and its roughness at the AFM pixel. The
    # radius from a 33 µm scan: PS (R = 0.3 mm) sags ~450 nm against 80 nm of long-wave
    # roughness that looks like form: 15 %; glass (2 mm, 3 nm roughness): 5 %. Slope is set
    # by the short waves: 5 % (after the noise below). The flattening depth is the truth's
    # statistic of the noise-free scans (docs/models.md §1.8): PS within 0.5 % (read 41.70 nm,
    # true 41.69 nm, SE 0.01 nm). Glass flows by < 1 nm under 0.3 nm noise per scan: its depth
    # is flagged near the noise floor, and reads no shallower than the truth, no deeper than
    # its deepest point.
    topography = json.loads((results / "topography.json").read_text())
    afm = truth["afm"]
    radius_tol = 0.15 if sphere == "PS" else 0.05
    assert topography["before"]["sphere_radius_mm"] == pytest.approx(
        truth["diameter_mm"] / 2, rel=radius_tol
    )
    # White height noise σ adds σ²/Δx² to the finite-difference slope² (central differences,
    # two components): negligible for PS, most of the slope of the 3 nm glass sphere.
    noisy_slope = np.hypot(afm["slope_rms"], afm["noise_nm"] / afm["pixel_nm"])
    assert topography["before"]["slope_rms"] == pytest.approx(noisy_slope, rel=0.05)
    depth = topography["flattening_depth_nm"]
    if sphere == "PS":
        assert depth["flag"] is None
        assert depth["estimate"] == pytest.approx(afm["flattening_depth_nm"], rel=0.005)
    elif depth["estimate"] is None:
        # Not resolved: its half depth lies within the noise threshold, and so does the
        # truth's (the small data's glass: true depth 0.0 nm, threshold 0.3 nm).
        assert depth["flag"].startswith("flattening not resolved")
        assert afm["flattening_depth_nm"] / 2 < topography["flattening_threshold_nm"]
    else:
        assert depth["flag"].startswith("near the noise floor")
        assert afm["flattening_depth_nm"] <= depth["estimate"] <= afm["max_plastic_depth_nm"]
    # The scan lines the virtual AFM shifts are found in both scans and removed.
    for scan in ("before", "after"):
        assert topography["line_levelling"][scan]["applied"] is True
        assert topography["line_levelling"][scan]["stepped_rows"] >= 2 * afm["line_offsets"]

    # Amontons table: normalised at 25 mN; with F_s = τ·A, F_s/F_s,ref follows A/A_ref to the
    # friction and area errors (2 % + 6 %).
    amontons = pd.read_csv(project / "results" / SMALL / material / "amontons.csv")
    rows = amontons[amontons["sphere"] == sphere]
    assert rows["area_over_area_ref"].iloc[0] == 1.0
    np.testing.assert_allclose(
        rows["friction_over_friction_ref"], rows["area_over_area_ref"], rtol=0.08
    )


def _topography_record(folder: Path) -> dict:
    """The topography record of ``folder``'s AFM scans, found as the rules' inputs find them
    (amontons.io.layout.afm_file) and measured with config/config.yaml's surface settings."""
    return measure_topography(
        afm_file(folder, "afm_before"),
        afm_file(folder, "afm_after"),
        None,
        nan_policy=SURFACE["afm_nan_policy"],
        channel=SURFACE["afm_channel"],
        line_levelling=line_levelling_mode(SURFACE["line_levelling"]),
    ).to_record()


def test_own_afm_maps_in_vendor_formats_are_measured(small_data, tmp_path):
    """A measured sphere whose AFM scans come as an ISO 25178 x3p file (before) and a
    Gwyddion file (after), written from the virtual PS sphere's float TIFF scans: the lookup
    the rules' inputs use finds them, and the topography measurement reads them through
    SurfaceTopography and gives the TIFF scans' numbers (to 1e-9 relative: the same float32
    heights, the same pixel). In-process: which file a rule takes is the lookup's, what it
    reads and measures is the library's (a Snakemake run of both rules gave the same)."""
    synthetic = small_data / "resources" / "synthetic" / SMALL / "PS"
    own = tmp_path / "my_data" / "PS-afm"
    own.mkdir(parents=True)
    for stem, writer in (("afm_before", "to_x3p"), ("afm_after", "to_gwy")):
        scan = read_image(synthetic / f"{stem}.tif", allow_nan=True)
        ny, nx = scan.data.shape
        topography = Topography(
            scan.data.astype(float).T, (nx * scan.pixel_m, ny * scan.pixel_m), unit="m"
        )
        getattr(topography, writer)(str(own / f"{stem}.{writer[3:]}"))
    assert [afm_file(own, stem).suffix for stem in ("afm_before", "afm_after")] == [".x3p", ".gwy"]
    found, reference = _topography_record(own), _topography_record(synthetic)
    assert found["channel"] == "Default" and reference["channel"] is None
    for scan in ("before", "after"):
        for key, value in reference[scan].items():
            assert found[scan][key] == pytest.approx(value, rel=1e-9), (scan, key)
    assert found["flattening_depth_nm"]["estimate"] == pytest.approx(
        reference["flattening_depth_nm"]["estimate"], rel=1e-9
    )


PROBE_SCENE = {
    "surface": "afm_before",
    "geometry": "sphere",
    "model": "elastic",
    "loads": "measured",
    "pixel_nm": 256.0,
    "window_factor": 1.5,
    "side_px": None,
    "max_side_px": 512,
    "tol": 1.0e-6,
    "optics": "none",
    "rendering": "emission",
    "confinement_floor_mpa": 0.0,
    "p_y_mpa": None,
    "k_mpa_per_nm": None,
    "increment": "local",
    "alpha": 1.0,
}


def _scene_jobs(project, target, **changes):
    """Jobs (rule → count) of a dry run of ``target`` with one scene, 'probe', selected."""

    def edit(config):
        config["run_scenes"] = ["probe"]
        config["scenes"] = {"probe": {**PROBE_SCENE, **changes}}
        config["run_scans"] = []  # the scans' base scenes are not selected
        config["study"] = {"run_curvature_pairs": []}

    _edit_config(project, edit)
    result = snakemake(project, target, "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    rules = re.findall(r"^(?:local)?rule (\w+):", result.stdout, re.M)
    return {rule: rules.count(rule) for rule in rules}, result.stdout


def test_an_elastic_scene_without_optics_schedules_no_psf_rendering_or_plastic_job(project):
    target = "results/small/PS/PS/scenes/scene_fits.json"
    jobs, _ = _scene_jobs(project, target)
    assert set(jobs) == {
        "generate_virtual_experiment_with_flim",
        "level_afm_map",
        "simulate_scene",
        "fit_sphere_scenes",
    }


def test_switching_a_scene_to_the_microscope_adds_exactly_its_psf_and_rendering_jobs(project):
    target = "results/small/PS/PS/scenes/probe/comparison.csv"
    without, _ = _scene_jobs(project, "results/small/PS/PS/scenes/scene_fits.json")
    fit_with, _ = _scene_jobs(
        project, "results/small/PS/PS/scenes/scene_fits.json", optics="microscope"
    )
    compare_with, _ = _scene_jobs(project, target, optics="microscope")
    added = {rule: n for rule, n in (fit_with | compare_with).items() if rule not in without}
    assert added == {"measure_psf": 1, "render_scene": 1, "compare_scene": 1}


def test_a_synthetic_scene_reads_nothing_of_the_experiment(project):
    synthetic = {
        "hurst": 0.8,
        "rms_slope": 0.1,
        "short_cutoff_um": None,
        "long_cutoff_um": None,
        "seed": 3,
        "e_star_gpa": 3.0,
    }
    jobs, stdout = _scene_jobs(
        project,
        "results/small/synthetic/scenes/probe/scene_fits.json",
        surface="synthetic",
        geometry="flat_periodic",
        side_px=128,
        loads=[1.0, 2.0, 4.0],
        synthetic=synthetic,
    )
    assert set(jobs) == {"simulate_synthetic_scene", "fit_synthetic_scene"}
    assert "resources/" not in stdout


def test_material_target_builds_only_its_scenes(project):
    result = snakemake(project, "PS", "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    assert "results/small/PS/PS/scenes/hardening/comparison.csv" in result.stdout
    assert "results/small/PS/scenes.csv" in result.stdout
    assert "glass/scenes/" not in result.stdout and "results/small/glass" not in result.stdout


def scene_file(project, sphere, scene, name, run=SMALL):
    return project / "results" / run / sphere / sphere / "scenes" / scene / name


@pytest.mark.parametrize("sphere", ["PS", "glass"])
def test_registration_recovers_the_virtual_afm_frame(small_run, sphere):
    """The virtual AFM scans are mirrored, rotated by 8° and centred off the apex: the hardening
    scene's registration finds the mirror, the rotation within 1° and the scan centre in the
    image within one fluorescence pixel (the issue's targets)."""
    truth = truth_of(small_run, sphere)
    frame = truth["afm"]["frame"]
    found = json.loads(scene_file(small_run, sphere, "hardening", "registration.json").read_text())
    assert found["mirrored"] is frame["mirrored"]
    assert found["rotation_deg"] == pytest.approx(frame["rotation_deg"], abs=1.0)
    error_um = np.subtract(found["afm_scan_centre_in_image_um"], frame["scan_centre_um"])
    assert np.hypot(*error_um) < truth["pixel_nm"] * 1e-3


def test_hardening_scene_at_the_true_k_matches_the_measured_contact(small_run):
    """The virtual PS sphere was made with contact hardening at the sheet's k; the hardening
    scene (AFM map before contact, the sheet's k, the measured PSF) rendered and thresholded
    gives the measured Otsu area within 3 % at every load, and the masks overlap with IoU
    ≥ 0.8 at the largest load (the issue's targets)."""
    table = pd.read_csv(scene_file(small_run, "PS", "hardening", "comparison.csv"))
    assert table["area_ratio"].to_numpy() == pytest.approx(1.0, abs=0.03)
    assert table["iou"].iloc[-1] >= 0.8


def test_elastic_scene_runs_no_plastic_loop_and_undershoots_the_hardened_contact(small_run):
    """Elastic scenes log zero plastic rounds; on PS, whose virtual contact hardens, the elastic
    scene's area lies below the measured one at every load (appendix Fig. B.12)."""
    solve = json.loads(scene_file(small_run, "PS", "elastic", "solve.json").read_text())
    assert [row["outer_iterations"] for row in solve["loads"]] == [0] * 5
    assert {row["route"] for row in solve["loads"]} == {"elastic"}
    table = pd.read_csv(scene_file(small_run, "PS", "elastic", "comparison.csv"))
    assert (table["area_ratio"] < 0.9).all()


def test_scene_table_lists_every_scene_beside_the_measured_exponent(small_run):
    table = pd.read_csv(small_run / "results" / SMALL / "PS" / "scenes.csv")
    assert list(table["scene"]) == [
        "elastic",
        "penetration_hardness",
        "hardening",
        "greenwood_tripp",
    ]
    measured_fit = json.loads(measured(small_run, "PS", "PS", "load_area_fit.json").read_text())
    assert table["measured_exponent"].iloc[0] == measured_fit["exponent"]["estimate"]
    hardening = table.set_index("scene").loc["hardening"]
    # the hardening scene's exponent is the measured one's within their intervals
    assert hardening["exponent_ci_low"] <= hardening["measured_ci_high"]
    assert hardening["measured_ci_low"] <= hardening["exponent_ci_high"]


def test_binary_rendering_overstates_the_measured_area(small_run):
    """The appendix's rendering (a binary contact map blurred with the PSF) against the emission
    rendering, on the PS hardening scene's own fields: under the √p law of the measured images
    the binary map's Otsu area lies above the measured one by more than the emission
    rendering's (which is within 3 %): the bias docs/simulate.md states."""
    from amontons.io.fields import read_load_series
    from amontons.measure.area import OtsuSettings
    from amontons.simulate.render import render_load_series

    folder = small_run / "results" / SMALL / "PS" / "PS" / "scenes" / "hardening"
    fields, _, settings = read_load_series(folder / "fields.h5")
    psf = json.loads(measured(small_run, "PS", "PS", "psf.json").read_text())
    binary = render_load_series(
        fields,
        settings["pixel_nm"] * 1e-9,
        pixel_m=200e-9,
        psf_fwhm_m=psf["fwhm_nm"]["estimate"] * 1e-9,
        rendering="binary",
        confinement_floor_pa=0.0,
        otsu=OtsuSettings(),
    )
    table = pd.read_csv(folder / "comparison.csv")
    ratio = np.array([r.otsu.area_m2 * 1e12 for r in binary]) / table["measured_area_um2"]
    print("binary / measured Otsu area:", np.round(ratio, 3))
    assert (ratio > table["area_ratio"] + 0.03).all()


# The study (docs/study.md): scans, best values, figures and the model table.


def study_file(project, sphere, name, run=SMALL):
    return project / "results" / run / sphere / sphere / "study" / name


def scan_best(project, sphere, scan, run=SMALL):
    path = project / "results" / run / sphere / sphere / "scans" / scan / "best.json"
    return json.loads(path.read_text())


def test_k_scan_recovers_the_true_k_of_the_rough_sphere_within_one_scan_step(small_run):
    """The virtual PS sphere was made with contact hardening at the sheet's k (5 MPa/nm). The
    scan (1 to 20 MPa/nm, 7 log steps of ×1.65; the truth is not a grid point) judges every
    value by the rendered against the measured Otsu areas: its best value lies within one
    scan step of the truth, and the interval the measured areas' scatter allows holds it."""
    best = scan_best(small_run, "PS", "k")
    truth = truth_of(small_run, "PS")["hardening_k_mpa_per_nm"]
    step = np.log(best["values"][1] / best["values"][0])
    print("PS k scan:", best["best"], best["interval"], "truth", truth)
    assert abs(np.log(best["best"] / truth)) <= step * (1 + 1e-9)
    low, high = best["interval"]
    assert (low is None or low <= truth) and (high is None or truth <= high)
    assert not best["at_scan_edge"]


def test_k_of_glass_is_left_open_where_no_k_changes_its_contact(small_run):
    """Glass (k = 10000 MPa/nm: E*/k = 3 nm, far below the 256 nm solver pixel) does not flow:
    every k of its scan (2000-40000 MPa/nm) gives nearly the same areas, so the data cannot
    bound k from above: the scatter interval is open there and holds the truth."""
    best = scan_best(small_run, "glass", "k")
    truth = truth_of(small_run, "glass")["hardening_k_mpa_per_nm"]
    print("glass k scan:", best["best"], best["interval"])
    low, high = best["interval"]
    assert high is None
    assert low is None or low <= truth


def test_model_table_says_hardening_explains_the_rough_sphere(small_run):
    """On the virtual PS sphere (made with contact hardening) the hardening model at its best k
    gives the measured load-area exponent within 0.03 (the issue's bound); the elastic and
    penetration-hardness exponents are reported with their distance from it. The truth
    decides which model wins: hardening, with the smallest distance of all."""
    table = pd.read_csv(small_run / "results" / SMALL / "PS" / "models.csv")
    print(table[["model", "source", "value", "exponent", "exponent_difference"]].to_string())
    fit = json.loads(measured(small_run, "PS", "PS", "load_area_fit.json").read_text())
    assert (table["measured_exponent"] == fit["exponent"]["estimate"]).all()
    best_k = table[table["source"] == "scan k, best value"].iloc[0]
    assert best_k["value"] == scan_best(small_run, "PS", "k")["best"]
    assert abs(best_k["exponent_difference"]) <= 0.03
    others = table[table["model"].isin(["elastic", "penetration_hardness"])]
    assert len(others) >= 3  # elastic scene, p_Y scene, p_Y scan best
    assert (others["exponent_difference"].abs() > abs(best_k["exponent_difference"])).all()
    assert table["area_ratio_largest"].notna().sum() == len(table) - 1  # all but GT


def test_curvature_does_not_change_the_load_area_exponent(small_run):
    """Appendix Fig. B.10: the same synthetic surface on a flat periodic and on a curved
    interface gives load-area exponents within 0.03 of each other, elastic and hardening
    (the issue's bound); the CSV holds each scene's exponent beside its areas."""
    table = pd.read_csv(small_run / "results" / SMALL / "study" / "B10_curvature.csv")
    for model, rows in table.groupby("model"):
        exponents = rows.groupby("geometry")["exponent"].first()
        print(model, exponents.to_dict())
        assert exponents["curved"] == pytest.approx(exponents["flat periodic"], abs=0.03)
        # and the CSV's exponent is the fit of its own areas (rounding-free check)
        for _, one in rows.groupby("geometry"):
            slope = np.polyfit(np.log(one["load_mn"]), np.log(one["area_um2"]), 1)[0]
            assert one["exponent"].iloc[0] == pytest.approx(slope, abs=1e-9)


def test_b8_csv_holds_every_scan_value_and_marks_the_best(small_run):
    """Fig. B.8's table: every value of the coarse grid (the refined values are the scan's,
    not the figure's), each with its scan.csv distance, and the grid's best marked: the grid
    value of least χ² under the criterion best.json states (the measured scatter as used, the
    model error refinement.json measured), recomputed here from the values' own records."""
    table = pd.read_csv(study_file(small_run, "PS", "B8_scans.csv"))
    for scan in ("p_y", "k"):
        best = scan_best(small_run, "PS", scan)
        rows = table[table["scan"] == scan]
        assert list(rows["value"]) == best["values"]
        assert list(rows.loc[rows["best"], "value"]) == [best["best"]]
        folder = small_run / "results" / SMALL / "PS" / "PS" / "scans" / scan
        scan_table = pd.read_csv(folder / "scan.csv")
        grid = scan_table[~scan_table["refined"]]
        assert sorted(scan_table[scan_table["refined"]]["value"]) == sorted(best["refined_values"])
        assert np.allclose(rows["log_area_distance"], grid["log_area_distance"], equal_nan=True)
        error = ModelError.from_record(json.loads((folder / "refinement.json").read_text())[
            "model_error"])  # fmt: skip
        criterion = Criterion(tuple(best["criterion_loads_mn"]), best["measured_log_area_sd"],
                              error)  # fmt: skip
        chi2 = {
            value: criterion.chi2(
                point_from_record(
                    json.loads((folder / "values" / value_label(value) / SCAN_POINT).read_text()),
                    criterion.n,
                ).residuals,
                best["log_area_sd_used"],
            )
            for value in best["values"]
        }
        assert min(chi2, key=chi2.get) == best["grid_best"]


def test_b11_csv_holds_the_measured_areas_and_the_best_k(small_run):
    table = pd.read_csv(study_file(small_run, "PS", "B11_load_series.csv"))
    areas = pd.read_csv(measured(small_run, "PS", "PS", "contact_area.csv"))
    experiment = table[table["row"] == "experiment"]
    assert np.allclose(experiment["area_um2"], areas["area_um2"])
    assert set(table["row"]) == {"experiment", "greenwood_tripp", "elastic", "hardening"}
    assert (table["best_k_mpa_per_nm"] == scan_best(small_run, "PS", "k")["best"]).all()
    hardening = table[table["row"] == "hardening"]
    elastic = table[table["row"] == "elastic"]
    # the figure's claim: hardening at the best k overlaps the measured contact better than
    # the elastic scene does, at every load
    assert (hardening["iou"].to_numpy() > elastic["iou"].to_numpy()).all()


def test_b9_csv_gives_the_measured_and_the_simulated_flattening(small_run):
    """The measured flattening in the solver window has the depth the topography step
    measured on the whole map (within 10 %: the window holds the whole contact), and the
    hardening model at the best k flattens the surface by a depth of the same order (the
    appendix: 'the overall magnitude ... is well described')."""
    table = pd.read_csv(study_file(small_run, "PS", "B9_flattening.csv")).set_index("panel")
    topography = json.loads(measured(small_run, "PS", "PS", "topography.json").read_text())
    depth = topography["flattening_depth_nm"]["estimate"]
    measured_depth = table.loc["measured (after - before)", "flattening_depth_nm"]
    simulated_depth = table.loc["hardening model (h_pl)", "flattening_depth_nm"]
    print(
        "flattening depth, nm: whole map", depth, "window", measured_depth, "model", simulated_depth
    )
    assert measured_depth == pytest.approx(depth, rel=0.1)
    assert 0.33 < simulated_depth / measured_depth < 3
    assert (table["best_k_mpa_per_nm"] == scan_best(small_run, "PS", "k")["best"]).all()


def test_b12_csv_holds_every_model_with_its_exponent(small_run):
    table = pd.read_csv(study_file(small_run, "PS", "B12_models.csv"))
    fit = json.loads(measured(small_run, "PS", "PS", "load_area_fit.json").read_text())
    measured_rows = table[table["series"] == "measured"]
    assert measured_rows["exponent"].iloc[0] == fit["exponent"]["estimate"]
    best = scan_best(small_run, "PS", "k")
    series = f"hardening, best k_mpa_per_nm = {best['best']:g}"
    assert table.loc[table["series"] == series, "exponent"].iloc[0] == pytest.approx(
        best["best_rendered_fit"]["exponent"]["estimate"], abs=1e-12
    )
    for scene in ("elastic", "penetration_hardness", "hardening", "greenwood_tripp"):
        assert (table["series"] == f"scene {scene}").sum() == 5


def test_b13_csv_normalises_measurement_and_model_at_the_reference_load(small_run):
    table = pd.read_csv(small_run / "results" / SMALL / "study" / "B13_amontons.csv")
    for sphere in ("PS", "glass"):
        rows = table[table["sphere"] == sphere]
        model = rows[rows["series"] == "hardening model"]
        assert model.loc[np.isclose(model["load_over_ref"], 1.0), "area_over_ref"].iloc[0] == 1.0
        assert (model["best_k_mpa_per_nm"] == scan_best(small_run, sphere, "k")["best"]).all()
        amontons = pd.read_csv(small_run / "results" / SMALL / sphere / "amontons.csv")
        measured_rows = rows[rows["series"] == "measured"]
        assert np.allclose(measured_rows["area_over_ref"], amontons["area_over_area_ref"])


def test_without_scans_no_scan_or_study_job_runs(project):
    def edit(config):
        config["run_scans"] = []
        config["study"] = {"run_curvature_pairs": []}

    _edit_config(project, edit)
    result = snakemake(project, "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    for rule in (
        "scan_scene",
        "best_scan_value",
        "plot_scan_maps",
        "tabulate_models",
        "plot_curvature_study",
        "plot_amontons_study",
    ):
        assert f"rule {rule}:" not in result.stdout
    assert "scenes/hardening/comparison.csv" in result.stdout  # the scenes still run


def test_slurm_dry_run_of_the_full_config_has_one_job_per_sphere_and_scan(project):
    """A scan's values run as a chain (each from the one before), so a cluster gets one job
    per sphere and scan, and the spheres' scans run side by side; each asks for its values'
    predicted solves together."""
    result = snakemake(
        project,
        "-n",
        "--profile",
        str(REPO / "profiles" / "slurm"),
        "--configfile",
        "config/config.yaml",
    )
    assert result.returncode == 0, result.stderr
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    spheres = 5  # PS, PMMA-1.5mm, PMMA-4mm, PTFE, glass
    expected = spheres * len(config["run_scans"])
    jobs = re.findall(r"rule scan_scene:\n(?:\s+.+\n)*?\s+wildcards: (.+)\n", result.stdout)
    assert len(jobs) == expected == len(set(jobs))
    assert all("value=" not in job for job in jobs)
