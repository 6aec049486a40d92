"""The study's verdict from the model tables, and the pages that show it (docs/study.md §6)."""

import base64
import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from docutils.core import publish_parts  # noqa: E402

from amontons.study.summary import (  # noqa: E402
    ReportFigure,
    SummaryError,
    decided_text,
    display_rows,
    markdown_table,
    matching_models,
    report_page,
    scan_headline,
    summary_markdown,
    verdict_rows,
    verdict_text,
)

MEASURED = {"measured_exponent": 0.82, "measured_ci_low": 0.80, "measured_ci_high": 0.84}


def _row(model, source, exponent, ratio=1.0, parameter=None, **scan):
    return {
        "sphere": "PS",
        "model": model,
        "source": source,
        "parameter": parameter,
        "value": scan.get("value"),
        "estimate": scan.get("estimate"),
        "estimate_low": scan.get("low"),
        "estimate_high": scan.get("high"),
        "exponent": exponent,
        **MEASURED,
        "exponent_difference": exponent - MEASURED["measured_exponent"],
        "area_ratio_largest": ratio,
        "chi2_best": scan.get("chi2_best"),
        "chi2_elastic_end": scan.get("chi2_elastic_end"),
        "chi2_elastic": scan.get("chi2_elastic"),
        "chi2_rise": 10.128 if "chi2_best" in scan else None,
        "n_loads": 5 if "chi2_best" in scan else None,
    }


def models_table() -> pd.DataFrame:
    """A models.csv of one sphere as tabulate_models writes it: four scenes, two scans."""
    return pd.DataFrame(
        [
            _row("elastic", "scene elastic", 0.86, 0.75),
            _row("penetration_hardness", "scene penetration_hardness", 0.90, 0.96, "p_y_mpa"),
            _row("hardening", "scene hardening", 0.818, 1.01, "k_mpa_per_nm"),
            _row("greenwood_tripp", "scene greenwood_tripp", 0.92, float("nan")),
            _row(
                "penetration_hardness",
                "scan p_y, best value",
                0.91,
                1.04,
                "p_y_mpa",
                value=178.9,
                estimate=178.9,
                low=178.9,
                high=194.4,
                chi2_best=40.0,
                chi2_elastic_end=60.0,
                chi2_elastic=48.0,
            ),
            _row(
                "hardening",
                "scan k, best value",
                0.813,
                1.03,
                "k_mpa_per_nm",
                value=4.472,
                estimate=float("nan"),  # a bound has no estimate (best.json's null)
                low=4.61,
                high=float("nan"),
                chi2_best=2.0,
                chi2_elastic_end=50.0,
                chi2_elastic=48.5,
            ),
        ]
    )


def test_a_plastic_model_is_judged_at_its_scan_and_the_others_at_their_scene():
    (row,) = verdict_rows(models_table(), "PS", "results/small/PS/models.csv")
    assert row["hardening_source"] == "scan k, best value"
    assert row["hardening_exponent"] == 0.813
    assert row["penetration_hardness_source"] == "scan p_y, best value"
    assert row["elastic_source"] == "scene elastic"
    assert row["greenwood_tripp_area_ratio"] is None  # no rendering, no area ratio
    assert (row["k_estimate"], row["k_low"], row["k_high"], row["k_grid_best"]) == (
        None,
        4.61,
        None,  # open at the scan's end
        4.472,
    )
    # only hardening's 0.813 lies inside the measured 0.80-0.84
    assert row["matching"] == "hardening"
    assert verdict_text(row) == "contact hardening only"


def test_models_inside_the_measured_interval_are_all_named_and_none_singled_out():
    row = {**MEASURED, "hardening_exponent": 0.80, "elastic_exponent": 0.84}
    row["penetration_hardness_exponent"] = 0.7999
    assert matching_models(row) == ["hardening", "elastic"]  # both ends included
    assert verdict_text({"matching": "hardening;elastic"}) == (
        "contact hardening, elastic: not decided"
    )
    assert verdict_text({"matching": ""}) == "no model"
    # the verdict table read back: pandas reads the empty cell as NaN
    read_back = pd.read_csv(io.StringIO("sphere,matching\nPS,\n")).iloc[0].to_dict()
    assert verdict_text(read_back) == "no model"


