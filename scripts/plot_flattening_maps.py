"""Rule plot_flattening_maps: appendix Fig. B.9 for one sphere. The AFM map before and after
the load series, and the deformed surface h + h_pl of the hardening model at the k scan's
grid's best k (the scanned value of least distance, docs/study.md §1) after the largest
load; sphere curvature subtracted from all three, all in the AFM frame cut to the solver
window about the fitted apex. Each shows the flattening: measured, where after − before drops
(amontons.measure.flattening); simulated, where h_pl < 0; its depth (the median drop over the
pixels that went down by more than half of it, the same definition for both) and the centre
of the flattened region."""

import logging

import numpy as np
import pandas as pd

from amontons.contact.surfaces import sphere as sphere_cap
from amontons.io.fields import read_load_series
from amontons.io.files import read_json, write_table
from amontons.io.units import optional_nm_to_m
from amontons.measure.flattening import SMOOTHING_PX
from amontons.measure.scan_lines import line_levelling_mode
from amontons.measure.topography import measure_topography, read_sphere_fits
from amontons.runlog import run_logged
from amontons.simulate.flattening import (
    flattened_region,
    offset_from_centre_m,
    window_slices,
)
from amontons.simulate.scan_record import grid_best_label, grid_best_text, is_decided
from amontons.study_figures import (
    MapPanel,
    grid_best_path,
    plot_height_maps,
    write_undecided_k_scan,
)

log = logging.getLogger(__name__)


def describe(name: str, depth, centre, pixel_m: float, shape, area_px: int) -> dict:
    """The CSV row of one panel: depth (nm) and centre (µm from the window centre)."""
    offset = offset_from_centre_m(centre, shape, pixel_m) or (None, None)
    return {
        "panel": name,
        "flattening_depth_nm": None if depth is None else depth * 1e9,
        "centre_row_um": None if offset[0] is None else offset[0] * 1e6,
        "centre_col_um": None if offset[1] is None else offset[1] * 1e6,
        "flattened_area_um2": area_px * pixel_m**2 * 1e12,
    }


def _title(name: str, depth) -> str:
    return f"{name}\nflattening {'none' if depth is None else f'{depth * 1e9:.1f} nm deep'}"


def main(
    before_path: str,
    after_path: str,
    fits_path: str,
    k_scan: dict,
    table_path: str,
    figure_paths: list[str],
    afm: dict,
    label: str,
) -> None:
    topo = measure_topography(
        before_path,
        after_path,
        optional_nm_to_m(afm["pixel_nm"]),
        nan_policy=afm["nan_policy"],
        channel=afm["channel"],
        line_levelling=line_levelling_mode(afm["line_levelling"]),
        known_fits=read_sphere_fits(fits_path),  # measure_topography's: no second fit
    )
    best = read_json(k_scan["best"])
    if not is_decided(best):  # the k scan solved nothing: no model to show
        write_undecided_k_scan(best, table_path, figure_paths, label)
        return
    fields, per_load, attrs = read_load_series(grid_best_path(k_scan["rendered"], best))
    last = fields[-1]
    solver_pixel = attrs["pixel_nm"] * 1e-9
    window = window_slices(
        topo.before.roughness.shape,
        topo.pixel_m,
        [c * 1e-6 for c in attrs["window_centre_in_scan_um"]],
        attrs["window_um"] * 1e-6,
    )
    before = topo.before.roughness[window]
    after = topo.after.roughness[window]
    change = topo.change_m[window]
    threshold = topo.flattening.threshold_m
    depth, core, centre = flattened_region(-change, SMOOTHING_PX, threshold)
    # The simulation: h + h_pl minus the fitted sphere, on the solver grid; the same
    # smoothing length and floor as the measurement decide its flattened region.
    deformed = last["deformed_heights"] - sphere_cap(
        last["deformed_heights"].shape, solver_pixel, topo.before.radius_m
    )
    deformed -= np.median(deformed)
    sim_depth, sim_core, sim_centre = flattened_region(
        -last["plastic_displacement"].astype(float),
        SMOOTHING_PX * topo.pixel_m / solver_pixel,
        threshold,
    )
    afm_um = topo.pixel_m * 1e6
    panels = [
        MapPanel(before * 1e9, _title("a) AFM before", depth), core, centre, pixel_um=afm_um),
        MapPanel(after * 1e9, _title("b) AFM after", depth), core, centre, pixel_um=afm_um),
        MapPanel(
            deformed * 1e9,
            _title(f"c) hardening, {grid_best_label(best)}", sim_depth),
            sim_core,
            sim_centre,
            pixel_um=solver_pixel * 1e6,
        ),
    ]
    rows = [
        describe(
            "measured (after - before)", depth, centre, topo.pixel_m, change.shape, int(core.sum())
        ),
        describe(
            "hardening model (h_pl)",
            sim_depth,
            sim_centre,
            solver_pixel,
            sim_core.shape,
            int(sim_core.sum()),
        ),
    ]
    table = pd.DataFrame(rows)
    table["best_k_mpa_per_nm"] = best["grid_best"]
    table["load_mn"] = per_load[-1]["load_mn"]
    write_table(table_path, table)
    log.info("\n%s", table.to_string(index=False))
    plot_height_maps(
        panels,
        f"{label}: AFM before and after the load series, and the hardening model's deformed "
        f"surface at {grid_best_text(best)}; sphere subtracted; outlines: flattened regions, "
        "+: their centres",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        before_path=sm.input.before,
        after_path=sm.input.after,
        fits_path=sm.input.fits,
        k_scan=sm.params.k_scan,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        afm=sm.params.afm,
        label=sm.params.label,
    )
