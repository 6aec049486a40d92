"""The validation study's tables (docs/study.md §7): from every case's record
(amontons.validation.case), the coverage of the intervals per truth and scanned parameter,
the confusion of truths against verdicts, the cost, and the checks the study is held to.

Coverage is a fraction of n cases; its own 95 % interval (Clopper–Pearson, exact binomial)
says how well n cases pin it: ten cases that all hold the truth bound the coverage only
below by 69 %. It is counted at two levels (the scans' confidence and the inner one), each
checked against its nominal within two binomial standard errors, so that intervals too wide
show as clearly as too narrow ones.

Elastic is a verdict: where no plastic model improves on the elastic model, the study names
elastic with each plastic parameter's one-sided bound (amontons.study.decision). On a truth
whose plasticity lies below the model error that is a right answer where the bound holds the
truth's value, and a wrong one where it excludes it."""

from __future__ import annotations

import math
from collections.abc import Sequence

import pandas as pd
from scipy.stats import binomtest

from amontons import models
from amontons.study.summary import markdown_table
from amontons.validation.case import NOT_DECIDED, SMALL_SPHERE
from amontons.validation.cases import (
    BELOW_MODEL_ERROR,
    CLEAR,
    NO_PLASTICITY,
    PARAMETER_OF,
    TRUTH_MODELS,
)

VERDICTS = (*TRUTH_MODELS, NOT_DECIDED)
ELASTIC = models.ELASTIC.name
# the confusion table's count of elastic verdicts on a plastic truth whose bound excludes it
BOUND_MISSES = "elastic_bound_misses"
# the study's targets (docs/study.md §7)
MIN_COVERAGE = 0.90
MIN_NAMED_TRUE = 0.90
MAX_NAMED_WRONG = 0.05


def case_table(records: Sequence[dict]) -> pd.DataFrame:
    """One row per case and scan: the sphere (a record before the sheet's spheres were
    validated is on the small one), the truth, the scan's estimate and interval, whether it
    holds the truth, the verdict and the cost."""
    rows = []
    for r in records:
        base = {"case": r["case"], "sphere": r.get("sphere", SMALL_SPHERE)}
        base |= {k: r[k] for k in ("truth", "model", "value", "signal", "seed", "ratio")}
        base |= {"solver": r["truth_solver"], "comparison": r["comparison"]}
        base |= {
            "verdict": r["verdict"],
            "truth_wall_s": r["truth_wall_s"],
            "study_wall_s": r["study_wall_s"],
            "study_solves": r["study_solves"],
        }
        for model, scan in r["scans"].items() or [(None, None)]:
            rows.append(base | {"scan": PARAMETER_OF.get(model), **_scan_columns(scan)})
    return pd.DataFrame(rows)


def _scan_columns(scan: dict | None) -> dict:
    """A case's scan as case-table columns: its estimate, its interval at both levels and
    whether each holds the truth (empty where the case has no scan)."""
    if scan is None:
        return dict.fromkeys(
            ("estimate", "low", "high", "holds_truth", "inner_low", "inner_high", "inner_holds")
        )
    inner = scan.get("inner_interval") or [None, None]
    return {
        "estimate": scan["estimate"],
        "low": scan["interval"][0],
        "high": scan["interval"][1],
        "holds_truth": scan["holds_truth"],
        "inner_confidence": scan.get("inner_confidence"),
        "inner_low": inner[0],
        "inner_high": inner[1],
        "inner_holds": scan.get("inner_holds_truth"),
    }


def ratio_label(ratio: float) -> str:
    """A truth-to-study pixel ratio as the tables name it."""
    return f"{ratio:.2g}"


