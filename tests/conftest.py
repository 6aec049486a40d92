"""Shared fixtures: repository paths and the schemas."""

from pathlib import Path

import pytest

from amontons.config import load_schema

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def config_schema() -> dict:
    return load_schema(REPO / "workflow" / "schemas" / "config.schema.yaml")


@pytest.fixture(scope="session")
def sheet_schema() -> dict:
    return load_schema(REPO / "workflow" / "schemas" / "materials.schema.yaml")


# Test modules that start Snakemake runs of minutes, first: under pytest-xdist (``make test``,
# --dist loadscope, one module per worker at a time) the longest runs then start at once on
# different workers, and the many short unit tests fill the gaps at the end. The first makes
# the session's small-data run (tests/workflow/conftest.py), the second runs its own spheres
# from the small data's virtual experiment meanwhile.
LONG_RUNS_FIRST = (
    "tests/workflow/test_deploy.py",
    "tests/workflow/test_own_data.py",
    "tests/workflow/test_executor.py",
    "tests/workflow/test_instrument_route.py",
    "tests/workflow/test_workflow.py",
)


def pytest_collection_modifyitems(config, items):
    """The modules of LONG_RUNS_FIRST first, in that order; the rest as collected."""
    rank = {path: i for i, path in enumerate(LONG_RUNS_FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(rank)))
