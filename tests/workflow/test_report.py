"""The HTML report answers the study's question (issue 35), on the small-data run: its first
page opens with the verdict table, read from the model tables, then Figs. B.13 and B.12; a
scan's estimate lies inside its own interval; summary.md names a file for every number.

The report's first page is the text Snakemake embeds as the JSON string ``workflow_desc``
and the report's script puts on the landing page; these tests read that payload. The check
in a browser (the page as a user sees it) is docs/study.md §6.
"""

import base64
import json
import re
from html.parser import HTMLParser
from pathlib import Path

import pandas as pd
import pytest

from amontons.simulate.scan_record import interval_text, significant

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[2]
SMALL = "small"
# the verdict table's row of the decision by the areas
DECIDED = "decided by the areas at every load (95%, scatter and model error)"


@pytest.fixture(scope="module")
def report_html(small_run) -> str:
    """The HTML report of the small-data run, as `snakemake --report` wrote it there
    (tests/workflow/conftest.py)."""
    return (small_run / "results" / SMALL / "report.html").read_text(encoding="utf-8")


def first_page(html: str) -> str:
    """The landing page's HTML: the report's `workflow_desc` payload (a JSON string)."""
    match = re.search(r"^\s*var workflow_desc = (\".*\");$", html, re.M)
    assert match, "no workflow_desc in the report"
    return json.loads(match.group(1))


class _Tables(HTMLParser):
    """Every table of an HTML text: its caption and its rows of cell texts."""

    def __init__(self):
        super().__init__()
        self.tables, self._cell, self._in_caption = [], None, False

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append({"caption": "", "rows": []})
        elif tag == "caption":
            self._in_caption = True
        elif tag == "tr":
            self.tables[-1]["rows"].append([])
        elif tag in ("td", "th"):
            self._cell = ""

    def handle_endtag(self, tag):
        if tag == "caption":
            self._in_caption = False
        elif tag in ("td", "th"):
            self.tables[-1]["rows"][-1].append(self._cell.strip())
            self._cell = None

    def handle_data(self, data):
        if self._in_caption:
            self.tables[-1]["caption"] += data
        elif self._cell is not None:
            self._cell += data


def verdict_cells(page: str) -> dict[str, dict[str, str]]:
    """The verdict table of the first page: quantity -> sphere -> cell text."""
    parser = _Tables()
    parser.feed(page)
    (table,) = [t for t in parser.tables if t["caption"] == "Verdict per sphere"]
    header, *rows = table["rows"]
    return {row[0]: dict(zip(header[1:], row[1:], strict=True)) for row in rows}


def results(project, *parts) -> Path:
    return project.joinpath("results", SMALL, *parts)


def scan_best(project, sphere, scan) -> dict:
    return json.loads(results(project, sphere, sphere, "scans", scan, "best.json").read_text())


def test_the_first_page_opens_with_the_verdict_read_from_the_model_tables(small_run, report_html):
    """The verdict table comes before anything else of the page, one column per sphere, and
    each cell is the model table's number (models.csv, best.json), formatted as a reader
    quotes it; the verdict row says hardening alone gives PS's exponent and no model is
    singled out on glass, which does not flow (docs/study.md §4)."""
    page = first_page(report_html)
    assert page.index("The answer") < page.index("<table") < page.index("The pipeline")
    cells = verdict_cells(page)
    for sphere in ("PS", "glass"):
        models = pd.read_csv(results(small_run, sphere, "models.csv"))
        hardening = models[models["source"] == "scan k, best value"].iloc[0]
        elastic = models[models["source"] == "scene elastic"].iloc[0]
        measured = cells["measured exponent (95% interval)"][sphere]
        assert measured == (
            f"{hardening['measured_exponent']:.3f} ({hardening['measured_ci_low']:.3f}–"
            f"{hardening['measured_ci_high']:.3f})"
        )
        row = cells["contact hardening at the grid's best k"][sphere]
        assert row.startswith(f"{hardening['exponent']:.3f} (")
        assert row.endswith(f"area ×{hardening['area_ratio_largest']:.2f}")
        assert cells["elastic"][sphere].startswith(f"{elastic['exponent']:.3f} (")
        best = scan_best(small_run, sphere, "k")
        low, high = best["interval"]
        # an interval that reaches the scan's end (glass's k) is stated as the bound it is, and
        # so is every interval where the answer is elastic: its lower end, k ≥ low
        elastic = cells[DECIDED][sphere].startswith("elastic: no flow detected")
        stated = (
            f"{interval_text(low, None if elastic else high)} (bound)"
            if None in (low, high) or elastic
            else f"{significant(best['estimate'])} ({interval_text(low, high)})"
        )
        assert cells["k (estimate, MPa/nm; 95% interval)"][sphere] == (
            f"{stated}; grid's best {significant(best['grid_best'])}"
        )
    verdict = cells["exponent inside the measured 95% interval"]
    assert verdict["PS"] == "contact hardening only"
    assert verdict["glass"].endswith("not decided")
    # by the areas, glass, which does not flow, is named elastic (issue 76): no plastic model
    # improves on it by more than the quantile (a gain of 1.6 against 5.5 on the machine that
    # recorded it), while PS's hardening improves on it by 530
    assert cells[DECIDED]["PS"] == "contact hardening only"
    assert cells[DECIDED]["glass"].startswith("elastic: no flow detected")


