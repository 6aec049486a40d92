"""A run of the workflow as amontons.workflow builds it from the shipped configs, without
Snakemake: the same call workflow/rules/common.smk makes."""

import copy

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
