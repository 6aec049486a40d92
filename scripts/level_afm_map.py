"""Rule level_afm_map: a sphere's AFM map before contact, levelled once for all its scenes."""

import logging

from amontons.io.fields import write_levelled_map
from amontons.io.units import optional_nm_to_m
from amontons.measure.scan_lines import line_levelling_mode
from amontons.measure.topography import write_fit_records
from amontons.runlog import run_logged
from amontons.simulate.surface import read_and_fit_afm_map

log = logging.getLogger(__name__)


def main(afm_before: str, levelled_path: str, fit_path: str, afm: dict) -> None:
    levelled, fit = read_and_fit_afm_map(
        afm_before,
        fallback_pixel_m=optional_nm_to_m(afm["pixel_nm"]),
        nan_policy=afm["nan_policy"],
        channel=afm["channel"],
        line_levelling=line_levelling_mode(afm["line_levelling"]),
    )
    log.info(
        "%s: %d × %d px of %.1f nm, fitted radius %.4f mm",
        afm_before,
        *levelled.heights_m.shape,
        levelled.pixel_m * 1e9,
        levelled.radius_m * 1e3,
    )
    write_levelled_map(
        levelled_path,
        levelled.heights_m,
        levelled.pixel_m,
        {**levelled.to_attributes(), "source": afm_before},
    )
    # measure_topography levels the same scan by this fit (the same map, read the same way)
    write_fit_records(fit_path, {"before": fit})


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        afm_before=sm.input.afm_before,
        levelled_path=sm.output.levelled,
        fit_path=sm.output.fit,
        afm=sm.params.afm,
    )
