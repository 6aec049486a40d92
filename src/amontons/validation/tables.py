"""The validation study's tables (docs/study.md §7): from every case's record
(amontons.validation.case), the coverage of the intervals per truth and scanned parameter,
the confusion of truths against verdicts, the cost, and the checks the study is held to.

Coverage is a fraction of n cases; its own 95 % interval (Clopper–Pearson, exact binomial)
says how well n cases pin it: ten cases that all hold the truth bound the coverage only
below by 69 %."""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd
from scipy.stats import binomtest

from amontons.study.summary import markdown_table
from amontons.validation.case import NOT_DECIDED
from amontons.validation.cases import (
    BELOW_MODEL_ERROR,
    CLEAR,
    PARAMETER_OF,
    TRUTH_MODELS,
)

VERDICTS = (*TRUTH_MODELS, NOT_DECIDED)
# the study's targets (docs/study.md §7)
MIN_COVERAGE = 0.90
MIN_NAMED_TRUE = 0.90
MAX_NAMED_WRONG = 0.05


def case_table(records: Sequence[dict]) -> pd.DataFrame:
    """One row per case and scan: the truth, the scan's estimate and interval, whether it
    holds the truth, the verdict and the cost."""
    rows = []
    for r in records:
        base = {k: r[k] for k in ("case", "truth", "model", "value", "signal", "seed", "ratio")}
        base |= {
            "verdict": r["verdict"],
            "truth_wall_s": r["truth_wall_s"],
            "study_wall_s": r["study_wall_s"],
            "study_solves": r["study_solves"],
        }
        for model, scan in r["scans"].items() or [(None, None)]:
            rows.append(
                base
                | {
                    "scan": PARAMETER_OF.get(model),
                    "estimate": None if scan is None else scan["estimate"],
                    "low": None if scan is None else scan["interval"][0],
                    "high": None if scan is None else scan["interval"][1],
                    "holds_truth": None if scan is None else scan["holds_truth"],
                }
            )
    return pd.DataFrame(rows)


def ratio_label(ratio: float) -> str:
    """A truth-to-study pixel ratio as the tables name it."""
    return f"{ratio:.2g}"


def coverage_table(cases: pd.DataFrame) -> pd.DataFrame:
    """Per truth, truth-to-study pixel ratio and scanned parameter whose intervals can hold
    the truth: cases, those that hold it, the fraction and its Clopper–Pearson 95 % interval."""
    checked = cases[cases["holds_truth"].notna()].copy()
    checked["ratio"] = checked["ratio"].map(ratio_label)
    rows = []
    for (truth, ratio, scan), group in checked.groupby(["truth", "ratio", "scan"], sort=False):
        n = len(group)
        held = int(group["holds_truth"].astype(bool).sum())
        ci = binomtest(held, n).proportion_ci(0.95, method="exact")
        rows.append(
            {
                "truth": truth,
                "model": group["model"].iloc[0],
                "value": group["value"].iloc[0],
                "ratio": ratio,
                "scan": scan,
                "cases": n,
                "held": held,
                "coverage": held / n,
                "coverage_low": ci.low,
                "coverage_high": ci.high,
            }
        )
    return pd.DataFrame(rows)


def confusion_table(records: Sequence[dict]) -> pd.DataFrame:
    """Truth (with its signal and pixel ratio) against verdict: counts per verdict."""
    rows = {}
    for r in records:
        key = (r["truth"], r["model"], r["signal"], ratio_label(r["ratio"]))
        row = rows.setdefault(key, dict.fromkeys(VERDICTS, 0))
        row[r["verdict"]] += 1
    return pd.DataFrame(
        [
            {
                "truth": t,
                "model": m,
                "signal": s,
                "ratio": q,
                **counts,
                "cases": sum(counts.values()),
            }
            for (t, m, s, q), counts in rows.items()
        ]
    )


def checks(coverage: pd.DataFrame, confusion: pd.DataFrame, study_ratio: str) -> list[dict]:
    """The study's targets on the cases at the study's truth ratio ``study_ratio``: coverage
    ≥ 90 % for each parameter, the true model named in ≥ 90 % of the clear truths' cases, a
    wrong model named in ≤ 5 % of any truth's, and no decision on a truth below the model
    error. Each with its measured value and whether it is met."""
    cov = coverage[coverage["ratio"] == study_ratio]
    conf = confusion[confusion["ratio"] == study_ratio]
    out = []
    for scan, group in cov.groupby("scan", sort=True):
        fraction = group["held"].sum() / group["cases"].sum()
        out.append(
            _check(
                f"coverage of the {scan} intervals",
                fraction,
                fraction >= MIN_COVERAGE,
                f"≥ {MIN_COVERAGE:.0%}",
            )
        )
    clear = conf[conf["signal"] == CLEAR]
    named_true = sum(row[row["model"]] for _, row in clear.iterrows()) / max(
        clear["cases"].sum(), 1
    )
    out.append(
        _check(
            "clear truths: the true model named",
            named_true,
            named_true >= MIN_NAMED_TRUE,
            f"≥ {MIN_NAMED_TRUE:.0%}",
        )
    )
    for _, row in conf.iterrows():
        wrong = sum(row[v] for v in VERDICTS if v not in (row["model"], NOT_DECIDED)) / row["cases"]
        out.append(
            _check(
                f"{row['truth']}: a wrong model named",
                wrong,
                wrong <= MAX_NAMED_WRONG,
                f"≤ {MAX_NAMED_WRONG:.0%}",
            )
        )
    for _, row in conf[conf["signal"] == BELOW_MODEL_ERROR].iterrows():
        undecided = row[NOT_DECIDED] / row["cases"]
        out.append(
            _check(
                f"{row['truth']} ({row['signal']}): not decided",
                undecided,
                undecided >= MIN_NAMED_TRUE,
                f"≥ {MIN_NAMED_TRUE:.0%}",
            )
        )
    return out


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


def summary_markdown(
    coverage: pd.DataFrame, confusion: pd.DataFrame, checked: list[dict], cost: pd.DataFrame
) -> str:
    """validation.md: the checks first, then coverage, confusion and cost."""
    met = all(c["met"] for c in checked)
    return (
        "\n\n".join(
            [
                "# Validation: the study's intervals and verdicts against truths of every model",
                f"All targets met: **{'yes' if met else 'no'}** (docs/study.md §7 says how the "
                "truths were made and what the intervals count).",
                _markdown(pd.DataFrame(checked)),
                "## Coverage of the 95 % intervals (Clopper–Pearson 95 % interval of the fraction)",
                _markdown(coverage),
                "## Verdicts (truth against verdict)",
                _markdown(confusion),
                "## Cost (s, one thread)",
                _markdown(cost),
            ]
        )
        + "\n"
    )
