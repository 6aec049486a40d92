"""Figures of the workflow (matplotlib, non-interactive backend)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from amontons.images import atomic_path  # noqa: E402


def plot_normalised_load_area(
    table: pd.DataFrame, title: str, paths: list[str], reference_load_mn: float
) -> None:
    """Log–log A/A_ref versus F/F_ref per sphere, with the fitted power law and guides for
    Amontons (slope 1) and Hertz (slope 2/3). ``table`` has columns sphere, load_mN,
    area_norm, fit_exponent."""
    fig, ax = plt.subplots(figsize=(4.5, 4.0), constrained_layout=True)
    ratio = table["load_mN"] / reference_load_mn
    span = np.geomspace(ratio.min(), ratio.max(), 50)
    for sphere, rows in table.groupby("sphere", sort=False):
        x = rows["load_mN"] / reference_load_mn
        exponent = rows["fit_exponent"].iloc[0]
        (line,) = ax.plot(x, rows["area_norm"], "o", label=f"{sphere}: α = {exponent:.3f}")
        ax.plot(span, span**exponent, "-", color=line.get_color(), lw=1)
    ax.plot(span, span, "k--", lw=0.8, label="Amontons (A ∝ F)")
    ax.plot(span, span ** (2 / 3), "k:", lw=0.8, label="Hertz (A ∝ F^2/3)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"F / {reference_load_mn:g} mN")
    ax.set_ylabel(f"A / A({reference_load_mn:g} mN)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    for path in paths:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=150, format=str(path).rsplit(".", 1)[-1])
    plt.close(fig)