def test_the_first_page_shows_fig_b13_then_each_fig_b12_after_the_table(small_run, report_html):
    """The page embeds the run's own PNGs of Fig. B.13 and each sphere's Fig. B.12, byte for
    byte, in that order, after the verdict table and before the pipeline's description."""
    page = first_page(report_html)
    images = re.findall(r'<img alt="([^"]*)" src="data:image/png;base64,([^"]+)"', page)
    expected = [
        ("Fig. B.13, every material", results(small_run, "study", "B13_amontons.png")),
        ("Fig. B.12, PS", results(small_run, "PS", "PS", "study", "B12_models.png")),
        ("Fig. B.12, glass", results(small_run, "glass", "glass", "study", "B12_models.png")),
    ]
    assert [alt for alt, _ in images] == [alt for alt, _ in expected]
    for (_, data), (_, path) in zip(images, expected, strict=True):
        assert base64.b64decode(data) == path.read_bytes()
    first_image = page.index("<img")
    assert page.index("</table>") < first_image and page.rindex("<img") < page.index("The pipeline")


def test_every_scan_states_an_estimate_inside_its_own_interval(small_run):
    """Each scan's best.json: the estimate lies inside its interval, and an interval open at
    an end is a bound with no estimate (issue 76); the grid's best is named as such, and the
    model table gives the same estimate and interval beside the grid's best value (its
    `value`)."""
    for sphere in ("PS", "glass"):
        models = pd.read_csv(results(small_run, sphere, "models.csv"))
        for scan in ("k", "p_y"):
            best = scan_best(small_run, sphere, scan)
            low, high = best["interval"]
            print(sphere, scan, best["estimate"], [low, high], "grid", best["grid_best"])
            row = models[models["source"] == f"scan {scan}, best value"].iloc[0]
            if low is None or high is None:
                assert best["estimate"] is None and pd.isna(row["estimate"])
            else:
                assert low <= best["estimate"] <= high
                assert row["estimate"] == best["estimate"]
            assert best["grid_best"] == best["best"] and best["grid_best"] in best["values"]
            assert row["value"] == best["grid_best"]
            for end, column in ((low, "estimate_low"), (high, "estimate_high")):
                assert (pd.isna(row[column]) and end is None) or row[column] == end
    assert "value_low" not in models and "value_high" not in models


def test_summary_names_the_file_of_every_number(small_run):
    """summary.md: the verdict table, then one line per headline number, each naming a file
    of the run that exists; PS's k is quoted as its estimate with its interval."""
    text = results(small_run, "summary.md").read_text(encoding="utf-8")
    assert "| exponent inside the measured 95% interval | contact hardening only |" in text
    headlines = [line for line in text.splitlines() if line.startswith("- **")]
    assert len(headlines) >= 15
    for line in headlines:
        paths = re.findall(r"`([^`]+)`", line.split("Source: ", 1)[1])
        assert paths and all((small_run / path).is_file() for path in paths), line
    best = scan_best(small_run, "PS", "k")
    low, high = best["interval"]
    (k_line,) = [line for line in headlines if line.startswith("- **PS: k of")]
    assert f"{significant(best['estimate'])} (95% interval {interval_text(low, high)}" in k_line
    assert "PS/PS/scans/k/best.json" in k_line
    # glass is named elastic: its scans are quoted as the bounds the verdict states
    glass_lines = [line for line in headlines if line.startswith("- **glass: ")]
    scans = [line for line in glass_lines if "/scans/" in line]
    assert scans and all("no flow detected, the answer is elastic" in line for line in scans)
