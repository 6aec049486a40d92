"""Figures of the workflow (matplotlib, non-interactive backend)."""

from __future__ import annotations

import textwrap

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from amontons.io.files import atomic_path
from amontons.simulate.grid import block_mean


def plot_normalised_load_area(
    table: pd.DataFrame, title: str, paths: list[str], reference_load_mn: float
) -> None:
    """Log–log A/A_ref versus F/F_ref per sphere, with the fitted power law and guides for
    Amontons (slope 1) and Hertz (slope 2/3). ``table`` has columns sphere, load_mn,
    area_norm (area over the area measured at the reference load), fit_exponent and fit_norm
    (the fit's area at the reference load on that scale)."""
    fig, ax = plt.subplots(figsize=(4.5, 4.0), constrained_layout=True)
    ratio = table["load_mn"] / reference_load_mn
    span = np.geomspace(ratio.min(), ratio.max(), 50)
    for sphere, rows in table.groupby("sphere", sort=False):
        x = rows["load_mn"] / reference_load_mn
        exponent, scale = rows["fit_exponent"].iloc[0], rows["fit_norm"].iloc[0]
        (line,) = ax.plot(x, rows["area_norm"], "o", label=f"{sphere}: α = {exponent:.3f}")
        ax.plot(span, scale * span**exponent, "-", color=line.get_color(), lw=1)
    ax.plot(span, span, "k--", lw=0.8, label="Amontons (A ∝ F)")
    ax.plot(span, span ** (2 / 3), "k:", lw=0.8, label="Hertz (A ∝ F^2/3)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"F / {reference_load_mn:g} mN")
    ax.set_ylabel(f"A / A({reference_load_mn:g} mN)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, paths)


# Rounds of wrapping and layout fit_titles runs at most: a wrap makes a title taller and the
# layout moves the axes, which may call for one more wrap.
TITLE_ROUNDS = 4
# The share of the figure's width a title may take (the rest: a margin at either edge).
TITLE_WIDTH = 0.98


def _text_width_px(renderer, text: str, properties) -> float:
    return renderer.get_text_width_height_descent(text, properties, ismath=False)[0]


def wrap_to_width(text: str, width_px: float, renderer, properties) -> str:
    """``text`` with each of its lines broken between words so that every line is at most
    ``width_px`` wide as ``renderer`` draws it in ``properties`` (display pixels). A single
    word wider than that stays on a line of its own."""
    lines = []
    for paragraph in text.split("\n"):
        line = ""
        for word in paragraph.split(" "):
            candidate = f"{line} {word}" if line else word
            if line and _text_width_px(renderer, candidate, properties) > width_px:
                lines.append(line)
                line = word
            else:
                line = candidate
        lines.append(line)
    return "\n".join(lines)


def _room_px(fig, ax) -> float:
    """The width an axes' title may take, centred over its axes as matplotlib draws it: to
    the nearer edge of the figure (less the margin) on either side, and no more than the
    distance to the centre of the nearest panel beside it, so that two neighbours' titles
    cannot meet."""
    frame = fig.bbox
    margin = frame.width * (1 - TITLE_WIDTH) / 2
    centre = (ax.bbox.x0 + ax.bbox.x1) / 2
    room = 2 * min(centre - frame.x0 - margin, frame.x1 - margin - centre)
    for other in fig.axes:
        beside = other.bbox.y0 < ax.bbox.y1 and ax.bbox.y0 < other.bbox.y1
        if other is not ax and other.title.get_text() and beside:
            room = min(room, abs((other.bbox.x0 + other.bbox.x1) / 2 - centre))
    return room


def _titles(fig):
    """(title, the width in display pixels it must fit) for the figure's title (the figure's
    width less the margin) and each axes' title (_room_px)."""
    # Figure.get_suptitle gives the string only; the Text artist is the figure's _suptitle.
    suptitle = getattr(fig, "_suptitle", None)
    if suptitle is not None and suptitle.get_text():
        yield suptitle, fig.bbox.width * TITLE_WIDTH
    for ax in fig.axes:
        if ax.get_visible() and ax.title.get_text():
            yield ax.title, _room_px(fig, ax)


def fit_titles(fig) -> None:
    """Wrap the figure's title to the figure's width and each axes' title to the room it has
    (_room_px), between words, keeping the line breaks they have, then lay the figure out
    again: a title never runs past the edge of the figure, nor over the next panel's.
    Measured with the figure's own renderer, so the font and its size decide, not a count of
    characters."""
    renderer = fig.canvas.get_renderer()
    for _ in range(TITLE_ROUNDS):
        _lay_out(fig, renderer)
        changed = False
        for title, width_px in _titles(fig):
            wrapped = wrap_to_width(
                title.get_text(), width_px, renderer, title.get_fontproperties()
            )
            if wrapped != title.get_text():
                title.set_text(wrapped)
                changed = True
        if not changed:
            return


def _lay_out(fig, renderer) -> None:
    """Place the axes as drawing the figure would (each axes' aspect, then the layout
    engine), without drawing them: what the titles' room needs, without resampling the
    images and drawing every artist (a tenth of a contact-area figure's time)."""
    for ax in fig.axes:
        locator = ax.get_axes_locator()
        ax.apply_aspect(locator(ax, renderer) if locator else None)
    engine = fig.get_layout_engine()
    if fig.axes and engine is not None:
        engine.execute(fig)


# Every figure's resolution (dots per inch).
FIGURE_DPI = 150


def save_figure(fig, paths: list[str]) -> None:
    """Fit the titles (fit_titles), then write ``fig`` to each path (format from the
    extension), atomically, and close it."""
    fit_titles(fig)
    for path in paths:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=FIGURE_DPI, format=str(path).rsplit(".", 1)[-1])
    plt.close(fig)


def display_factor(shape: tuple[int, ...], panel_px: int) -> int:
    """The block size that brings an image of ``shape`` (px) to no more than ``panel_px``
    pixels a side (what its panel shows at FIGURE_DPI); 1 where it is no wider."""
    return max(1, int(np.ceil(max(shape) / panel_px)))


def at_display(image: np.ndarray, factor: int) -> np.ndarray:
    """``image`` as block means of ``factor`` × ``factor`` pixels (a mask as the fraction of
    each block inside it, outlined at 0.5); itself where ``factor`` is 1. What a panel shows
    of a map wider than its pixels, while every number is computed at full resolution."""
    return image if factor == 1 else block_mean(image, factor)


def plot_psf_profile(
    r_nm: np.ndarray,
    counts: np.ndarray,
    fwhm_nm: float,
    fwhm_se_nm: float,
    peak_counts: float,
    background_counts: float,
    title: str,
    paths: list[str],
) -> None:
    """Radially averaged bead profile (counts vs distance from the centroid, nm) with the
    fitted Gaussian (appendix Fig. B.2). The curve shown uses the pixel-corrected FWHM."""
    sigma = fwhm_nm / (2 * np.sqrt(2 * np.log(2)))
    fig, ax = plt.subplots(figsize=(4.5, 3.5), constrained_layout=True)
    ax.plot(r_nm, counts, "o", ms=3, label="radial average")
    span = np.linspace(0, r_nm.max(), 200)
    ax.plot(
        span,
        peak_counts * np.exp(-0.5 * (span / sigma) ** 2) + background_counts,
        "-",
        label=f"Gaussian, FWHM {fwhm_nm:.0f} ± {fwhm_se_nm:.0f} nm",
    )
    ax.set_xlabel("distance from centre of intensity (nm)")
    ax.set_ylabel("intensity (counts)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, paths)


def plot_absorbance(
    wavelength_nm: np.ndarray,
    absorbance: np.ndarray,
    smoothed: np.ndarray,
    peak_nm: float,
    peak_absorbance: float,
    density_per_um2: float,
    title: str,
    paths: list[str],
) -> None:
    """Absorbance spectrum with its LOWESS smoothing and maximum (appendix Fig. B.1)."""
    fig, ax = plt.subplots(figsize=(4.5, 3.5), constrained_layout=True)
    ax.plot(wavelength_nm, absorbance, ".", ms=2, color="0.6", label="measured")
    ax.plot(wavelength_nm, smoothed, "r-", label="LOWESS")
    ax.plot(
        [peak_nm],
        [peak_absorbance],
        "kx",
        label=f"max {peak_absorbance:.2g} at {peak_nm:.0f} nm → {density_per_um2:.3g} µm⁻²",
    )
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("absorbance")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, paths)


def plot_edge_gap(
    ring_r_um: list[np.ndarray],
    ring_gap_nm: list[np.ndarray],
    edge_radii_um: np.ndarray,
    edge_gaps_nm: np.ndarray,
    title: str,
    paths: list[str],
    *,
    equal_area_radius_um: float,
    summary: str,
) -> None:
    """Gap of each Newton ring versus distance from the contact centre, every half-profile,
    and each profile's extrapolated gap at its own fluorescent edge (green squares, as in
    appendix Fig. B.7b); the equal-area radius of the contact for comparison. ``summary``:
    the mean with its interval, or why it is undetermined (then written in red)."""
    fig, ax = plt.subplots(figsize=(4.5, 3.8), constrained_layout=True)
    for r, gap in zip(ring_r_um, ring_gap_nm, strict=True):
        ax.plot(r, gap, "o-", ms=2, lw=0.4, color="tab:blue", alpha=0.4)
    ax.plot(edge_radii_um, edge_gaps_nm, "s", ms=3, color="tab:green", label="edge of each profile")
    ax.axvline(equal_area_radius_um, color="0.5", lw=0.8, ls=":", label="equal-area radius")
    ax.axhline(0, color="0.7", lw=0.5)
    undetermined = summary.startswith("undetermined")
    ax.text(
        0.02,
        0.98,
        textwrap.fill(summary, 70),
        transform=ax.transAxes,
        va="top",
        fontsize=6,
        color="tab:red" if undetermined else "black",
    )
    ax.set_xlabel("distance from contact centre (µm)")
    ax.set_ylabel("gap (nm)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    save_figure(fig, paths)


def plot_unmeasured(reason: str, title: str, paths: list[str]) -> None:
    """A figure that says why a quantity could not be measured (no silent empty plot)."""
    fig, ax = plt.subplots(figsize=(4.5, 3.5), constrained_layout=True)
    ax.axis("off")
    ax.text(
        0.5,
        0.5,
        "not measurable:\n" + textwrap.fill(reason, 60),
        ha="center",
        va="center",
        fontsize=7,
        wrap=True,
        transform=ax.transAxes,
    )
    ax.set_title(title, fontsize=9)
    save_figure(fig, paths)


# The widths (px at FIGURE_DPI) of the map panels below, 3 and 2.4 in: a map is drawn with no
# more pixels than its panel shows.
_TOPOGRAPHY_PANEL_PX = round(3.0 * FIGURE_DPI)
_LOAD_PANEL_PX = round(2.4 * FIGURE_DPI)


def plot_topography(
    before_nm: np.ndarray,
    after_nm: np.ndarray,
    change_nm: np.ndarray,
    pixel_um: float,
    title: str,
    paths: list[str],
) -> None:
    """Levelled AFM roughness before and after contact and their difference (appendix
    Fig. B.9), on one colour scale for the two scans."""
    fig, axes = plt.subplots(1, 3, figsize=(9, 3.2), constrained_layout=True)
    # the colour scales from the full maps, the panels drawn at the pixels they show
    low, high = np.percentile(before_nm, [1, 99])
    span = max(float(np.percentile(np.abs(change_nm), 99.9)), 1e-3)
    factor = display_factor(before_nm.shape, _TOPOGRAPHY_PANEL_PX)
    before_nm, after_nm, change_nm = (
        at_display(m, factor) for m in (before_nm, after_nm, change_nm)
    )
    pixel_um *= factor
    extent = [0, before_nm.shape[1] * pixel_um, 0, before_nm.shape[0] * pixel_um]
    for ax, data, label in ((axes[0], before_nm, "before"), (axes[1], after_nm, "after")):
        image = ax.imshow(data, extent=extent, origin="lower", vmin=low, vmax=high, cmap="viridis")
        ax.set_title(f"{label} contact", fontsize=8)
    fig.colorbar(image, ax=axes[:2], label="height (nm)", shrink=0.8)
    diff = axes[2].imshow(
        change_nm, extent=extent, origin="lower", vmin=-span, vmax=span, cmap="RdBu"
    )
    axes[2].set_title("after − before", fontsize=8)
    fig.colorbar(diff, ax=axes[2], label="height change (nm)", shrink=0.8)
    for ax in axes:
        ax.set_xlabel("x (µm)")
    axes[0].set_ylabel("y (µm)")
    fig.suptitle(title, fontsize=9)
    save_figure(fig, paths)


def plot_amontons_deviation(
    table: pd.DataFrame, title: str, paths: list[str], reference_load_mn: float
) -> None:
    """Appendix Fig. B.13: (a) A/A_ref and (b) F_s/F_s,ref versus F/F_ref per sphere, log–log,
    with Amontons' law (slope 1). ``table`` has columns sphere, normal_force_mn,
    area_over_area_ref, friction_over_friction_ref."""
    fig, axes = plt.subplots(1, 2, figsize=(8.0, 3.8), constrained_layout=True)
    ratio = table["normal_force_mn"] / reference_load_mn
    span = np.geomspace(ratio.min(), ratio.max(), 50)
    panels = (
        ("area_over_area_ref", f"A / A({reference_load_mn:g} mN)", "a) contact area"),
        (
            "friction_over_friction_ref",
            f"F_s / F_s({reference_load_mn:g} mN)",
            "b) static friction",
        ),
    )
    for ax, (column, label, name) in zip(axes, panels, strict=True):
        for sphere, rows in table.groupby("sphere", sort=False):
            ax.plot(rows["normal_force_mn"] / reference_load_mn, rows[column], "o-", label=sphere)
        amontons_axes(ax, span, reference_load_mn, label, name, legend_size=7)
    fig.suptitle(title, fontsize=9)
    save_figure(fig, paths)


def amontons_axes(ax, span, reference_load_mn: float, ylabel: str, title: str, legend_size):
    """One panel of Fig. B.13: log-log against F / F_ref (mN) with Amontons' law (slope 1)
    over ``span``, the quantity ``ylabel`` normalised at the reference load."""
    ax.plot(span, span, "k--", lw=0.8, label="Amontons (∝ F)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"F / {reference_load_mn:g} mN")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=legend_size)


def plot_contact_separation(
    loads_mn: list[float],
    images: list[np.ndarray],
    masks: list[np.ndarray],
    thresholds: list[float],
    separations: list[float],
    flags: list[str | None],
    pixel_um: float,
    title: str,
    paths: list[str],
) -> None:
    """Per load: the fluorescence image with the Otsu contact edge (green, as in appendix
    Fig. B.7a) above the histogram of its pixel counts with the threshold and the Otsu
    separation η, so a reader sees when contact and background overlap. A load whose flag
    says no contact was found (amontons.measure.area) is titled in red, "no contact"."""
    n = len(loads_mn)
    fig, axes = plt.subplots(2, n, figsize=(2.4 * n, 5.0), constrained_layout=True, squeeze=False)
    for column, (load, image, mask, threshold, eta, flag) in enumerate(
        zip(loads_mn, images, masks, thresholds, separations, flags, strict=True)
    ):
        top, bottom = axes[0, column], axes[1, column]
        factor = display_factor(image.shape, _LOAD_PANEL_PX)
        shown = at_display(image, factor)
        extent = [0, shown.shape[1] * pixel_um * factor, 0, shown.shape[0] * pixel_um * factor]
        top.imshow(shown, cmap="gray", origin="lower", extent=extent)
        top.contour(
            at_display(mask.astype(float), factor),
            levels=[0.5],
            colors="lime",
            linewidths=0.5,
            origin="lower",
            extent=extent,
        )
        top.set_title(f"{load:g} mN", fontsize=8)
        top.set_xlabel("x (µm)", fontsize=7)
        top.tick_params(labelsize=6)
        bottom.hist(image.ravel(), bins=128, log=True, color="0.4")
        bottom.axvline(threshold, color="tab:green", ls="--", lw=1)
        bottom.set_title(
            f"η = {eta:.2f}" + ("" if flag is None else ": no contact"),
            fontsize=8,
            color="black" if flag is None else "red",
        )
        bottom.set_xlabel("counts", fontsize=7)
        bottom.tick_params(labelsize=6)
    axes[0, 0].set_ylabel("y (µm)", fontsize=7)
    axes[1, 0].set_ylabel("pixels", fontsize=7)
    fig.suptitle(title, fontsize=9)
    save_figure(fig, paths)


def plot_intensity_pressure(
    pressure_mpa: np.ndarray, intensity_counts: np.ndarray, fit, title: str, paths: list[str]
) -> None:
    """Appendix Fig. B.4: background-subtracted mean contact intensity versus mean contact
    pressure F/A (log–log), the fitted power law (``fit``: amontons.power_law.PowerLawFit with
    x_ref in Pa) and the appendix's square-root law through the fit at the middle pressure."""
    fig, ax = plt.subplots(figsize=(4.5, 3.5), constrained_layout=True)
    ax.plot(pressure_mpa, intensity_counts, "o", label="per load")
    span = np.geomspace(pressure_mpa.min(), pressure_mpa.max(), 50)
    exponent = fit.exponent

    def fitted(p_mpa):
        return fit.prefactor.estimate * (p_mpa * 1e6 / fit.x_ref) ** exponent.estimate

    ax.plot(
        span,
        fitted(span),
        "-",
        label=(
            f"fit: α = {exponent.estimate:.3f} "
            f"[{exponent.ci_low:.3f}, {exponent.ci_high:.3f}] ({exponent.confidence:.0%})"
        ),
    )
    middle = float(np.sqrt(span[0] * span[-1]))
    ax.plot(span, fitted(middle) * (span / middle) ** 0.5, "k:", lw=0.8, label="I ∝ p^1/2")
    ax.set_xscale("log")
    ax.set_yscale("log")
    # A narrow log range gets only minor ticks; label them plainly instead of as powers.
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
        axis.set_minor_formatter(matplotlib.ticker.ScalarFormatter())
    ax.tick_params(which="both", labelsize=7)
    ax.set_xlabel("mean contact pressure F/A (MPa)")
    ax.set_ylabel("mean contact intensity (counts)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, paths)


def plot_scene_comparison(
    loads_mn: list[float],
    images: list[np.ndarray],
    measured_masks: list[np.ndarray],
    simulated_masks: list[np.ndarray | None],
    ious: list[float | None],
    ratios: list[float | None],
    pixel_um: float,
    title: str,
    paths: list[str],
) -> None:
    """Per load: the measured fluorescence image with its Otsu edge (green, as in appendix
    Fig. B.8) and the registered simulated contact's Otsu edge (magenta), titled with the
    intersection over union and the simulated/measured area ratio. A load whose simulated
    mask is None was not simulated (its window lies outside the AFM scan) and says so."""
    n = len(loads_mn)
    fig, axes = plt.subplots(1, n, figsize=(2.4 * n, 2.8), constrained_layout=True, squeeze=False)
    for ax, load, image, measured, simulated, iou, ratio in zip(
        axes[0], loads_mn, images, measured_masks, simulated_masks, ious, ratios, strict=True
    ):
        factor = display_factor(image.shape, _LOAD_PANEL_PX)
        shown = at_display(image, factor)
        extent = [0, shown.shape[1] * pixel_um * factor, 0, shown.shape[0] * pixel_um * factor]
        ax.imshow(shown, cmap="gray", origin="lower", extent=extent)
        for mask, colour in ((measured, "lime"), (simulated, "magenta")):
            if mask is not None and mask.any():
                ax.contour(
                    at_display(mask.astype(float), factor),
                    levels=[0.5],
                    colors=colour,
                    linewidths=0.6,
                    origin="lower",
                    extent=extent,
                )
        if simulated is None:
            ax.set_title(f"{load:g} mN: outside the AFM scan", fontsize=7)
        else:
            ax.set_title(f"{load:g} mN: IoU {iou:.2f}, A_sim/A {ratio:.2f}", fontsize=7)
        ax.set_xlabel("x (µm)", fontsize=7)
        ax.tick_params(labelsize=6)
    axes[0, 0].set_ylabel("y (µm)", fontsize=7)
    fig.suptitle(title + "\ngreen: measured Otsu edge, magenta: simulated", fontsize=8)
    save_figure(fig, paths)
