"""Citations of the benchmark pages find their sections, and the reference page stays one.

benchmarks/README.md is the reference page: per benchmark what it measures, its command,
today's figure and the target. The dated notebook it was until 2026-11-27 (rounds, superseded
tables, ideas tried and dropped) moved verbatim to benchmarks/HISTORY.md. Code comments,
docstrings, docs and the changelog cite sections of these pages, by a quoted title (one that
may wrap over a comment's line break), by number or by part, for example::

    (benchmarks/README.md, "A second core")
    benchmarks/README.md §1; benchmarks/README.md, benchmark 7, part C
    (benchmarks/README.md, "Why the
    # kernels are written as they are")

Moving history out, or trimming the reference page, must not leave one of them pointing at a
section that is gone. So this test finds every citation of either page in the repository's
text files (src/, scripts/, tests/, docs/, benchmarks/, workflow/, README.md, CHANGELOG.md,
Snakefile; untracked files too, so that a new comment is checked before it is committed) and
requires that it resolves:

* a quoted title is part of a heading line of the cited page (case-sensitive, whitespace
  normalised);
* ``§N`` and ``benchmark N`` name a heading ``## N.`` of the page; a title after ``§N`` is part
  of a heading in that section, and ``part X`` appears in it as "Part X" or "part X";
* ``#anchor`` after the page is the GitHub anchor of one of its headings.

It also holds the reference page to its shape: at most 400 lines, and every relative link and
every ``python benchmarks/x.py`` or ``bash benchmarks/x.sh`` it gives names a file that exists.
Each failure names the citing file and line.
"""

import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BENCHMARKS = REPO / "benchmarks"
PAGES = {"README": BENCHMARKS / "README.md", "HISTORY": BENCHMARKS / "HISTORY.md"}
SCANNED = (
    "src",
    "scripts",
    "tests",
    "docs",
    "benchmarks",
    "workflow",
    "README.md",
    "CHANGELOG.md",
    "Snakefile",
)
MAX_README_LINES = 400

# The page a citation names: benchmarks/README.md, benchmarks/HISTORY.md, or without ".md".
PAGE = re.compile(r"benchmarks/(README|HISTORY)(?:\.md)?")
ANCHOR = re.compile(r"#([\w-]+)")
# What may follow the page name (whitespace normalised, comment markers dropped).
SECTION = re.compile(r"\s*,?\s*\(?§\s*(\d+)")
BENCHMARK = re.compile(r"\s*,?\s*\(?benchmark\s+(\d+)")
PART = re.compile(r"\s*,\s*part\s+([A-Za-z])\b")
# A title starts with a letter or digit, so that a string's closing quote followed by
# another string (`"benchmarks/README.md", "x"`) is not read as one.
TITLE = re.compile(r'\s*,?\s*"([A-Za-z0-9][^"]{0,119})"')
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
COMMAND = re.compile(r"\b(?:python|bash)\s+(benchmarks/[\w./-]+\.(?:py|sh))\b")


@dataclass(frozen=True)
class Citation:
    source: str  # "path:line" of the citing text
    page: str  # "README" or "HISTORY"
    titles: tuple[str, ...] = ()
    section: int | None = None
    part: str | None = None
    anchor: str | None = None

    def __str__(self) -> str:
        said = [f"benchmarks/{self.page}.md"]
        if self.anchor:
            said[0] += f"#{self.anchor}"
        if self.section is not None:
            said.append(f"§{self.section}")
        if self.part:
            said.append(f"part {self.part}")
        said += [f'"{title}"' for title in self.titles]
        return f"{self.source}: " + ", ".join(said)


def normalise(text: str) -> str:
    return " ".join(text.split())


def following(text: str, end: int) -> str:
    """The text after a citation's page name, its next three lines joined: each continuation
    line without its indentation and comment markers (``#``), whitespace normalised."""
    lines = text[end : end + 600].split("\n")[:4]
    rest = [re.sub(r"^\s*#*", "", line) for line in lines[1:]]
    return normalise(" ".join([lines[0], *rest]))


