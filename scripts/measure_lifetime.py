"""Rule measure_lifetime: mean photon arrival time inside and outside the contact (FLIM)."""

import logging

from amontons.io.files import write_json
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings
from amontons.measure.lifetime import measure_lifetime
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    flim_path: str,
    lifetime_path: str,
    pixel_nm: float | None,
    otsu: dict,
    exclude_edge_px: int,
    channel: int | None,
    irf_peak_ns: float | None,
) -> None:
    """``channel`` and ``irf_peak_ns`` apply to a PTU file only (config optics.lifetime)."""
    stats = measure_lifetime(
        flim_path,
        optional_nm_to_m(pixel_nm),
        otsu=OtsuSettings.from_config(otsu),
        exclude_edge_px=exclude_edge_px,
        channel=channel,
        irf_peak_ns=irf_peak_ns,
    )
    log.info(
        "%s: %.3f ns inside, %.3f ns outside",
        flim_path,
        stats.inside_mean_ns,
        stats.outside_mean_ns,
    )
    write_json(lifetime_path, {**stats.to_record(exclude_edge_px), "map": flim_path})


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        flim_path=sm.input.flim,
        lifetime_path=sm.output.lifetime,
        pixel_nm=sm.params.pixel_nm,
        otsu=sm.params.otsu,
        exclude_edge_px=sm.params.lifetime["exclude_edge_px"],
        channel=sm.params.lifetime["channel"],
        irf_peak_ns=sm.params.lifetime["irf_peak_ns"],
    )
