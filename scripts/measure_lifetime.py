"""Rule measure_lifetime: mean photon arrival time inside and outside the contact (FLIM)."""

import json
import logging

from amontons.images import atomic_path
from amontons.measurements import measure_lifetime
from amontons.optics.area import OtsuSettings
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    flim_path: str,
    lifetime_path: str,
    pixel_nm: float,
    otsu: dict,
    exclude_edge_px: int,
) -> None:
    stats = measure_lifetime(
        flim_path,
        pixel_nm * 1e-9,
        otsu=OtsuSettings.from_config(otsu),
        exclude_edge_px=exclude_edge_px,
    )
    result = {
        "quantity": "mean photon arrival time, ns, inside and outside the contact (Otsu mask "
        "of the arrival-time map, edge band excluded)",
        "inside_ns": {
            "mean": stats.inside_mean_ns,
            "sd": stats.inside_sd_ns,
            "standard_error": float(stats.inside_se_ns),
            "n": stats.inside_n,
        },
        "outside_ns": {
            "mean": stats.outside_mean_ns,
            "sd": stats.outside_sd_ns,
            "standard_error": float(stats.outside_se_ns),
            "n": stats.outside_n,
        },
        "exclude_edge_px": exclude_edge_px,
        "map": flim_path,
    }
    log.info(
        "%s: %.3f ns inside, %.3f ns outside",
        flim_path,
        stats.inside_mean_ns,
        stats.outside_mean_ns,
    )
    with atomic_path(lifetime_path) as tmp:
        tmp.write_text(json.dumps(result, indent=2))


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
    )