def parse(tail: str) -> dict:
    """What a citation names after its page: an anchor, ``§N`` or ``benchmark N`` (with a
    title or ``part X`` after it), or quoted titles."""
    found: dict = {"titles": ()}
    if m := ANCHOR.match(tail):
        found["anchor"] = m.group(1)
        tail = tail[m.end() :]
    tail = tail.lstrip("`")
    if m := SECTION.match(tail) or BENCHMARK.match(tail):
        found["section"] = int(m.group(1))
        tail = tail[m.end() :]
        if m := PART.match(tail):
            found["part"] = m.group(1)
            return found
    titles = []
    while m := TITLE.match(tail):
        titles.append(normalise(m.group(1)))
        tail = tail[m.end() :]
    found["titles"] = tuple(titles)
    return found


def citations_in(text: str, source: str) -> list[Citation]:
    found = []
    for m in PAGE.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        parts = parse(following(text, m.end()))
        found.append(Citation(f"{source}:{line}", m.group(1), **parts))
    return found


def scanned_files() -> list[Path]:
    """The repository's text files in SCANNED, tracked or new (git's ignore rules apply)."""
    try:
        listed = subprocess.run(
            ["git", "ls-files", "--cached", "--others", "--exclude-standard", "--", *SCANNED],
            cwd=REPO,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.splitlines()
        paths = [REPO / name for name in listed]
    except (OSError, subprocess.CalledProcessError):  # not a git checkout
        paths = []
        for name in SCANNED:
            top = REPO / name
            paths += [top] if top.is_file() else sorted(top.rglob("*"))
    skip = {".venv", "__pycache__", ".git"}
    return [
        path
        for path in paths
        if path.is_file()
        and path.resolve() != Path(__file__).resolve()  # its examples are not citations
        and not skip.intersection(path.relative_to(REPO).parts)
        and path.stat().st_size < 2_000_000
    ]


def all_citations() -> list[Citation]:
    found = []
    for path in scanned_files():
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue  # not a text file
        found += citations_in(text, str(path.relative_to(REPO)))
    return found


def without_code(text: str) -> list[str]:
    """The page's lines with those of fenced code blocks blanked (a "# " there is no heading)."""
    lines, fenced = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
            lines.append("")
        else:
            lines.append("" if fenced else line)
    return lines


def headings(lines: list[str]) -> list[str]:
    return [normalise(line.lstrip("#")) for line in lines if re.match(r"#{1,6} ", line)]


def numbered_section(lines: list[str], number: int) -> list[str] | None:
    """The lines of section ``## N.``, its heading first, up to the next ``##`` heading."""
    start = next((i for i, line in enumerate(lines) if line.startswith(f"## {number}.")), None)
    if start is None:
        return None
    end = next(
        (i for i in range(start + 1, len(lines)) if re.match(r"#{1,2} ", lines[i])), len(lines)
    )
    return lines[start:end]


def anchor(heading: str) -> str:
    """The anchor GitHub gives a heading (as tests/test_docs.py computes it)."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def problems(citation: Citation, pages: dict[str, Path] = PAGES) -> list[str]:
    """Why ``citation`` does not resolve against ``pages``; empty when it does."""
    page = pages[citation.page]
    if not page.exists():
        return [f"{citation}: {page.relative_to(REPO)} does not exist"]
    lines = without_code(page.read_text(encoding="utf-8"))
    found = []
    if citation.anchor and citation.anchor not in {anchor(h) for h in headings(lines)}:
        found.append(f"{citation}: no heading with anchor #{citation.anchor}")
    scope = lines
    if citation.section is not None:
        scope = numbered_section(lines, citation.section)
        if scope is None:
            return found + [f"{citation}: no heading '## {citation.section}.' in the page"]
        if citation.part and not re.search(rf"\b[Pp]art {citation.part}\b", "\n".join(scope)):
            found.append(f"{citation}: no 'Part {citation.part}' in section {citation.section}")
    for title in citation.titles:
        if not any(title in heading for heading in headings(scope)):
            where = "the page" if scope is lines else f"section {citation.section}"
            found.append(f'{citation}: no heading in {where} contains "{title}"')
    return found


def test_every_citation_of_the_benchmark_pages_resolves():
    citations = all_citations()
    assert citations, "no citation of benchmarks/README.md found: the scan is broken"
    broken = [problem for citation in citations for problem in problems(citation)]
    assert not broken, "\n".join(broken)


def test_the_scan_reads_each_form_of_citation():
    text = (
        'see (benchmarks/README.md, "A second\n    # core"); `benchmarks/README.md` §3;\n'
        'benchmarks/README.md,\n  # §2 "Design note"\nbenchmarks/README.md,\nbenchmark 7, '
        'part C; benchmarks/README.md "Fused kernels"; (benchmarks/README);\n'
        'benchmarks/README.md, "FFTW planner effort", "Fast FFT lengths"\n'
        'benchmarks/HISTORY.md#stall-window; x = "benchmarks/README.md", "y"\n'
    )
    found = citations_in(text, "example")
    assert [(c.source, c.page, c.titles, c.section, c.part, c.anchor) for c in found] == [
        ("example:1", "README", ("A second core",), None, None, None),
        ("example:2", "README", (), 3, None, None),
        ("example:3", "README", ("Design note",), 2, None, None),
        ("example:5", "README", (), 7, "C", None),
        ("example:6", "README", ("Fused kernels",), None, None, None),
        ("example:6", "README", (), None, None, None),
        ("example:7", "README", ("FFTW planner effort", "Fast FFT lengths"), None, None, None),
        ("example:8", "HISTORY", (), None, None, "stall-window"),
        ("example:8", "README", (), None, None, None),
    ]


def test_a_citation_of_a_missing_section_fails():
    """The check is not vacuous: each form of citation fails when its section is gone."""
    gone = [
        Citation("example:1", "README", titles=("A section that is not there",)),
        Citation("example:2", "README", section=99),
        Citation("example:3", "README", section=7, part="Z"),
        Citation("example:4", "README", section=2, titles=("Stall window",)),
        Citation("example:5", "HISTORY", anchor="no-such-heading"),
    ]
    for citation in gone:
        assert problems(citation), f"{citation} resolved"
    assert not problems(Citation("example:6", "README", section=7, part="C"))


def test_the_reference_page_is_at_most_400_lines():
    lines = PAGES["README"].read_text(encoding="utf-8").splitlines()
    assert len(lines) <= MAX_README_LINES, (
        f"benchmarks/README.md:{MAX_README_LINES + 1}: the page has {len(lines)} lines, more "
        f"than {MAX_README_LINES}; dated rounds belong in benchmarks/HISTORY.md"
    )


def test_the_reference_page_names_files_that_exist():
    text = PAGES["README"].read_text(encoding="utf-8")
    missing = []
    for number, line in enumerate(text.splitlines(), start=1):
        for link in LINK.findall(line):
            if re.match(r"[a-z][a-z0-9+.-]*:", link):
                continue  # a URL
            path, _, fragment = link.partition("#")
            target = (BENCHMARKS / path).resolve() if path else PAGES["README"]
            if not target.exists():
                missing.append(f"benchmarks/README.md:{number}: link {link}: no file {path}")
            elif fragment and target.suffix == ".md":
                names = {anchor(h) for h in headings(without_code(target.read_text("utf-8")))}
                if fragment not in names:
                    missing.append(f"benchmarks/README.md:{number}: link {link}: no heading")
    for m in COMMAND.finditer(text):
        if not (REPO / m.group(1)).is_file():
            number = text.count("\n", 0, m.start()) + 1
            missing.append(f"benchmarks/README.md:{number}: `{m.group(0)}`: no such script")
    assert not missing, "\n".join(missing)
