"""Rule plot_flattening_maps: appendix Fig. B.9 for one sphere
(amontons.study.flattening_maps): reads the AFM maps before and after (levelled without a
second sphere fit) and the k scan's grid's best rendered series, and writes the figure and
its table."""

import logging

from amontons.io.fields import read_load_series
from amontons.io.files import read_json
from amontons.io.units import optional_nm_to_m
from amontons.measure.scan_lines import line_levelling_mode
from amontons.measure.topography import measure_topography, read_sphere_fits
from amontons.runlog import run_logged
from amontons.simulate.scan_record import is_decided
from amontons.study.figures import grid_best_path, write_undecided_k_scan
from amontons.study.flattening_maps import write_flattening

log = logging.getLogger(__name__)


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
    table = write_flattening(topo, fields, per_load, attrs, best, table_path, figure_paths, label)
    log.info("\n%s", table.to_string(index=False))


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
