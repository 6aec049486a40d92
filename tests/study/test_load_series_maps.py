"""Fig. B.11's panels and table (amontons.study.load_series_maps) on small arrays, in-process:
what the figure's table states is what its masks and areas are. A disc of radius 5 px on a
32² grid of 1 µm pixels stands for every contact; the rendered rows are that disc (IoU 1) and
the disc shifted by 2 px (its IoU is counted here from the two masks)."""

import json

import numpy as np
import pandas as pd
import pytest

from amontons.measure.area import ContactArea
from amontons.models import CONTACT_HARDENING, ELASTIC, GREENWOOD_TRIPP
from amontons.simulate.register import Registration
from amontons.study import figures
from amontons.study.load_series_maps import (
    EXPERIMENT,
    LoadSeries,
    load_series_panels,
    row_titles,
    write_load_series,
)

SHAPE = (32, 32)
PIXEL_M = 1e-6
LOADS_MN = [10.0, 20.0]


def _disc(shift: int = 0) -> np.ndarray:
    rows, cols = np.indices(SHAPE)
    return np.hypot(rows - 16, cols - 16 - shift) <= 5


def _measured(mask: np.ndarray) -> ContactArea:
    return ContactArea(
        area_m2=mask.sum() * PIXEL_M**2,
        n_contact_pixels=int(mask.sum()),
        threshold=0.5,
        separation=1.0,
        contrast=1.0,
        largest_patch_px=int(mask.sum()),
        flag=None,
        mask=mask,
    )


@pytest.fixture
def series() -> LoadSeries:
    disc = _disc()
    image = disc.astype(float)
    gt = [
        {"r_um": [0.0, 4.0, 8.0], "area_fraction": [0.5, 0.25, 0.0], "area_um2": 30.0 * (i + 1)}
        for i in range(len(LOADS_MN))
    ]
    return LoadSeries(
        images=[image, image],
        measured=[_measured(disc), _measured(disc)],
        greenwood_tripp=gt,
        rendered={
            ELASTIC.name: [(image, disc)] * 2,
            CONTACT_HARDENING.name: [(image, _disc(shift=2))] * 2,
        },
        registration=Registration(False, 0.0, (0.0, 0.0), 1.0),
        loads_mn=LOADS_MN,
        pixel_m=PIXEL_M,
    )


def test_the_table_states_each_rows_area_and_overlap(series):
    box = (slice(0, 32), slice(0, 32))
    rows, table = load_series_panels(series, box)
    assert [len(r) for r in rows] == [2, 2, 2, 2]
    disc, shifted = _disc(), _disc(shift=2)
    iou = (disc & shifted).sum() / (disc | shifted).sum()
    at_first = table[table["load_mn"] == LOADS_MN[0]].set_index("row")
    assert list(at_first.index) == [
        EXPERIMENT,
        GREENWOOD_TRIPP.name,
        ELASTIC.name,
        CONTACT_HARDENING.name,
    ]
    # areas in µm²: one pixel is 1 µm², so the area is the mask's pixel count, exactly
    assert at_first.loc[EXPERIMENT, "area_um2"] == pytest.approx(disc.sum(), rel=1e-12)
    assert at_first.loc[ELASTIC.name, "iou"] == 1.0
    assert at_first.loc[CONTACT_HARDENING.name, "iou"] == pytest.approx(iou, rel=1e-12)
    assert at_first.loc[GREENWOOD_TRIPP.name, "area_um2"] == 30.0


def test_greenwood_tripps_panel_is_its_radial_fraction_about_the_map_centre(series):
    rows, _ = load_series_panels(series, (slice(0, 32), slice(0, 32)))
    phi = rows[1][0].image
    centre = (np.asarray(SHAPE) - 1) / 2  # the identity registration: the grid's centre
    # pixel (15, 15) lies 0.5·√2 px = 0.707 µm from it: linear between 0.5 at 0 and 0.25 at 4
    expected = 0.5 - 0.25 * np.hypot(*(centre - 15)) / 4
    assert phi[15, 15] == pytest.approx(expected, rel=1e-12)
    assert phi[0, 0] == 0.0  # beyond the last radius (8 µm)


def test_the_hardening_row_names_the_grid_best_it_shows():
    titles = row_titles({"grid_best": 4.47})
    assert titles[3].endswith("k = 4.47 MPa/nm") and titles[2] == ELASTIC.label
    # every model row is named as the model table and the verdict name it (its record's label)
    assert titles[1].splitlines()[0] == "Greenwood–Tripp" == GREENWOOD_TRIPP.label


def test_the_figure_and_its_table_are_written(series, tmp_path, monkeypatch):
    drawn = []
    monkeypatch.setattr("amontons.study.load_series_maps.plot_map_grid", lambda *a: drawn.append(a))
    best = {"grid_best": 5.0, "interval": [4.0, 6.0], "estimate": 5.1, "confidence": 0.95}
    best |= {"parameter": CONTACT_HARDENING.parameter.key}
    table = write_load_series(
        series, (slice(0, 32), slice(0, 32)), best, str(tmp_path / "b11.csv"), [], "PS"
    )
    written = pd.read_csv(tmp_path / "b11.csv")
    assert list(written.columns) == list(table.columns)
    assert (written[figures.BEST_K] == 5.0).all() and len(written) == 8
    assert drawn and "grid's best k = 5 MPa/nm" in drawn[0][3]
    json.dumps(drawn[0][1])  # the titles are plain text
