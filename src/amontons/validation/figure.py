"""The validation study's figure (docs/study.md §7): every case's 95 % interval divided by
its truth, one panel per truth with a parameter, one column per seed, the truth solved at the
study's pixel ratio (solid) and at the default run's (pale, offset); an interval that holds
the truth crosses 1 (blue), one that misses it does not (red). An open end runs to the
panel's edge. The elastic truth has no value to divide by: its intervals hold it where they
are open at the scan's elastic end (the tables count them)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from amontons.study.plots import save_figure  # noqa: E402

# how far past the panel's data an open end is drawn (×)
OPEN_REACH = 1.5
HELD, MISSED = "tab:blue", "tab:red"


def _limits(rows: pd.DataFrame) -> tuple[float, float]:
    ends = pd.concat([rows["low"], rows["high"], rows["estimate"]]).dropna().astype(float)
    ends = ends / rows["value"].iloc[0]
    return min(float(ends.min()), 1.0) / OPEN_REACH, max(float(ends.max()), 1.0) * OPEN_REACH


def _held_text(rows: pd.DataFrame, study_ratio: float) -> str:
    parts = []
    for ratio, group in rows.groupby("ratio", sort=False):
        held = int(group["holds_truth"].astype(bool).sum())
        parts.append(f"{held}/{len(group)} at ×{ratio:g}")
    return ", ".join(parts)


def _draw_case(ax, x: float, row, value: float, limits, pale: bool) -> None:
    bottom, top = limits
    low = bottom if pd.isna(row["low"]) else row["low"] / value
    high = top if pd.isna(row["high"]) else row["high"] / value
    colour = HELD if row["holds_truth"] else MISSED
    alpha = 0.4 if pale else 1.0
    ax.plot([x, x], [low, high], "-", color=colour, lw=2, alpha=alpha)
    if not pd.isna(row["estimate"]):  # a bound has no estimate
        ax.plot(x, row["estimate"] / value, "o", color=colour, ms=3, alpha=alpha)


def plot_intervals(cases: pd.DataFrame, study_ratio: float, paths: list[str]) -> None:
    """Per truth with a value: each case's interval of its own model's scan over the truth,
        by seed, at ``study_ratio`` (solid) and the comparison's ratios (pale, offset to the right
    in increasing order)."""
    own = cases[cases["holds_truth"].notna() & cases["value"].notna()]
    truths = list(dict.fromkeys(own["truth"]))
    n = max(len(truths), 1)
    fig, axes = plt.subplots(1, n, figsize=(3.2 * n, 3.6), constrained_layout=True, squeeze=False)
    for ax, truth in zip(axes[0], truths, strict=False):
        rows = own[own["truth"] == truth]
        value = rows["value"].iloc[0]
        limits = _limits(rows)
        others = sorted(r for r in rows["ratio"].unique() if not np.isclose(r, study_ratio))
        for _, row in rows.iterrows():
            pale = row["ratio"] in others
            offset = 0.25 * (others.index(row["ratio"]) + 1) if pale else 0.0
            _draw_case(ax, row["seed"] + offset, row, value, limits, pale)
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_yscale("log")
        ax.set_ylim(*limits)
        ax.set_xticks(sorted(rows["seed"].unique()))
        ax.set_title(
            f"{truth}: {rows['scan'].iloc[0]} = {value:g}\nheld {_held_text(rows, study_ratio)}",
            fontsize=8,
        )
    axes[0][0].set_ylabel("95 % interval / truth")
    fig.supxlabel("seed", fontsize=8)
    handles = [
        Line2D([], [], color=HELD, lw=2, label=f"holds the truth (truth ×{study_ratio:g} finer)"),
        Line2D([], [], color=HELD, lw=2, alpha=0.4, label="at the comparison's ratios, right"),
        Line2D([], [], color=MISSED, lw=2, label="misses it"),
    ]
    axes[0][-1].legend(handles=handles, fontsize=6, loc="lower right")
    save_figure(fig, paths)
