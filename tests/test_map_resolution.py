"""Maps drawn at the resolution their panels show (Figs. B.8, B.9, B.11): block means to at
most the panel's pixels a side, the grid's pixel and the marks moved with it, so that what a
panel shows, and where, is unchanged."""

import numpy as np

from amontons.simulate.grid import block_mean
from amontons.study.figures import MapPanel, at_display_resolution


def test_block_mean_averages_whole_blocks_and_drops_the_rest():
    image = np.arange(7 * 9, dtype=float).reshape(7, 9)
    small = block_mean(image, 2)
    assert small.shape == (3, 4)  # the seventh row and ninth column fill no block
    assert small[1, 2] == np.mean(image[2:4, 4:6])
    # a boolean mask averages to the fraction of each block inside it
    assert block_mean(image > 30, 3)[1, 1] == np.mean(image[3:6, 3:6] > 30)


def test_a_wide_map_is_drawn_at_the_panels_resolution_with_its_marks_in_place():
    rows, cols = np.indices((1000, 1000))
    disc = (rows - 480.0) ** 2 + (cols - 530.0) ** 2 < 200.0**2
    image = disc.astype(float)
    image[500:505, 300:305] = 5.0  # a bright block, aligned to the 5 px blocks
    panel = MapPanel(image, "map", outline=disc, marker=(502.0, 302.0))
    shown = at_display_resolution(panel, 0.2, 240)
    # ceil(1000 / 240) = 5: 200 px a side, each 1 µm; the panel still shows 200 µm
    assert shown.image.shape == (200, 200)
    assert shown.pixel_um == 1.0
    assert shown.image.shape[0] * shown.pixel_um == image.shape[0] * 0.2
    # the marker lands on the block that holds what it marked
    peak = np.unravel_index(np.argmax(shown.image), shown.image.shape)
    assert shown.marker == (100.0, 60.0) == tuple(float(p) for p in peak)
    # the outline drawn at half a block holds the disc's area within its rim's blocks: the
    # rim is 2π·200 px long, and half a 5 px block either way moves it by at most 2.5 px
    drawn = np.count_nonzero(shown.outline >= 0.5) * 25
    assert abs(drawn - np.count_nonzero(disc)) < 2 * np.pi * 200 * 2.5
    assert abs(drawn - np.count_nonzero(disc)) / np.count_nonzero(disc) < 0.01


def test_a_map_no_wider_than_its_panel_is_drawn_as_it_is():
    panel = MapPanel(np.ones((240, 100)), "map", pixel_um=0.5)
    assert at_display_resolution(panel, 0.2, 240) is panel


def _drawn_shapes(monkeypatch) -> list[tuple[int, ...]]:
    """The shape of every image matplotlib is asked to draw from here on."""
    import matplotlib.axes

    shapes = []
    imshow = matplotlib.axes.Axes.imshow

    def recording(self, image, *args, **kwargs):
        shapes.append(np.shape(image))
        return imshow(self, image, *args, **kwargs)

    monkeypatch.setattr(matplotlib.axes.Axes, "imshow", recording)
    return shapes


def test_the_measurement_figures_draw_wide_maps_at_their_panels_pixels(monkeypatch, tmp_path):
    """Topography (3 in panels, 450 px at 150 dpi), contact areas and scene comparisons
    (2.4 in, 360 px): a 2048² AFM map and 1568² fluorescence images are drawn as block means
    no wider than their panel, and a 300² image as it is."""
    from amontons.study.plots import plot_contact_separation, plot_scene_comparison, plot_topography

    shapes = _drawn_shapes(monkeypatch)
    rng = np.random.default_rng(0)
    afm = rng.normal(size=(2048, 2048))
    plot_topography(afm, afm, afm, 0.05, "t", [str(tmp_path / "topo.png")])
    assert shapes == [(409, 409)] * 3  # 2048 // 5: blocks of 5 px
    shapes.clear()
    rows, cols = np.indices((1568, 1568))
    image = rng.normal(size=(1568, 1568))
    mask = (rows - 800.0) ** 2 + (cols - 700.0) ** 2 < 300.0**2
    plot_scene_comparison([10.0, 20.0], [image, image[:300, :300]], [mask, mask[:300, :300]],
                          [mask, None], [0.9, None], [1.0, None], 0.2, "c",
                          [str(tmp_path / "c.png")])  # fmt: skip
    plot_contact_separation([10.0], [image], [mask], [0.5], [0.9], [None], 0.2, "s",
                            [str(tmp_path / "s.png")])  # fmt: skip
    assert shapes == [(313, 313), (300, 300), (313, 313)]  # 1568 // 5
    assert all((tmp_path / name).stat().st_size > 0 for name in ("topo.png", "c.png", "s.png"))