def test_a_scan_of_a_sphere_named_elastic_is_quoted_as_its_bound():
    """Where no flow is detected, a closed scan interval is no estimate: the headline states
    its lower end as the verdict does, with no estimate and no upper end."""
    best = {
        "parameter": "p_y_mpa",
        "estimate": 134.0,
        "interval": [117.0, 150.0],
        "grid_best": 130.0,
        "at_scan_edge": False,
        "confidence": 0.95,
    }
    closed = scan_headline("glass", best, "glass/scans/p_y/best.json")
    assert closed.value.startswith("134 (95% interval 117–150")
    bound = scan_headline("glass", best, "glass/scans/p_y/best.json", elastic=True)
    assert bound.value == (
        "≥ 117 (95% bound; no flow detected, the answer is elastic; grid's best 130)"
    )
    assert "134" not in bound.value and "150" not in bound.value


def test_a_best_json_without_the_estimate_is_named():
    with pytest.raises(SummaryError, match=r"scans/k/best\.json: no 'estimate'.*--forcerun"):
        scan_headline("PS", {"best": 4.472, "interval": [4.6, 6.0]}, "PS/scans/k/best.json")


def test_a_table_that_is_not_a_model_table_is_named():
    with pytest.raises(SummaryError, match=r"results/x/PS/models\.csv: no column .*'estimate'"):
        verdict_rows(
            pd.DataFrame({"sphere": ["PS"], "model": ["elastic"]}), "PS", "results/x/PS/models.csv"
        )


def test_the_first_page_is_valid_restructured_text_with_the_table_then_the_figures(tmp_path):
    """docutils renders the page without a system message (an error would show in the
    report as a red box): the verdict table with one column per sphere, then each figure's
    PNG embedded byte for byte, in the order given."""
    verdict = pd.DataFrame(verdict_rows(models_table(), "PS", "models.csv"))
    figures = []
    for name in ("b13", "b12"):
        fig, ax = plt.subplots(figsize=(2, 2))
        ax.plot([1, 2], [1, 2])
        fig.savefig(tmp_path / f"{name}.png")
        plt.close(fig)
        figures.append(ReportFigure(str(tmp_path / f"{name}.png"), f"Fig. {name}"))
    page = report_page(verdict, figures, 0.95, "synthetic data", ["models.csv"], "verdict.csv")
    html = publish_parts(page, writer="html", settings_overrides={"report_level": 1})["html_body"]
    assert "System Message" not in html
    assert html.index("<table") < html.index('alt="Fig. b13"') < html.index('alt="Fig. b12"')
    assert "<caption>Verdict per sphere</caption>" in html
    for figure in figures:
        start = html.index(f'alt="{figure.caption}" src="data:image/png;base64,')
        data = html[start:].split("base64,", 1)[1].split('"', 1)[0]
        assert base64.b64decode(data) == Path(figure.png).read_bytes()


def test_the_reader_table_states_estimate_interval_and_grid_best():
    verdict = pd.DataFrame(verdict_rows(models_table(), "PS", "models.csv"))
    lines = display_rows(verdict, 0.95)
    by_name = {line[0]: line[1:] for line in lines}
    assert by_name["sphere (material)"] == ["PS"]
    # an interval open at the scan's end is stated as the bound it is (issue 65)
    assert by_name["k (estimate, MPa/nm; 95% interval)"] == ["≥ 4.61 (bound); grid's best 4.47"]
    assert by_name["contact hardening at the grid's best k"] == ["0.813 (−0.007), area ×1.03"]
    assert by_name["Greenwood–Tripp"] == ["0.920 (+0.100)"]
    table = markdown_table(lines)
    assert table.splitlines()[1] == "|---|---|" and len(table.splitlines()) == len(lines) + 1


