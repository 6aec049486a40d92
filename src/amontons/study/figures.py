"""Figures of the study (docs/study.md): the appendix's Figs. B.8-B.13. Each function draws
data it is given (the scripts write the same data to a CSV beside the figure)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from amontons.io.fields import read_load_series_settings  # noqa: E402
from amontons.io.files import write_table  # noqa: E402
from amontons.models import CONTACT_HARDENING  # noqa: E402
from amontons.simulate.grid import block_mean  # noqa: E402
from amontons.study.plots import (  # noqa: E402
    FIGURE_DPI,
    amontons_axes,
    display_factor,
    plot_unmeasured,
    save_figure,
)

# The figures' table column of the k scan's grid's best k (config units).
BEST_K = f"best_{CONTACT_HARDENING.parameter.key}"


@dataclass(frozen=True)
class MapPanel:
    """One image panel: the image, its title, and an optional outline (bool mask) and marker
    ((row, col) px) drawn on it; ``framed`` draws the appendix's blue rectangle around it;
    ``pixel_um`` its own pixel where panels differ (else the figure's)."""

    image: np.ndarray
    title: str
    outline: np.ndarray | None = None
    marker: tuple[float, float] | None = None
    framed: bool = False
    pixel_um: float | None = None


def crop_box(mask: np.ndarray, margin: float = 0.35) -> tuple[slice, slice]:
    """A square around ``mask`` (a measured contact), ``margin`` of its size wider on each
    side, so that panels show the contact and not the empty field around it."""
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        return slice(None), slice(None)
    centre = ((rows.min() + rows.max()) / 2, (cols.min() + cols.max()) / 2)
    half = (1 + 2 * margin) * max(rows.max() - rows.min(), cols.max() - cols.min()) / 2 + 2
    r0, c0 = (int(max(0, c - half)) for c in centre)
    return slice(r0, int(centre[0] + half) + 1), slice(c0, int(centre[1] + half) + 1)


def _plain_log_ticks(ax) -> None:
    """Log axes labelled in plain numbers, minor ticks unlabelled (they overlap)."""
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        axis.set_minor_formatter(matplotlib.ticker.NullFormatter())


# The widths of the map panels (in): a map is drawn with no more pixels than its panel shows
# at the figures' resolution (Figs. B.8, B.11 and B.9).
_GRID_PANEL_IN = 1.6
_HEIGHT_PANEL_IN = 3.2
_GRID_PANEL_PX = round(_GRID_PANEL_IN * FIGURE_DPI)
_HEIGHT_PANEL_PX = round(_HEIGHT_PANEL_IN * FIGURE_DPI)


def at_display_resolution(panel: MapPanel, pixel_um: float, panel_px: int) -> MapPanel:
    """``panel`` with its image (and outline) block-averaged to at most ``panel_px`` pixels a
    side, its pixel (µm) and marker moved to the coarser grid; unchanged where it is no wider.
    A block k covers pixels f·k … f·k + f - 1, so a position p lands at (p - (f - 1)/2)/f."""
    factor = display_factor(panel.image.shape, panel_px)
    if factor == 1:
        return panel
    marker = panel.marker
    if marker is not None:
        marker = tuple((m - (factor - 1) / 2) / factor for m in marker)
    return replace(
        panel,
        image=block_mean(panel.image, factor),
        # the outline's fraction per block, drawn at 0.5: where most of the block is inside
        outline=None if panel.outline is None else block_mean(panel.outline, factor),
        marker=marker,
        pixel_um=(panel.pixel_um or pixel_um) * factor,
    )


def _extent(shape, pixel_um: float) -> list[float]:
    rows, cols = shape
    return [-cols * pixel_um / 2, cols * pixel_um / 2, rows * pixel_um / 2, -rows * pixel_um / 2]


def _draw(ax, panel: MapPanel, pixel_um: float, cmap: str, limits=None) -> None:
    pixel_um = panel.pixel_um or pixel_um
    extent = _extent(panel.image.shape, pixel_um)
    vmin, vmax = limits if limits is not None else (None, None)
    ax.imshow(panel.image, cmap=cmap, extent=extent, vmin=vmin, vmax=vmax)
    if panel.outline is not None and panel.outline.any():
        ax.contour(
            panel.outline.astype(float),
            [0.5],
            colors="w",
            linewidths=0.6,
            extent=extent,
            origin="upper",
        )
    if panel.marker is not None:
        rows, cols = panel.image.shape
        y = (panel.marker[0] - (rows - 1) / 2) * pixel_um
        x = (panel.marker[1] - (cols - 1) / 2) * pixel_um
        ax.plot([x], [y], "+", color="r", ms=8, mew=1.5)
    if panel.framed:
        for spine in ax.spines.values():
            spine.set_edgecolor("tab:blue")
            spine.set_linewidth(3)
    ax.set_title(panel.title, fontsize=7)
    ax.set_xticks([])
    ax.set_yticks([])


def _drawn_at(panel_px: int) -> str:
    """The caption's note of the resolution maps are drawn at."""
    return f"maps wider than {panel_px} px drawn as block means to at most {panel_px} px a side"


def plot_map_grid(
    rows: Sequence[Sequence[MapPanel | None]],
    row_labels: Sequence[str],
    pixel_um: float,
    title: str,
    paths: list[str],
    *,
    cmap: str = "gray",
    shared_limits: bool = False,
) -> None:
    """A grid of image panels (None leaves a cell empty), one labelled row each; a scale note
    in the caption line. Figs. B.8 and B.11 (5.2)."""
    n_rows, n_cols = len(rows), max(len(r) for r in rows)
    fig, axes = plt.subplots(
        n_rows,
        n_cols,
        figsize=(_GRID_PANEL_IN * n_cols + 0.8, 1.7 * n_rows + 0.6),
        squeeze=False,
        constrained_layout=True,
    )
    limits = None
    if shared_limits:
        images = [p.image for r in rows for p in r if p is not None]
        limits = (min(float(np.min(i)) for i in images), max(float(np.max(i)) for i in images))
    for r, (row, label) in enumerate(zip(rows, row_labels, strict=True)):
        for c in range(n_cols):
            ax = axes[r, c]
            panel = row[c] if c < len(row) else None
            if panel is None:
                ax.axis("off")
                continue
            shown = at_display_resolution(panel, pixel_um, _GRID_PANEL_PX)
            _draw(ax, shown, pixel_um, cmap, limits)
            if c == 0:
                ax.set_ylabel(label, fontsize=7)
    side = rows[0][0].image.shape[1] * pixel_um if rows[0][0] is not None else 0
    fig.suptitle(
        f"{title} (each panel {side:.0f} µm wide; {_drawn_at(_GRID_PANEL_PX)})",
        fontsize=8,
    )
    save_figure(fig, paths)


def plot_height_maps(panels: Sequence[MapPanel], title: str, paths: list[str]) -> None:
    """Fig. B.9: height maps (nm; each panel with its own ``pixel_um``) side by side on one
    colour scale, each with the flattened region outlined and its centre marked."""
    fig, axes = plt.subplots(
        1,
        len(panels),
        figsize=(_HEIGHT_PANEL_IN * len(panels), 3.6),
        squeeze=False,
        constrained_layout=True,
    )
    values = np.concatenate([p.image.ravel() for p in panels])
    limits = tuple(np.percentile(values, [1, 99]))
    for ax, panel in zip(axes[0], panels, strict=True):
        _draw(
            ax,
            at_display_resolution(panel, 1.0, _HEIGHT_PANEL_PX),
            1.0,
            "viridis",
            limits,
        )
    side = panels[0].image.shape[1] * panels[0].pixel_um
    mappable = plt.cm.ScalarMappable(norm=matplotlib.colors.Normalize(*limits), cmap="viridis")
    fig.colorbar(mappable, ax=list(axes[0]), shrink=0.8, label="height (nm)")
    fig.suptitle(
        f"{title} (each panel {side:.1f} µm wide; {_drawn_at(_HEIGHT_PANEL_PX)})",
        fontsize=8,
    )
    save_figure(fig, paths)


@dataclass(frozen=True)
class Curve:
    """A load-area series: loads (mN), areas (µm²), its legend label and line style."""

    label: str
    loads_mn: np.ndarray
    areas_um2: np.ndarray
    style: str = "-"
    band: tuple[np.ndarray, np.ndarray] | None = None


def plot_area_curves(
    points: Curve | None,
    curves: Sequence[Curve],
    title: str,
    paths: list[str],
    *,
    guides_at: float | None = None,
    xlabel: str = "normal load F (mN)",
    ylabel: str = "real contact area A (µm²)",
) -> None:
    """Log-log area against load: measured points (symbols), model curves with an optional
    interval band, and, with ``guides_at`` (a load), the linear and the 2/3 power law drawn
    through the first curve's area there. Figs. B.10 and B.12."""
    fig, ax = plt.subplots(figsize=(5.2, 4.2), constrained_layout=True)
    if points is not None:
        ax.plot(points.loads_mn, points.areas_um2, "ko", label=points.label, zorder=3)
    for curve in curves:
        (line,) = ax.plot(curve.loads_mn, curve.areas_um2, curve.style, label=curve.label, lw=1.2)
        if curve.band is not None:
            ax.fill_between(curve.loads_mn, *curve.band, color=line.get_color(), alpha=0.15)
    if guides_at is not None and curves:
        first = curves[0]
        span = np.geomspace(first.loads_mn.min(), first.loads_mn.max(), 20)
        a0 = float(np.interp(np.log(guides_at), np.log(first.loads_mn), first.areas_um2))
        ax.plot(span, a0 * (span / guides_at), "k-", lw=0.7, label="A ∝ F (linear)")
        ax.plot(span, a0 * (span / guides_at) ** (2 / 3), "k:", lw=0.9, label="A ∝ F^(2/3)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    _plain_log_ticks(ax)
    ax.set_title(title, fontsize=8)
    ax.legend(fontsize=6)
    save_figure(fig, paths)


def plot_normalised_study(
    measured: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
    models: dict[str, tuple[np.ndarray, np.ndarray]],
    reference_load_mn: float,
    title: str,
    paths: list[str],
) -> None:
    """Fig. B.13: a) area and b) static friction over their values at the reference load,
    against F / F_ref, per sphere (``measured``: sphere → (F/F_ref, A/A_ref, Fs/Fs_ref)), with
    each sphere's best hardening model's A/A_ref (``models``: sphere → (F/F_ref, A/A_ref)) as
    a line in a), and Amontons' law (slope 1)."""
    fig, axes = plt.subplots(1, 2, figsize=(8.0, 3.8), constrained_layout=True)
    every = np.concatenate([x for x, _, _ in measured.values()])
    span = np.geomspace(every.min(), every.max(), 20)
    for sphere, (x, area, friction) in measured.items():
        (line,) = axes[0].plot(x, area, "o", label=sphere)
        axes[1].plot(x, friction, "o", color=line.get_color(), label=sphere)
        if sphere in models:
            mx, ma = models[sphere]
            label = f"{sphere}: {CONTACT_HARDENING.name}"
            axes[0].plot(mx, ma, "-", color=line.get_color(), lw=1, label=label)
    for ax, name, label in (
        (axes[0], "a) contact area", "A / A_ref"),
        (axes[1], "b) static friction", "F_s / F_s,ref"),
    ):
        amontons_axes(ax, span, reference_load_mn, label, name, legend_size=6)
    for ax in axes:
        _plain_log_ticks(ax)
    fig.suptitle(title, fontsize=9)
    save_figure(fig, paths)


def grid_best_path(rendered_paths: Sequence[str], best: dict) -> str:
    """The rendered series (rendered.h5) of a scan's grid's best value, found by the value
    each file's settings record (their fields are not read)."""
    return next(
        p for p in rendered_paths if read_load_series_settings(p)["value"] == best["grid_best"]
    )


def write_undecided_k_scan(
    best: dict, table_path: str, figure_paths: list[str], label: str
) -> None:
    """The table and the figure (Fig. B.9 or B.11) of a sphere whose k scan was not decided
    (best.json's ``not_decided``): why, in both, in place of a model that was not solved."""
    table = pd.DataFrame([{BEST_K: None, "not_decided": best["not_decided"]}])
    write_table(table_path, table)
    plot_unmeasured(best["not_decided"], f"{label}: the k scan was not decided", figure_paths)
