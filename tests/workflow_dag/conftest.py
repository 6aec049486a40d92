"""A run of the workflow as amontons.workflow builds it from the shipped configs, without
Snakemake: the same call workflow/rules/common.smk makes."""

import copy

import pandas as pd
import pytest

from amontons.config import read_config
from amontons.workflow.run import WorkflowRun


def build_run(repo, name="test.yaml", edit=None):
    """The WorkflowRun of config/config.yaml with config/``name`` merged over it (``edit``:
    a function that changes the merged config first)."""
    overlays = [] if name == "config.yaml" else [repo / "config" / name]
    config = read_config(repo / "config" / "config.yaml", *overlays)
    if edit is not None:
        edit(config)
    return WorkflowRun.from_config(copy.deepcopy(config), repo / "workflow", name)


@pytest.fixture
def make_run(repo, monkeypatch):
    """build_run, from the repository (the sheet's path is relative to the project folder)."""
    monkeypatch.chdir(repo)
    return lambda name="test.yaml", edit=None: build_run(repo, name, edit)


@pytest.fixture
def small(make_run):
    """The small data set's run."""
    return make_run()


@pytest.fixture
def measured_ps(repo, tmp_path, monkeypatch):
    """A project folder (the working directory) whose sheet makes PS a measured sphere in
    lab/PS; returns a function that builds the run as the DAG does."""
    monkeypatch.chdir(tmp_path)
    lab = tmp_path / "lab" / "PS"
    for name in ("reflection.tif", "bead.tif", "absorbance.csv", "afm_before.tif"):
        (lab / name).parent.mkdir(parents=True, exist_ok=True)
        (lab / name).write_text("")  # found, never read: the DAG only looks for them
    (lab / "rheometer").mkdir()
    sheet = pd.read_csv(repo / "config" / "materials.tsv", sep="\t", dtype=str)
    sheet.loc[sheet["sphere"] == "PS", "data_source"] = str(lab)
    sheet.to_csv(tmp_path / "sheet.tsv", sep="\t", index=False)

    def edit(config):
        config.update(materials_sheet=str(tmp_path / "sheet.tsv"))

    return lambda: build_run(repo, edit=edit)