def coverage_table(cases: pd.DataFrame, confidence: float) -> pd.DataFrame:
    """Per truth, truth-to-study pixel ratio, scanned parameter whose intervals can hold the
    truth, and level (``confidence``, the scans', and the inner one where the cases have it):
    cases, those that hold it, the fraction and its Clopper–Pearson 95 % interval."""
    rows = []
    levels = [("holds_truth", confidence)]
    if "inner_holds" in cases and cases["inner_holds"].notna().any():
        levels.append(("inner_holds", float(cases["inner_confidence"].dropna().iloc[0])))
    for column, level in levels:
        checked = cases[cases[column].notna()].copy()
        checked["ratio"] = checked["ratio"].map(ratio_label)
        keys = ["truth", "ratio", "scan"]
        for (truth, ratio, scan), group in checked.groupby(keys, sort=False):
            n = len(group)
            held = int(group[column].astype(bool).sum())
            ci = binomtest(held, n).proportion_ci(0.95, method="exact")
            rows.append(
                {
                    "truth": truth,
                    "model": group["model"].iloc[0],
                    "value": group["value"].iloc[0],
                    "solver": group["solver"].iloc[0],
                    "comparison": bool(group["comparison"].iloc[0]),
                    "ratio": ratio,
                    "scan": scan,
                    "level": level,
                    "cases": n,
                    "held": held,
                    "coverage": held / n,
                    "coverage_low": ci.low,
                    "coverage_high": ci.high,
                }
            )
    return pd.DataFrame(rows)


def elastic_bound_misses(record: dict) -> bool:
    """Whether a case named elastic on a plastic truth with a bound that excludes the truth's
    value (the lower end of its own model's interval above it)."""
    if record["verdict"] != ELASTIC or record["model"] == ELASTIC:
        return False
    low = record["scans"][record["model"]]["interval"][0]
    return low is not None and low > record["value"]


def confusion_table(records: Sequence[dict]) -> pd.DataFrame:
    """Truth (with its signal and pixel ratio) against verdict: counts per verdict, and the
    elastic verdicts on a plastic truth whose bound excludes it (:data:`BOUND_MISSES`)."""
    rows = {}
    for r in records:
        key = (r["truth"], r["model"], r["signal"], r["truth_solver"], ratio_label(r["ratio"]))
        row = rows.setdefault(
            key, {"comparison": r["comparison"], **dict.fromkeys((*VERDICTS, BOUND_MISSES), 0)}
        )
        row[r["verdict"]] += 1
        row[BOUND_MISSES] += elastic_bound_misses(r)
    return pd.DataFrame(
        [
            {
                "truth": t,
                "model": m,
                "signal": s,
                "solver": solver,
                "ratio": q,
                **counts,
                "cases": sum(counts[v] for v in VERDICTS),
            }
            for (t, m, s, solver, q), counts in rows.items()
        ]
    )


def checks(coverage: pd.DataFrame, confusion: pd.DataFrame, confidence: float) -> list[dict]:
    """The study's targets on the run truths' cases (each at its own ratio; the comparison
    ratios' cases are reported, not held to them): at the
    scans' level ``confidence``, coverage ≥ 90 % for each parameter; at each level, the
    plastic truths' coverage within two binomial standard errors of its nominal (an elastic
    truth lies at the scan's end, where an interval holds it 1 − (1 − level)/2 of the time,
    not the level's); the true model named in ≥ 90 % of the clear
    truths' cases and of the elastic truths'; a wrong model named in ≤ 5 % of any truth's
    (elastic on a truth below the model error counts as wrong only where its bound excludes
    the truth). Each with its measured value and whether it is met."""
    cov = coverage[~coverage["comparison"].astype(bool)]
    conf = confusion[~confusion["comparison"].astype(bool)]
    out = []
    for (level, scan), group in cov.groupby(["level", "scan"], sort=True):
        out += _coverage_checks(scan, level, group, level == confidence)
    for what, signal in (
        ("clear truths: the true model named", CLEAR),
        ("elastic truths: elastic named", NO_PLASTICITY),
    ):
        if (conf["signal"] == signal).any():
            out.append(_named_check(what, conf[conf["signal"] == signal]))
    for _, row in conf.iterrows():
        wrong = _wrong(row) / row["cases"]
        out.append(
            _check(
                f"{row['truth']}: a wrong model named",
                wrong,
                wrong <= MAX_NAMED_WRONG,
                f"≤ {MAX_NAMED_WRONG:.0%}",
            )
        )
    return out


