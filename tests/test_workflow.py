"""The workflow as a user runs it: static checks, dry runs, targets, bad configs, a small real run.

Each Snakemake call runs in a fresh working directory holding a copy of config/, as a user's
project folder would, with the repository's Snakefile.
"""

import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def run(args, cwd, timeout=600):
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=timeout)


def snakemake(workdir, *args, timeout=600):
    command = [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile"), "-d", str(workdir)]
    return run([*command, *args], cwd=workdir, timeout=timeout)


@pytest.fixture
def project(tmp_path):
    shutil.copytree(REPO / "config", tmp_path / "config")
    return tmp_path


def _edit_config(project, edit):
    path = project / "config" / "test.yaml"
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
    assert "resources/synthetic/PS/" in result.stdout
    assert "glass" not in result.stdout


def test_lifetime_job_only_where_a_flim_map_exists(project):
    # The sheet gives PS a FLIM load and glass none: the DAG holds PS's lifetime job only.
    result = snakemake(project, "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    assert "results/PS/PS/lifetime.json" in result.stdout
    assert "results/glass/glass/lifetime.json" not in result.stdout
    assert result.stdout.count("rule measure_lifetime:") == 1
    assert "resources/synthetic/PS/flim.tif" in result.stdout
    assert "resources/synthetic/glass/flim.tif" not in result.stdout


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


def test_slurm_profile_dry_run_shows_per_job_resources(project):
    result = snakemake(
        project,
        "-n",
        "--profile",
        str(REPO / "profiles" / "slurm"),
        "--configfile",
        "config/test.yaml",
    )
    assert result.returncode == 0, result.stderr
    jobs = result.stdout.count("rule generate_virtual_experiment:") + result.stdout.count(
        "rule generate_virtual_experiment_with_flim:"
    )
    assert jobs == 2
    assert result.stdout.count("runtime=10") >= jobs and "slurm_partition=" in result.stdout


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda c: c.update(materials=["PS", "PEEK"]), "allowed values (from the sample sheet)"),
        (lambda c: c["optics"].update(otsu_bin=c["optics"].pop("otsu_bins")), "'otsu_bin'"),
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


def test_small_data_run(project):
    start = time.perf_counter()
    result = snakemake(project, "--cores", "2", "--configfile", "config/test.yaml")
    elapsed = time.perf_counter() - start
    assert result.returncode == 0, result.stderr[-3000:]
    print(f"small-data run: {elapsed:.1f} s")
    for material in ("PS", "glass"):
        for ext in ("png", "pdf", "csv"):
            assert (project / "results" / material / f"load_area.{ext}").stat().st_size > 0
    fit = json.loads((project / "results/glass/glass/load_area_fit.json").read_text())
    truth = json.loads((project / "resources/synthetic/glass/truth.json").read_text())
    # Smooth-sphere virtual experiment: the exponent is Hertz's 2/3; Otsu's blur bias keeps it
    # within 0.01 (see tests/test_virtual_experiment.py).
    assert fit["exponent"]["estimate"] == pytest.approx(truth["area_exponent"], abs=0.01)
    assert fit["n"] == len(truth["loads_mn"])
    for sphere in ("PS", "glass"):
        check_measurements_against_truth(project, sphere, sphere)
    lifetime = json.loads((project / "results/PS/PS/lifetime.json").read_text())
    flim = json.loads((project / "resources/synthetic/PS/truth.json").read_text())["flim"]
    # > 1000 pixels on each side with 0.1 ns scatter: standard errors ≈ 0.003 ns, so 0.02 ns
    # is > 5 σ.
    assert lifetime["inside_ns"]["mean"] == pytest.approx(flim["contact_ns"], abs=0.02)
    assert lifetime["outside_ns"]["mean"] == pytest.approx(flim["outside_ns"], abs=0.02)
    assert not (project / "results/glass/glass/lifetime.json").exists()
    # Re-running does nothing: every output is up to date.
    again = snakemake(project, "-n", "--configfile", "config/test.yaml")
    assert "Nothing to be done" in again.stdout + again.stderr
    # A changed setting re-runs exactly the jobs that use it: params hold only their slice.
    # (Key order is kept: Snakemake compares params dicts in order.)
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    config["optics"]["psf"]["profile_radius_nm"] = 1800.0
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    changed = snakemake(project, "-n", "--configfile", "config/test.yaml")
    stats = changed.stdout.split("Job stats:", 1)[1].split("total", 1)[0]
    assert dict(re.findall(r"(\w+)\s+(\d+)\n", stats)) == {"measure_psf": "2", "all": "1"}


def check_measurements_against_truth(project, material, sphere):
    """Each measurement of the small-data run recovers the virtual experiment's truth."""
    results = project / "results" / material / sphere
    truth = json.loads((project / f"resources/synthetic/{sphere}/truth.json").read_text())

    # PSF: shot noise scatters the FWHM by ~1 % at these counts (tests/optics), so 3 % (the
    # brief's tolerance) is a ~3 σ bound that a missing pixel correction (+4 %) breaks.
    psf = json.loads((results / "psf.json").read_text())
    assert psf["fwhm_nm"]["estimate"] == pytest.approx(truth["psf_fwhm_nm"], rel=0.03)
    assert psf["n"] > 100

    # Grafting density: LOWESS maximum scatters by 1.3 % at 6 % noise (tests/optics); 5 %.
    density = json.loads((results / "grafting_density.json").read_text())
    assert density["density_per_um2"] == pytest.approx(truth["grafting_density_per_um2"], rel=0.05)

    # Newton rings: the first bright ring is at λ/4n = 84.3 nm by eq. B.1 (0.1 nm rounding).
    gap = json.loads((results / "edge_gap.json").read_text())
    assert gap["first_ring_gap_nm"] == pytest.approx(truth["first_ring_gap_nm"], abs=0.1)
    assert gap["first_ring_gap_nm"] == pytest.approx(84.3, abs=0.1)
    assert gap["edge_gap_nm"]["n"] == 40
    if sphere == "glass":
        # The stiff 4 mm glass sphere (the appendix's Newton-ring sphere, Fig. B.6): the edge
        # gap within 2 nm of the truth. The Otsu edge of the √p profile lies ~2 % inside the
        # mechanical edge, which biases the extrapolation low by ~1 nm here; for the soft PS
        # sphere the same bias is several nm (README, "Known limitations"), so PS is not held
        # to 2 nm.
        assert gap["edge_gap_nm"]["mean"] == pytest.approx(truth["edge_gap_nm"], abs=2.0)

    # Static friction: the torque-peak median scatters by 0.5 % at 1 % torque noise
    # (tests/virtual); 2 % per load. Speed from the angle slope to 2 % as well.
    friction = pd.read_csv(results / "friction.csv")
    np.testing.assert_allclose(
        friction["static_friction_mN"], truth["static_friction_mn"], rtol=0.02
    )
    np.testing.assert_allclose(
        friction["dynamic_friction_mN"], truth["dynamic_friction_mn"], rtol=0.02
    )
    np.testing.assert_allclose(
        friction["sliding_speed_um_s"], truth["sliding_speed_um_s"], rtol=0.02
    )
    np.testing.assert_allclose(friction["load_mN"], truth["loads_mn"])

    # Intensity ∝ √p: PSF and Otsu mask move the exponent by < 0.01 (tests/optics); ±0.05.
    intensity = json.loads((results / "intensity_pressure_fit.json").read_text())
    assert intensity["exponent"]["estimate"] == pytest.approx(
        truth["intensity_pressure_exponent"], abs=0.05
    )

    # Hertz check of a smooth sphere: the Otsu radius is 1–3 % inside the Hertz radius (the
    # √p edge under the PSF), so the ratio lies in [0.95, 1.0].
    hertz = pd.read_csv(results / "hertz_check.csv")
    assert hertz["radius_ratio"].between(0.95, 1.0).all()

    # Amontons table: normalised at 25 mN; with F_s = τ·A, F_s/F_s,ref follows A/A_ref to the
    # friction and area errors (2 % + 6 %).
    amontons = pd.read_csv(project / "results" / material / "amontons.csv")
    rows = amontons[amontons["sphere"] == sphere]
    assert rows["area_over_area_ref"].iloc[0] == 1.0
    np.testing.assert_allclose(
        rows["friction_over_friction_ref"], rows["area_over_area_ref"], rtol=0.08
    )


def test_readme_shows_the_current_rule_graph():
    graph = run(
        [sys.executable, "-m", "snakemake", "--rulegraph", "mermaid-js", "--quiet", "all"],
        cwd=REPO,
    )
    assert graph.returncode == 0, graph.stderr
    readme = (REPO / "README.md").read_text()
    shown = readme.split("```mermaid\n", 1)[1].split("```", 1)[0]

    def named_edges(text):
        # Node ids, colours and edge order vary between runs; the named edges do not.
        names = dict(re.findall(r"(id\d+)\[(\w+)\]", text))
        return {(names[a], names[b]) for a, b in re.findall(r"(id\d+) --> (id\d+)", text)}

    assert named_edges(shown) == named_edges(graph.stdout)
    assert named_edges(shown)
