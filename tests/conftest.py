"""Shared fixtures: repository paths and the schemas."""

from pathlib import Path

import pytest

from amontons.config import load_schema

REPO = Path(__file__).resolve().parents[1]


def pytest_addoption(parser):
    parser.addoption(
        "--cluster",
        action="store_true",
        help="collect tests/cluster: a one-node SLURM started as root (make test-cluster)",
    )


def pytest_ignore_collect(collection_path, config):
    """tests/cluster only under --cluster (make test-cluster), never in make test."""
    if collection_path == REPO / "tests" / "cluster" and not config.getoption("--cluster"):
        return True
    return None


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def config_schema() -> dict:
    return load_schema(REPO / "workflow" / "schemas" / "config.schema.yaml")


@pytest.fixture(scope="session")
def sheet_schema() -> dict:
    return load_schema(REPO / "workflow" / "schemas" / "materials.schema.yaml")


# The order in which `make test`'s processes (pytest-xdist, --dist loadscope: one module per
# process at a time) take the modules; the rest follow as collected. make test compiles the
# solver's kernels beside the tests, one core for about 75 s on a cold cache, and every solve
# waits for it (amontons.contact.jit), the small data set's first.
# - The two modules whose Snakemake runs take longest, first, on two processes: the first
#   makes the session's small-data run (tests/workflow/conftest.py), the second runs its own
#   spheres from the small data's virtual experiment meanwhile.
# - Then modules that solve nothing, for the third process while the kernels compile and the
#   other two wait for them and for the small data set (without them that core sat idle).
# - Then the short Snakemake runs and the workflow tests, whose first tests (dry runs) run
#   beside the two long runs and whose others wait for the small run.
# - Then the runs that wait for the two long ones (the lab's three continuations and the
#   cluster executor, each 100 to 170 s under make test, the cut-scan and corrupt-file runs,
#   the longest, first; the instrument route's short run last), so that they are at the head
#   of the queue when the two long runs end, for the processes those free, side by side; the
#   unit tests last, to fill the gaps. A process takes the next module as soon as it has two
#   tests or fewer left: each one-test module is followed by a module of several tests that
#   read the small run, so that no process takes two of the long ones in a row. (The
#   prior-free scans, three tests, may still take the instrument route after them when no
#   other process asks first.) docs/testing.md gives the measured timeline; earlier orders
#   and what they cost are in benchmarks/HISTORY.md.
MODULE_ORDER = (
    "tests/workflow/test_deploy.py",
    "tests/workflow/test_own_data.py",
    # solve nothing: each was run on an empty numba cache and left it empty
    "tests/simulate/test_register.py",
    "tests/io/test_ptu.py",
    "tests/measure/test_newton_rings.py",
    "tests/study/test_plots.py",
    "tests/virtual/test_instrument_formats.py",
    "tests/test_map_resolution.py",
    "tests/io/test_bad_files.py",
    "tests/io/test_confocal.py",
    "tests/io/test_rawdata.py",
    "tests/io/test_rheometer_files.py",
    "tests/io/test_rheometer_export.py",
    "tests/io/test_heightmap.py",
    "tests/io/test_pixel_probe.py",
    "tests/io/test_tiff.py",
    "tests/measure/test_area.py",
    "tests/measure/test_grafting.py",
    "tests/measure/test_psf.py",
    "tests/measure/test_topography.py",
    "tests/measure/test_hard_cases.py",
    "tests/virtual/test_instrument_files.py",
    "tests/workflow_dag/test_spheres.py",
    "tests/workflow_dag/test_scenes.py",
    "tests/study/test_summary.py",
    "tests/test_docs.py",
    "tests/test_architecture.py",
    "tests/test_config.py",
    "tests/test_config_reference.py",
    "tests/test_model_names.py",
    # short Snakemake runs
    "tests/workflow/test_killed_run.py",
    "tests/workflow/test_load_series_run.py",
    "tests/workflow/test_dag_unchanged.py",
    "tests/workflow/test_workflow.py",
    # the runs that wait for the two long ones, each one-test module followed by a module
    # of several tests that read the small run
    "tests/workflow/test_scan_on_cut_scans.py",
    "tests/workflow/test_report.py",
    "tests/workflow/test_corrupt_file.py",
    "tests/workflow/test_validation_run.py",
    "tests/workflow/test_executor.py",
    "tests/workflow/test_accuracy_run.py",
    "tests/workflow/test_no_prior.py",
    "tests/workflow/test_instrument_route.py",
)


def pytest_collection_modifyitems(config, items):
    """The modules of MODULE_ORDER first, in that order; the rest as collected. A module it
    names that is not there stops the session: a renamed module would otherwise lose its
    place in silence."""
    gone = [path for path in MODULE_ORDER if not (REPO / path).is_file()]
    if gone:
        raise pytest.UsageError(f"tests/conftest.py: MODULE_ORDER names no such module: {gone}")
    rank = {path: i for i, path in enumerate(MODULE_ORDER)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(rank)))