def _coverage_checks(scan: str, level: float, group: pd.DataFrame, outer: bool) -> list[dict]:
    """A parameter's coverage at one level: the plastic truths' within two binomial standard
    errors of the nominal, and at the scans' own level (``outer``) every truth's at least
    :data:`MIN_COVERAGE`."""
    plastic = group[group["model"] != ELASTIC]
    n = int(plastic["cases"].sum())
    out = []
    if n:
        fraction = plastic["held"].sum() / n
        se = math.sqrt(level * (1 - level) / n)
        out.append(
            _check(
                f"coverage of the {level:.0%} {scan} intervals of plastic truths, within 2 "
                "binomial se of nominal",
                fraction,
                abs(fraction - level) <= 2 * se,
                f"{level - 2 * se:.0%}–{min(level + 2 * se, 1):.0%} ({n} cases)",
            )
        )
    if outer:
        fraction = group["held"].sum() / group["cases"].sum()
        out.append(
            _check(
                f"coverage of the {scan} intervals",
                fraction,
                fraction >= MIN_COVERAGE,
                f"≥ {MIN_COVERAGE:.0%}",
            )
        )
    return out


def _named_check(what: str, rows: pd.DataFrame) -> dict:
    """The fraction of ``rows``' cases whose verdict named the truth's model (≥
    :data:`MIN_NAMED_TRUE`)."""
    named = sum(row[row["model"]] for _, row in rows.iterrows()) / rows["cases"].sum()
    return _check(what, named, named >= MIN_NAMED_TRUE, f"≥ {MIN_NAMED_TRUE:.0%}")


def _wrong(row) -> int:
    """A confusion row's cases that named a wrong model: another plastic model, or elastic on
    a plastic truth (on one below the model error, only where the bound excludes it)."""
    others = [v for v in VERDICTS if v not in (row["model"], NOT_DECIDED, ELASTIC)]
    wrong = sum(row[v] for v in others)
    if row["model"] == ELASTIC:
        return wrong
    if row["signal"] == BELOW_MODEL_ERROR:
        return wrong + row[BOUND_MISSES]
    return wrong + row[ELASTIC]


def _check(what: str, value: float, met: bool, target: str) -> dict:
    return {"check": what, "value": float(value), "target": target, "met": bool(met)}


def cost_table(cases: pd.DataFrame) -> pd.DataFrame:
    """Per truth and pixel ratio: cases, the truth's and the study's median and total wall
    time (s, one thread) and the study's median number of load-series solves."""
    per_case = cases.drop_duplicates("case").copy()
    per_case["ratio"] = per_case["ratio"].map(ratio_label)
    return (
        per_case.groupby(["truth", "ratio"], sort=False)
        .agg(
            cases=("case", "size"),
            truth_median_s=("truth_wall_s", "median"),
            truth_total_s=("truth_wall_s", "sum"),
            study_median_s=("study_wall_s", "median"),
            study_total_s=("study_wall_s", "sum"),
            study_solves_median=("study_solves", "median"),
        )
        .reset_index()
    )


def _markdown(table: pd.DataFrame) -> str:
    """A table as a Markdown (pipe) table (amontons.study.summary.markdown_table), numbers to
    3 significant digits."""

    def cell(v) -> str:
        return f"{v:.3g}" if isinstance(v, float) else str(v)

    lines = [list(table.columns)] + [
        [cell(v) for v in row] for row in table.itertuples(index=False)
    ]
    return markdown_table(lines).rstrip("\n")


def _left_out_section(left_out: Sequence[str]) -> list[str]:
    """validation.md's list of the spheres the config named but the run left out (none:
    no section)."""
    if not left_out:
        return []
    return ["Left out:\n\n" + "\n".join(f"- {line}" for line in left_out)]


def summary_markdown(
    coverage: pd.DataFrame,
    confusion: pd.DataFrame,
    checked: list[dict],
    cost: pd.DataFrame,
    left_out: Sequence[str] = (),
) -> str:
    """validation.md: the checks first, then the spheres the config named but the run left out
    (``left_out``: a line each, why), coverage, confusion and cost."""
    met = all(c["met"] for c in checked)
    return (
        "\n\n".join(
            [
                "# Validation: the study's intervals and verdicts against truths of every model",
                f"All targets met: **{'yes' if met else 'no'}** (docs/study.md §7 says how the "
                "truths were made and what the intervals count).",
                *_left_out_section(left_out),
                _markdown(pd.DataFrame(checked)),
                "## Coverage of the intervals at each level (Clopper–Pearson 95 % interval of the "
                "fraction)",
                _markdown(coverage),
                "## Verdicts (truth against verdict)",
                _markdown(confusion),
                "## Cost (s, one thread)",
                _markdown(cost),
            ]
        )
        + "\n"
    )
