"""Appendix Fig. B.9 for one sphere (docs/study.md): the AFM map before and after the load
series, and the deformed surface h + h_pl of the hardening model at the k scan's grid's best
k (the scanned value of least distance, docs/study.md §1) after the largest load; sphere
curvature subtracted from all three, all in the AFM frame cut to the solver window about the
fitted apex. Each shows the flattening: measured, where after − before drops
(amontons.measure.flattening); simulated, where h_pl < 0; its depth (the median drop over
the pixels that went down by more than half of it, the same definition for both) and the
centre of the flattened region. Heights in m, depths in the table in nm."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from amontons.contact.surfaces import sphere as sphere_cap
from amontons.io.files import write_table
from amontons.measure.flattening import SMOOTHING_PX
from amontons.models import CONTACT_HARDENING
from amontons.simulate.flattening import flattened_region, offset_from_centre_m, window_slices
from amontons.simulate.scan_record import grid_best_label, grid_best_text
from amontons.study.figures import BEST_K, MapPanel, plot_height_maps


@dataclass(frozen=True)
class Flattening:
    """One panel's flattened region: its depth (m; None for none), its core (bool mask) and
    its centre ((row, col) px; None for none), on a grid of ``pixel_m``."""

    depth: float | None
    core: np.ndarray
    centre: tuple | None
    pixel_m: float

    def describe(self, name: str) -> dict:
        """The CSV row of the panel: depth (nm), centre (µm from the window centre), area
        (µm²)."""
        offset = offset_from_centre_m(self.centre, self.core.shape, self.pixel_m)
        offset = offset or (None, None)
        return {
            "panel": name,
            "flattening_depth_nm": None if self.depth is None else self.depth * 1e9,
            "centre_row_um": None if offset[0] is None else offset[0] * 1e6,
            "centre_col_um": None if offset[1] is None else offset[1] * 1e6,
            "flattened_area_um2": int(self.core.sum()) * self.pixel_m**2 * 1e12,
        }


def _title(name: str, depth) -> str:
    return f"{name}\nflattening {'none' if depth is None else f'{depth * 1e9:.1f} nm deep'}"


def measured_window(topo, attrs: Mapping) -> tuple[slice, slice]:
    """The solver window (the scan's rendered series' attributes: its centre in the scan and
    its side, µm) on the AFM map of ``topo`` (amontons.measure.topography)."""
    return window_slices(
        topo.before.roughness.shape,
        topo.pixel_m,
        [c * 1e-6 for c in attrs["window_centre_in_scan_um"]],
        attrs["window_um"] * 1e-6,
    )


def simulated_surface(last: Mapping, solver_pixel_m: float, radius_m: float) -> np.ndarray:
    """The model's deformed surface h + h_pl (m) at the last load, less the fitted sphere
    and its median."""
    heights = last["deformed_heights"]
    deformed = heights - sphere_cap(heights.shape, solver_pixel_m, radius_m)
    return deformed - np.median(deformed)


def simulated_flattening(last: Mapping, solver_pixel_m: float, topo) -> Flattening:
    """The model's flattened region, where h_pl < 0, with the measurement's smoothing length
    (on the solver grid) and floor."""
    depth, core, centre = flattened_region(
        -last["plastic_displacement"].astype(float),
        SMOOTHING_PX * topo.pixel_m / solver_pixel_m,
        topo.flattening.threshold_m,
    )
    return Flattening(depth, core, centre, solver_pixel_m)


def flattening_panels(topo, window, last: Mapping, solver_pixel_m: float, best: Mapping):
    """The three panels and the two table rows (measured, model) of Fig. B.9."""
    change = topo.change_m[window]
    depth, core, centre = flattened_region(-change, SMOOTHING_PX, topo.flattening.threshold_m)
    measured = Flattening(depth, core, centre, topo.pixel_m)
    model = simulated_flattening(last, solver_pixel_m, topo)
    deformed = simulated_surface(last, solver_pixel_m, topo.before.radius_m)
    afm_um = topo.pixel_m * 1e6
    name = CONTACT_HARDENING.name
    panels = [
        MapPanel(scan.roughness[window] * 1e9, _title(title, depth), core, centre, pixel_um=afm_um)
        for scan, title in ((topo.before, "a) AFM before"), (topo.after, "b) AFM after"))
    ]
    panels.append(
        MapPanel(
            deformed * 1e9,
            _title(f"c) {name}, {grid_best_label(best)}", model.depth),
            model.core,
            model.centre,
            pixel_um=solver_pixel_m * 1e6,
        )
    )
    rows = [measured.describe("measured (after - before)"), model.describe(f"{name} model (h_pl)")]
    return panels, rows


def write_flattening(
    topo, fields, per_load, attrs, best, table_path: str, figure_paths: list[str], label: str
) -> pd.DataFrame:
    """Fig. B.9 and its table (CSV) from the measured topography ``topo`` and the grid's best
    value's rendered series (fields, per-load records, attributes) of a decided k scan."""
    window = measured_window(topo, attrs)
    panels, rows = flattening_panels(topo, window, fields[-1], attrs["pixel_nm"] * 1e-9, best)
    table = pd.DataFrame(rows)
    table[BEST_K] = best["grid_best"]
    table["load_mn"] = per_load[-1]["load_mn"]
    write_table(table_path, table)
    plot_height_maps(
        panels,
        f"{label}: AFM before and after the load series, and the {CONTACT_HARDENING.name} "
        f"model's deformed surface at {grid_best_text(best)}; sphere subtracted; outlines: "
        "flattened regions, +: their centres",
        figure_paths,
    )
    return table
