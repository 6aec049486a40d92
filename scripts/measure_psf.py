"""Rule measure_psf: PSF FWHM from the bead image of one sphere, and its radial profile."""

import logging

from amontons.io.confocal import ImageChoice
from amontons.io.files import write_json
from amontons.io.units import optional_nm_to_m
from amontons.measure.psf import measure_bead
from amontons.runlog import run_logged
from amontons.study.plots import plot_psf_profile

log = logging.getLogger(__name__)


def main(
    bead_path: str,
    psf_path: str,
    figure_paths: list[str],
    pixel_nm: float | None,
    images: dict,
    profile_radius_nm: float,
    centroid_radius_nm: float,
    data_label: str,
    sphere: str,
) -> None:
    psf = measure_bead(
        bead_path,
        optional_nm_to_m(pixel_nm),
        choice=ImageChoice(**images),
        profile_radius_m=profile_radius_nm * 1e-9,
        centroid_radius_m=centroid_radius_nm * 1e-9,
    )
    log.info("%s: FWHM %.1f ± %.1f nm", bead_path, psf.fwhm_m * 1e9, psf.fwhm_se_m * 1e9)
    write_json(psf_path, {**psf.to_record(), "image": bead_path})
    plot_psf_profile(
        psf.profile_r_m * 1e9,
        psf.profile_counts,
        psf.fwhm_m * 1e9,
        psf.fwhm_se_m * 1e9,
        psf.peak_counts,
        psf.background_counts,
        f"{sphere}: bead radial profile ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        bead_path=sm.input.bead,
        psf_path=sm.output.psf,
        figure_paths=[sm.output.png, sm.output.pdf],
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        profile_radius_nm=sm.params.psf["profile_radius_nm"],
        centroid_radius_nm=sm.params.psf["centroid_radius_nm"],
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