def test_the_first_page_and_the_summary_say_what_the_data_did_not_allow():
    """A sphere's missing file leaves no silent gap: its reason stands on the report's first
    page, as valid reStructuredText, and in summary.md."""
    verdict = pd.DataFrame(verdict_rows(models_table(), "PS", "models.csv"))
    reason = "sphere PS-2 (PS): no rheometer/ folder in lab/PS-2: the friction will not be made"
    page = report_page(verdict, [], 0.95, "measured data", ["models.csv"], "v.csv", [reason])
    html = publish_parts(page, writer="html", settings_overrides={"report_level": 1})["html_body"]
    assert "System Message" not in html and "no rheometer/ folder in lab/PS-2" in html
    assert "What the data did not allow" not in report_page(
        verdict, [], 0.95, "measured data", ["models.csv"], "v.csv"
    )
    text = summary_markdown("small", "measured data", None, None, [], [reason])
    assert text.endswith(f"## What the data did not allow\n\n- {reason}\n")


def test_a_failed_sphere_is_named_on_the_first_page_and_in_the_summary():
    """A sphere held out by a failed job is marked failed, with its step and error, before
    what the data did not allow: valid reStructuredText, and its own section of summary.md."""
    verdict = pd.DataFrame(verdict_rows(models_table(), "PS", "models.csv"))
    failed = (
        "sphere PS-2 (PS): failed in an earlier run: measure_contact_area: RawDataError: "
        "lab/PS-2/fluorescence/100.tif: not a readable TIFF [logs/x.log]"
    )
    reason = "sphere PS-3 (PS): no rheometer/ folder in lab/PS-3: the friction will not be made"
    page = report_page(verdict, [], 0.95, "measured data", ["m.csv"], "v.csv", [reason], [failed])
    html = publish_parts(page, writer="html", settings_overrides={"report_level": 1})["html_body"]
    assert "System Message" not in html
    assert html.index("Failed: held out of every table") < html.index("not a readable TIFF")
    assert html.index("not a readable TIFF") < html.index("What the data did not allow")
    text = summary_markdown("small", "measured data", None, None, [], [reason], [failed])
    assert f"## Failed: held out of every table and figure\n\n- {failed}\n\n## What" in text
    assert "Failed" not in summary_markdown("small", "measured data", None, None, [], [reason])


def test_the_verdict_table_states_the_decision_by_the_areas():
    """The sphere's k scan fits (χ² 2), its p_Y scan and both elastic ends do not (38 and 48
    above it, beyond F(1, 3)'s 10.1): contact hardening is named, beside the exponent's
    verdict."""
    verdict = pd.DataFrame(verdict_rows(models_table(), "PS", "models.csv"))
    assert verdict.loc[0, "decided"] == "hardening"
    assert verdict.loc[0, "k_chi2_best"] == 2.0 and verdict.loc[0, "p_y_chi2_elastic_end"] == 60
    lines = {line[0]: line[1:] for line in display_rows(verdict, 0.95)}
    assert lines["decided by the areas at every load (95%, scatter and model error)"] == [
        "contact hardening only"
    ]


def test_an_elastic_answer_states_each_plastic_parameter_as_its_bound():
    """The elastic model, judged with its own error, lies within the quantile of both scans'
    best (χ² 3 against 2 and 40 → no flow detected): the verdict names elastic, and each
    scanned parameter is stated as the one-sided bound its interval's lower end sets, with no
    estimate and no upper end, even where the scan's own interval is closed (p_Y's
    178.9-194.4): the elastic limit, p_Y → ∞, is kept."""
    table = models_table()
    table["chi2_elastic"] = table["chi2_elastic"].where(table["chi2_elastic"].isna(), 3.0)
    (row,) = verdict_rows(table, "PS", "models.csv")
    assert row["decided"] == "elastic"
    assert "no flow detected" in row["decided_why"]
    assert (row["p_y_estimate"], row["p_y_low"], row["p_y_high"]) == (None, 178.9, None)
    assert (row["k_estimate"], row["k_low"], row["k_high"]) == (None, 4.61, None)
    assert decided_text(row) == "elastic: no flow detected, p_Y ≥ 179 MPa, k ≥ 4.61 MPa/nm"
    lines = {line[0]: line[1:] for line in display_rows(pd.DataFrame([row]), 0.95)}
    assert lines["p_Y (estimate, MPa; 95% interval)"] == ["≥ 179 (bound); grid's best 179"]
