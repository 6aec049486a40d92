"""The software the workflow declares: pyproject.toml's dependencies and version, and the conda
environment every rule names (workflow/envs/amontons.yaml, docs/deploy.md "Software per job")."""

import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import yaml

import amontons

REPO = Path(__file__).resolve().parents[1]
ENVIRONMENT = REPO / "workflow" / "envs" / "amontons.yaml"
# conda-forge names of the PyPI packages where the two differ: matplotlib-base is matplotlib
# without a GUI toolkit, which the jobs (Agg backend) do not use.
CONDA_NAMES = {"matplotlib": "matplotlib-base"}
# Dependencies the jobs' environment does not list: each with the reason.
NOT_IN_ENVIRONMENT = {
    # the rules' scripts run under the Snakemake that calls them, which puts its own package
    # on the script's path; the environment needs only what the scripts import
    "snakemake",
}


def _pyproject() -> dict:
    with open(REPO / "pyproject.toml", "rb") as stream:
        return tomllib.load(stream)


def _requirement(line: str) -> tuple[str, str]:
    """A dependency as pip ('numpy>=1.26') or conda ('numpy >=1.26') writes it, as (name in
    lower case, its version bounds without spaces, sorted: '>=1.26' or '')."""
    match = re.fullmatch(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)\s*(.*?)\s*", line)
    if match is None:
        raise ValueError(f"{line!r} is not a package name with version bounds")
    bounds = ",".join(sorted(part.replace(" ", "") for part in match[2].split(",") if part))
    return match[1].lower(), bounds


def _environment() -> tuple[dict[str, str], dict[str, str]]:
    """The environment's conda and pip packages, each as {name: bounds}; pip entries that are
    paths (the amontons library itself) left out."""
    with open(ENVIRONMENT, encoding="utf-8") as stream:
        dependencies = yaml.safe_load(stream)["dependencies"]
    conda, pip = {}, {}
    for entry in dependencies:
        if isinstance(entry, dict):
            for line in entry["pip"]:
                if not line.startswith((".", "/")):
                    name, bounds = _requirement(line)
                    pip[name] = bounds
        else:
            name, bounds = _requirement(entry)
            conda[name] = bounds
    return conda, pip


def test_the_environment_lists_every_dependency_of_pyproject_with_its_bounds():
    """Each runtime dependency of pyproject.toml is in the environment under its conda-forge
    name (or, where the file says so, from pip) with the same version bounds, Python with
    pyproject's requires-python, and the environment lists nothing pyproject does not."""
    project = _pyproject()["project"]
    conda, pip = _environment()
    assert conda.pop("python") == _requirement("python" + project["requires-python"])[1]
    assert conda.pop("pip") == ""
    expected = dict(map(_requirement, project["dependencies"]))
    for name in NOT_IN_ENVIRONMENT:
        del expected[name]
    listed = dict(pip)
    for name, bounds in conda.items():
        pypi = next((p for p, c in CONDA_NAMES.items() if c == name), name)
        listed[pypi] = bounds
    assert listed == expected
    assert not set(pip) & {CONDA_NAMES.get(name, name) for name in conda}


def test_the_library_reports_pyprojects_version():
    """pyproject.toml holds the version (docs/deploy.md, "Cutting a release"); the library's
    __version__ must say the same, so that a run can tell which release made it."""
    assert amontons.__version__ == _pyproject()["project"]["version"]


@pytest.mark.workflow
@pytest.mark.skipif(
    shutil.which("conda") is None,
    reason="Snakemake 9 asks `conda info --json` even for a dry run with --sdm conda, and no "
    "conda command is on the PATH (docs/deploy.md)",
)
def test_a_dry_run_with_conda_environments(tmp_path):
    """Every job of the small data set gets the environment of workflow/envs/amontons.yaml."""
    shutil.copytree(REPO / "config", tmp_path / "config")
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile"), "-d", str(tmp_path)]
        + ["-n", "--sdm", "conda", "--configfile", "config/test.yaml"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr
    assert "This was a dry-run" in result.stdout
    assert "workflow/envs/amontons.yaml" in result.stdout + result.stderr
