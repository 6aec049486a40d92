"""Figure titles fit their figures: wrapped between words to the width the figure's renderer
measures, for the figure's title and each panel's, so that none runs past the figure's edge
(the B.11 title of issue 35 was cut off at both ends)."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.font_manager import FontProperties  # noqa: E402

import amontons.study.figures  # noqa: E402
import amontons.study.plots  # noqa: E402
from amontons.study.figures import (  # noqa: E402
    Curve,
    MapPanel,
    plot_area_curves,
    plot_height_maps,
    plot_map_grid,
    plot_normalised_study,
)
from amontons.study.plots import fit_titles, plot_scene_comparison, wrap_to_width  # noqa: E402

# The title of Fig. B.11 on the full run's PS sphere (issue 35), and a longer one.
B11_TITLE = (
    "PS (synthetic data): measured and simulated contact at increasing loads; hardening at "
    "the grid's best k = 4.47 MPa/nm (estimate 5.31, 95% interval 4.61–6.13); outlines: "
    "Otsu masks"
)
LONG_TITLE = " ".join([B11_TITLE] * 2)


def overflowing_titles(fig) -> list[str]:
    """The titles of ``fig`` that run past an edge of the figure, or over another panel's
    title, as the figure's renderer draws them now; 0.5 px: the renderer's rounding of a
    glyph's extent."""
    if not isinstance(fig.canvas, FigureCanvasAgg):  # a closed figure lost its canvas
        FigureCanvasAgg(fig)
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    frame = fig.bbox
    titles = [fig._suptitle] if fig._suptitle is not None else []
    titles += [ax.title for ax in fig.axes if ax.title.get_text()]
    boxes = [title.get_window_extent(renderer) for title in titles]
    out = []
    for i, (title, box) in enumerate(zip(titles, boxes, strict=True)):
        outside = (
            box.x0 < frame.x0 - 0.5
            or box.x1 > frame.x1 + 0.5
            or box.y0 < frame.y0 - 0.5
            or box.y1 > frame.y1 + 0.5
        )
        overlapping = any(
            box.overlaps(other) for j, other in enumerate(boxes) if j != i and i and j
        )
        if outside or overlapping:
            out.append(title.get_text())
    return out


@pytest.fixture
def saved(monkeypatch):
    """Every figure the plotting functions save, kept after saving (closed, but drawable)."""
    figures = []
    real = amontons.study.plots.save_figure

    def keep(fig, paths):
        real(fig, paths)
        figures.append(fig)

    monkeypatch.setattr(amontons.study.plots, "save_figure", keep)
    monkeypatch.setattr(amontons.study.figures, "save_figure", keep)
    return figures


def test_wrap_to_width_breaks_between_words_and_keeps_every_word():
    fig = plt.figure(figsize=(4, 3))
    renderer = fig.canvas.get_renderer()
    properties = FontProperties(size=8)
    wrapped = wrap_to_width("first line\n" + LONG_TITLE, 200.0, renderer, properties)
    lines = wrapped.split("\n")
    assert lines[0] == "first line"  # an existing break is kept
    assert wrapped.split() == ("first line\n" + LONG_TITLE).split()  # no word lost or split
    widths = [renderer.get_text_width_height_descent(line, properties, False)[0] for line in lines]
    assert max(widths) <= 200.0 and len(lines) > 5
    plt.close(fig)


def test_fit_titles_keeps_every_title_inside_its_figure_and_its_panel():
    fig, axes = plt.subplots(1, 5, figsize=(8.8, 2.3), constrained_layout=True)
    fig.suptitle(LONG_TITLE, fontsize=8)
    for ax in axes:
        ax.set_title("hardening at the grid's best k = 4.47 MPa/nm: IoU 0.93", fontsize=7)
    assert len(overflowing_titles(fig)) == 6
    fit_titles(fig)
    assert overflowing_titles(fig) == []
    plt.close(fig)


def _map_grid(path):
    rng = np.random.default_rng(0)
    rows = [[MapPanel(rng.random((40, 40)), f"{load} mN") for load in (25, 50, 100, 200, 300)]]
    rows *= 4
    plot_map_grid(rows, ["experiment", "GT", "elastic", "hardening"], 0.2, B11_TITLE, [path])


def _height_maps(path):
    rng = np.random.default_rng(0)
    panels = [MapPanel(rng.random((30, 30)), f"{c}) AFM", pixel_um=0.05) for c in "abc"]
    plot_height_maps(panels, LONG_TITLE, [path])


def _area_curves(path):
    """Fig. B.12 as PS's full run draws it: seven fits in the legend, the scans' estimates in
    the title."""
    loads = np.array([25.0, 50, 100, 200, 300])
    label = "penetration_hardness, grid's best p_Y = 179 MPa: α = 0.914 [0.898, 0.930]"
    curves = [Curve(label, loads, loads ** (0.8 + i / 50)) for i in range(7)]
    plot_area_curves(Curve("measured", loads, loads**0.87), curves, LONG_TITLE, [path])


def _normalised_study(path):
    x = np.array([1.0, 2, 4, 8, 12])
    plot_normalised_study(
        {"PS": (x, x**0.87, x**0.9)}, {"PS": (x, x**0.86)}, 25.0, LONG_TITLE, [path]
    )


def _scene_comparison(path):
    image = np.random.default_rng(0).random((40, 40))
    mask = image > 0.5
    n = 5
    plot_scene_comparison(
        [25.0] * n,
        [image] * n,
        [mask] * n,
        [mask] * n,
        [0.9] * n,
        [1.0] * n,
        0.2,
        LONG_TITLE,
        [path],
    )


@pytest.mark.parametrize(
    "draw",
    [_map_grid, _height_maps, _area_curves, _normalised_study, _scene_comparison],
    ids=["B8-B11 map grid", "B9 height maps", "B10-B12 area curves", "B13", "scene comparison"],
)
def test_a_long_title_fits_the_saved_figure(draw, saved, tmp_path):
    """Each figure as the rules save it (PNG at 150 dpi): no title runs past the figure or
    past its panel."""
    path = tmp_path / "figure.png"
    draw(str(path))
    assert path.stat().st_size > 0
    (fig,) = saved
    assert overflowing_titles(fig) == []
