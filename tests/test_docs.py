"""The documentation holds together: the README links every page of docs/, every relative link
of the README, docs/, config/README.md and CHANGELOG.md points to a file (and heading) that
exists, docs/workflow.md shows the current rule graph, and CHANGELOG.md's versions agree with
pyproject.toml's."""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PAGES = [
    REPO / "README.md",
    REPO / "config" / "README.md",
    REPO / "CHANGELOG.md",
    *sorted((REPO / "docs").glob("*.md")),
]
# [text](target): a Markdown link; an image's ![alt](target) is one too.
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def prose(text: str) -> str:
    """``text`` without its fenced code blocks and inline code, where brackets are code."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.M | re.S)
    return re.sub(r"`[^`\n]*`", "", text)


def relative_links(page: Path) -> list[str]:
    """The links of ``page`` that point into the repository (no scheme, no mail address)."""
    links = LINK.findall(prose(page.read_text(encoding="utf-8")))
    return [link for link in links if not re.match(r"[a-z][a-z0-9+.-]*:", link)]


def anchor(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    """The anchors of every heading of a Markdown page (code blocks left out)."""
    headings = re.findall(r"^#{1,6} (.+)$", prose(page.read_text(encoding="utf-8")), re.M)
    return {anchor(heading) for heading in headings}


def test_anchor_follows_github():
    assert anchor("Software per job: --sdm conda") == "software-per-job---sdm-conda"
    assert anchor("1.5 Newton rings and the gap") == "15-newton-rings-and-the-gap"
    assert anchor("Where results land") == "where-results-land"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_every_relative_link_points_to_an_existing_file_and_heading(page):
    broken = []
    for link in relative_links(page):
        path, _, fragment = link.partition("#")
        target = (page.parent / path).resolve() if path else page
        if not target.exists():
            broken.append(f"{link}: no file {target}")
        elif fragment and fragment not in anchors(target):
            broken.append(f"{link}: no heading #{fragment} in {target.relative_to(REPO)}")
    assert not broken, f"{page.relative_to(REPO)}: " + "; ".join(broken)


def test_the_readme_links_every_page_of_docs():
    """The reference material lives in docs/; the README is where a reader finds it."""
    linked = {(REPO / link.partition("#")[0]).resolve() for link in relative_links(PAGES[0])}
    missing = [p.name for p in (REPO / "docs").glob("*.md") if p.resolve() not in linked]
    assert not missing


@pytest.mark.workflow
def test_docs_show_the_current_rule_graph():
    graph = subprocess.run(
        [sys.executable, "-m", "snakemake", "--rulegraph", "mermaid-js", "--quiet", "all"],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert graph.returncode == 0, graph.stderr
    page = (REPO / "docs" / "workflow.md").read_text(encoding="utf-8")
    shown = page.split("```mermaid\n", 1)[1].split("```", 1)[0]

    def named_edges(text):
        # Node ids, colours and edge order vary between runs; the named edges do not.
        names = dict(re.findall(r"(id\d+)\[(\w+)\]", text))
        return {(names[a], names[b]) for a, b in re.findall(r"(id\d+) --> (id\d+)", text)}

    assert named_edges(shown) == named_edges(graph.stdout)
    assert named_edges(shown)


def _version(text: str) -> tuple[int, ...]:
    return tuple(int(part) for part in text.split("."))


def test_the_changelog_agrees_with_pyprojects_version():
    """CHANGELOG.md (Keep a Changelog): sections `[Unreleased]` or `[X.Y.Z] - YYYY-MM-DD`,
    newest first; pyproject.toml's version is the newest released one, or, while an
    Unreleased section lists changes to come, one above every released version (the one the
    next release will carry)."""
    text = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    sections = re.findall(r"^## (.+)$", text, re.M)
    assert sections
    released = []
    for number, section in enumerate(sections):
        if section == "[Unreleased]":
            assert number == 0, "the Unreleased section comes first"
            continue
        match = re.fullmatch(r"\[(\d+\.\d+\.\d+)\] - \d{4}-\d{2}-\d{2}", section)
        assert match, f"CHANGELOG.md: section {section!r} is not '[X.Y.Z] - YYYY-MM-DD'"
        released.append(_version(match[1]))
    assert released == sorted(released, reverse=True) and len(set(released)) == len(released)
    with open(REPO / "pyproject.toml", "rb") as stream:
        version = _version(tomllib.load(stream)["project"]["version"])
    if sections[0] == "[Unreleased]":
        assert all(version > v for v in released) or version == released[0]
    else:
        assert version == released[0]


def test_the_readmes_job_count_is_the_full_runs():
    """The README's count of `make reproduce`'s jobs is the full config's DAG: the record
    tests/workflow/test_dag_unchanged.py holds to a dry run of config/config.yaml."""
    text = PAGES[0].read_text(encoding="utf-8")
    block = text.split("make reproduce", 1)[1].split("make test", 1)[0]
    claimed = [int(n) for n in re.findall(r"(\d+) jobs", block)]
    record = REPO / "tests" / "workflow" / "dags" / "config.jsonl"
    jobs = len(record.read_text(encoding="utf-8").splitlines())
    assert claimed and all(n == jobs for n in claimed), (claimed, jobs)
