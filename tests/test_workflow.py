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
    jobs = result.stdout.count("rule generate_virtual_experiment:")
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
    # Re-running does nothing: every output is up to date.
    again = snakemake(project, "-n", "--configfile", "config/test.yaml")
    assert "Nothing to be done" in again.stdout + again.stderr


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
