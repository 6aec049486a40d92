"""Appendix Figs. 5.2 and B.11 for one sphere (docs/study.md): measured and simulated contact
at increasing loads. Rows: the experiment; Greenwood–Tripp (its mean-field real-area
fraction: the model has no asperity map); the elastic scene; the hardening model at the k
scan's grid's best k (the scanned value of least distance, docs/study.md §1), each
simulation warped onto the measured image by its scene's registration. Areas in µm², loads
in mN."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from amontons.io.fields import read_load_series
from amontons.io.files import write_table
from amontons.measure.area import ContactArea
from amontons.models import CONTACT_HARDENING, ELASTIC, GREENWOOD_TRIPP
from amontons.simulate.compare import intersection_over_union
from amontons.simulate.register import Registration, warp_to_measured
from amontons.simulate.render import area_fraction_map
from amontons.simulate.scan_record import grid_best_text, significant
from amontons.study.figures import BEST_K, MapPanel, plot_map_grid

EXPERIMENT = "experiment"
# The rendered rows, each a model's scene warped onto the measured grid.
RENDERED_ROWS = (ELASTIC.name, CONTACT_HARDENING.name)


def warped_series(path: str, registration: Registration, shape) -> list:
    """Every load's rendered image of ``path`` on the measured grid, with its Otsu mask."""
    fields, per_load, _ = read_load_series(path)
    out = []
    for field, info in zip(fields, per_load, strict=True):
        image = warp_to_measured(field["image"], registration, shape, order=1)
        out.append((image, image > info["otsu_threshold"]))
    return out


@dataclass(frozen=True)
class LoadSeries:
    """What Fig. B.11 shows at each load: the measured images (2-D arrays) and their Otsu
    areas, Greenwood–Tripp's solve per load (solve.json's ``loads``), each rendered row's
    (image, mask) per load on the measured grid, the hardening model's registration (its
    map's centre places Greenwood–Tripp's radial fraction), the loads (mN) and the image
    pixel (m)."""

    images: Sequence[np.ndarray]
    measured: Sequence[ContactArea]
    greenwood_tripp: Sequence[Mapping]
    rendered: Mapping[str, list]
    registration: Registration
    loads_mn: Sequence[float]
    pixel_m: float

    @property
    def shape(self) -> tuple[int, int]:
        return self.images[0].shape

    def centre_px(self) -> np.ndarray:
        """The rendered map's centre on the measured grid, px (row, column)."""
        offset = np.asarray(self.registration.map_offset_px((0.0, 0.0)))
        return offset + (np.asarray(self.shape) - 1) / 2


def _row_record(load: float, row: str, area_um2: float, area: str, iou) -> dict:
    return {"load_mn": load, "row": row, "area_um2": area_um2, "area": area, "iou": iou}


def _measured_panels(series: LoadSeries, i: int, box) -> tuple[list, list]:
    """Load ``i``'s experiment and Greenwood–Tripp panels and table rows."""
    load, gt, measured = series.loads_mn[i], series.greenwood_tripp[i], series.measured[i]
    phi = area_fraction_map(
        gt["r_um"], gt["area_fraction"], series.shape, series.centre_px(), series.pixel_m
    )
    panels = [
        MapPanel(series.images[i][box], f"{load:g} mN", measured.mask[box]),
        MapPanel(phi[box], f"A = {gt['area_um2']:.0f} µm²"),
    ]
    records = [
        _row_record(load, EXPERIMENT, measured.area_m2 * 1e12, "measured Otsu", None),
        _row_record(load, GREENWOOD_TRIPP.name, gt["area_um2"], "model real area", None),
    ]
    return panels, records


def _rendered_panel(series: LoadSeries, name: str, i: int, box) -> tuple[MapPanel, dict]:
    """Load ``i``'s panel and table row of the rendered row ``name``: its Otsu area and its
    IoU with the measured mask."""
    image, mask = series.rendered[name][i]
    area = np.count_nonzero(mask) * series.pixel_m**2 * 1e12
    iou = intersection_over_union(mask, series.measured[i].mask)
    record = _row_record(series.loads_mn[i], name, area, "rendered Otsu (registered)", iou)
    return MapPanel(image[box], f"IoU {iou:.2f}", mask[box]), record


def load_series_panels(series: LoadSeries, box) -> tuple[list[list[MapPanel]], pd.DataFrame]:
    """The figure's rows of panels (experiment, Greenwood–Tripp, then :data:`RENDERED_ROWS`)
    cropped to ``box``, and its table: per load and row, the area (µm²), how it was measured
    and the IoU with the measured mask."""
    rows = {EXPERIMENT: [], GREENWOOD_TRIPP.name: [], **{name: [] for name in RENDERED_ROWS}}
    records = []
    for i in range(len(series.loads_mn)):
        panels, measured = _measured_panels(series, i, box)
        rows[EXPERIMENT].append(panels[0])
        rows[GREENWOOD_TRIPP.name].append(panels[1])
        records += measured
        for name in RENDERED_ROWS:
            panel, record = _rendered_panel(series, name, i, box)
            rows[name].append(panel)
            records.append(record)
    return list(rows.values()), pd.DataFrame(records)


def row_titles(best: Mapping) -> list[str]:
    """The rows' titles; the hardening row names the grid's best value it shows."""
    parameter = CONTACT_HARDENING.parameter
    return [
        EXPERIMENT,
        f"{GREENWOOD_TRIPP.label}\n(area fraction)",
        ELASTIC.label,
        f"{CONTACT_HARDENING.name}\ngrid's best\n{parameter.symbol} = "
        f"{significant(best['grid_best'])} {parameter.unit}",
    ]


def write_load_series(
    series: LoadSeries, box, best: Mapping, table_path: str, figure_paths: list[str], label: str
) -> pd.DataFrame:
    """Fig. B.11 and its table (CSV) for a decided k scan's ``best`` (best.json)."""
    rows, table = load_series_panels(series, box)
    table[BEST_K] = best["grid_best"]
    write_table(table_path, table)
    plot_map_grid(
        rows,
        row_titles(best),
        series.pixel_m * 1e6,
        f"{label}: measured and simulated contact at increasing loads; "
        f"{CONTACT_HARDENING.name} at {grid_best_text(best)}; outlines: Otsu masks",
        figure_paths,
    )
    return table
