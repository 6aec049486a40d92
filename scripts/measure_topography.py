"""Rule measure_topography: the sphere's AFM scans levelled, their roughness and the flattening."""

import logging

from amontons.io.files import write_json
from amontons.io.units import optional_nm_to_m
from amontons.measure.scan_lines import line_levelling_mode
from amontons.measure.topography import measure_topography, read_fit_record, write_sphere_fits
from amontons.runlog import run_logged
from amontons.study.plots import plot_topography

log = logging.getLogger(__name__)


def main(
    before_path: str,
    after_path: str,
    before_fit_path: str,
    topography_path: str,
    fits_path: str,
    figure_paths: list[str],
    afm_pixel_nm: float | None,
    nan_policy: str,
    channel: str | None,
    line_levelling: str | bool,
    data_label: str,
    sphere: str,
) -> None:
    topo = measure_topography(
        before_path,
        after_path,
        optional_nm_to_m(afm_pixel_nm),
        nan_policy=nan_policy,
        channel=channel,
        line_levelling=line_levelling_mode(line_levelling),
        # level_afm_map's fit of the same before scan: only the after scan is fitted here
        known_fits=(read_fit_record(before_fit_path, "before"), None),
    )
    flattening = topo.flattening
    log.info(
        "%s: R = %.3f mm, h_rms %.1f nm, h' %.3f, flattening %s nm (%s); lines levelled: "
        "before %s, after %s",
        sphere,
        topo.before.radius_m * 1e3,
        topo.before_statistics.h_rms_m * 1e9,
        topo.before_statistics.slope_rms,
        "none" if flattening.depth_m is None else f"{flattening.depth_m * 1e9:.2f}",
        flattening.flag or "resolved",
        topo.before.line_levelling.applied,
        topo.after.line_levelling.applied,
    )
    write_json(topography_path, topo.to_record())
    write_sphere_fits(fits_path, topo)
    plot_topography(
        topo.before.roughness * 1e9,
        topo.after.roughness * 1e9,
        topo.change_m * 1e9,
        topo.pixel_m * 1e6,
        f"{sphere}: AFM before and after the load series ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        before_path=sm.input.before,
        after_path=sm.input.after,
        before_fit_path=sm.input.before_fit,
        topography_path=sm.output.topography,
        fits_path=sm.output.fits,
        figure_paths=[sm.output.png, sm.output.pdf],
        afm_pixel_nm=sm.params.afm_pixel_nm,
        nan_policy=sm.params.nan_policy,
        channel=sm.params.channel,
        line_levelling=sm.params.line_levelling,
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
