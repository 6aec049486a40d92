"""The accuracy study's figure: each error measure against wall time, log-log, one panel per
measure, one marker per problem, the Pareto front of each problem drawn as a step line."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from amontons.accuracy.front import ERRORS  # noqa: E402
from amontons.accuracy.settings import REFERENCE  # noqa: E402
from amontons.study.plots import save_figure  # noqa: E402

MARKERS = ("o", "s", "^", "D", "v")
# an error of exactly 0 (a setting equal to the reference in that measure) is drawn here
FLOOR = 1e-7


def plot_error_versus_time(table: pd.DataFrame, title: str, paths: list[str]) -> None:
    """Log-log error against solve wall time (s) for each error measure of ``table`` (the
    accuracy table: columns problem, setting, wall_time_s, <measure>_error, <measure>_front)."""
    measures = list(ERRORS)
    fig, axes = plt.subplots(
        1, len(measures), figsize=(3.2 * len(measures), 3.4), constrained_layout=True
    )
    rows = table[table["setting"] != REFERENCE]
    for ax, measure in zip(axes, measures, strict=True):
        for (problem, group), marker in zip(
            rows.groupby("problem", sort=False), MARKERS, strict=False
        ):
            error = np.maximum(group[f"{measure}_error"], FLOOR)
            (points,) = ax.plot(group["wall_time_s"], error, marker, ms=4, alpha=0.6, label=problem)
            front = group[group[f"{measure}_front"]].sort_values("wall_time_s")
            ax.step(
                front["wall_time_s"],
                np.maximum(front[f"{measure}_error"], FLOOR),
                where="post",
                color=points.get_color(),
                lw=1.2,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("solve wall time, s (1 thread)")
        ax.set_ylabel(f"{measure.replace('_', ' ')} error")
        ax.set_title(ERRORS[measure], fontsize=7, wrap=True)
    axes[0].legend(fontsize=7)
    fig.suptitle(title, fontsize=9)
    save_figure(fig, paths)
