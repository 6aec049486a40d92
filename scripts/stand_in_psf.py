"""Rule stand_in_psf: the config's PSF for a sphere without a bead image, written as that
sphere's psf.json and recorded as a stand-in (config/README.md, optics.psf.stand_in)."""

import logging

from amontons.io.files import write_json
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(psf_path: str, fwhm_nm: float, fwhm_se_nm: float, looked_for: str, sphere: str):
    log.info(
        "%s: %s; the PSF is the config's stand-in, FWHM %.1f ± %.1f nm",
        sphere,
        looked_for,
        fwhm_nm,
        fwhm_se_nm,
    )
    write_json(
        psf_path,
        {
            "quantity": "PSF FWHM, the config's stand-in (optics.psf.stand_in): no bead image",
            "fwhm_nm": {"estimate": fwhm_nm, "standard_error": fwhm_se_nm},
            "source": "config optics.psf.stand_in",
            "bead_image": looked_for,
        },
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        psf_path=sm.output.psf,
        fwhm_nm=sm.params.stand_in["fwhm_nm"],
        fwhm_se_nm=sm.params.stand_in["fwhm_se_nm"],
        looked_for=sm.params.looked_for,
        sphere=sm.wildcards.sphere,
    )
