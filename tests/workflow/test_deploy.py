"""The workflow deployed as a Snakemake module (docs/deploy.md): a folder of a user's own, with
their config/ (a copy of the repository's, run with the small overlay) and the README's
Snakefile, which declares the repository's Snakefile as a module and uses all its rules. The
session's small-data run is that folder (tests/workflow/conftest.py): the small data set runs
through the module once, with its report, and the tests here read what it made."""

import re
import subprocess
import sys
from itertools import product
from pathlib import Path

import pytest

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[2]
# The run name of config/test.yaml, the overlay the deployed folder runs with.
RUN = "small"
# Where the README's and docs/deploy.md's Snakefile names the clone.
CLONE = "/path/to/amontons"


def python_block(page: Path, heading: str) -> str:
    """The first ```python block below ``heading`` of a Markdown page."""
    section = ("\n" + page.read_text(encoding="utf-8")).split(f"\n{heading}\n", 1)[1]
    return section.split("```python\n", 1)[1].split("```", 1)[0]


def snakemake(project: Path, *args: str, timeout: int = 600) -> subprocess.CompletedProcess:
    """Snakemake in ``project`` as a user runs it there: the folder's own Snakefile."""
    return subprocess.run(
        [sys.executable, "-m", "snakemake", *args],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


@pytest.fixture(scope="module")
def deployed(small_run):
    """A user's folder after the small data set ran through the module, with its report."""
    snakefile = python_block(REPO / "README.md", "## Use it from a folder of your own")
    assert CLONE in snakefile
    assert (small_run / "Snakefile").read_text(encoding="utf-8") == snakefile.replace(
        CLONE, str(REPO)
    )
    assert (small_run / "results" / RUN / "report.html").stat().st_size > 0
    return small_run


def test_docs_deploy_shows_the_readmes_module_declaration():
    """docs/deploy.md and the README show the one Snakefile this test runs."""
    shown = python_block(REPO / "docs" / "deploy.md", "## 2. Your folder")
    assert shown == python_block(REPO / "README.md", "## Use it from a folder of your own")


def _expand(pattern: str) -> list[str]:
    """A path of a results tree as glob patterns: `<name>` and `…` match anything,
    `{a,b}` gives one pattern each."""
    pattern = re.sub(r"<[^>]+>|…", "*", pattern)
    parts = re.split(r"\{([^}]*)\}", pattern)
    choices = [[part] if i % 2 == 0 else part.split(",") for i, part in enumerate(parts)]
    return ["".join(combination) for combination in product(*choices)]


def tree_entries(page: Path, heading: str) -> list[str]:
    """The paths of the results tree below ``heading``: the first code block's lines that do
    not start with a space (those continue a description), each path up to its description
    (two spaces); 'a/b.json, c.csv' names a/b.json and a/c.csv."""
    block = ("\n" + page.read_text(encoding="utf-8")).split(f"\n{heading}\n", 1)[1]
    block = block.split("```\n", 1)[1].split("```", 1)[0]
    entries = []
    for line in block.splitlines():
        if not line or line[0] == " ":
            continue
        names = re.split(r",\s+(?![^{]*\})", re.split(r"\s{2,}", line, maxsplit=1)[0])
        folder = names[0].rpartition("/")[0]
        entries += [names[0]] + [f"{folder}/{name}" if folder else name for name in names[1:]]
    assert entries, f"{page.name}: no results tree below {heading!r}"
    return entries


@pytest.mark.parametrize(
    ("page", "heading", "base"),
    [
        ("README.md", "## Where results land", "."),
        ("docs/results.md", "# Where results land", f"results/{RUN}"),
    ],
)
def test_every_result_the_docs_list_is_where_they_say(deployed, page, heading, base):
    """Each path of the README's summary and of docs/results.md's tree (below results/<run>/)
    names at least one file or folder of the deployed run: nothing the docs promise is
    missing or elsewhere."""
    missing = [
        entry
        for entry in tree_entries(REPO / page, heading)
        for pattern in _expand(entry.replace("<run>", RUN))
        if not list((deployed / base).glob(pattern))
    ]
    assert not missing, f"{page}: {missing}"


def test_a_second_run_of_the_deployed_module_has_nothing_to_do(deployed):
    """The module's jobs are complete and up to date: its code, params and inputs read the
    same from the user's folder on every run."""
    result = snakemake(deployed, "-n", "--configfile", "config/test.yaml")
    assert result.returncode == 0, result.stderr
    assert "Nothing to be done" in result.stdout + result.stderr


def _job_counts(result: subprocess.CompletedProcess) -> dict[str, int]:
    """The 'Job stats' table of a dry run: jobs per rule."""
    assert result.returncode == 0, result.stderr
    table = (result.stdout + result.stderr).split("Job stats:", 1)[1].split("\n\n", 1)[0]
    return {rule: int(n) for rule, n in re.findall(r"^(\w+)\s+(\d+)$", table, re.M)}


def test_the_module_schedules_the_jobs_of_the_repositorys_snakefile(deployed):
    """Every job of the small data set, counted by rule, is the same through the module as
    through the repository's Snakefile run on the same folder."""
    forced = ("-n", "--forceall", "--configfile", "config/test.yaml")
    through_module = _job_counts(snakemake(deployed, *forced))
    direct = _job_counts(snakemake(deployed, "-s", str(REPO / "Snakefile"), *forced))
    assert through_module == direct
    assert through_module["scan_scene"] > 0 and through_module["total"] > 50
