"""Rule render_scene: a scene's contact at each load seen like the microscope sees it (emission
law, fluorescence pixel, the PSF measured from the sphere's bead) and thresholded by Otsu."""

import logging

import pandas as pd

from amontons.io.fields import read_load_series, write_load_series
from amontons.io.files import read_json, write_table
from amontons.measure.area import OtsuSettings, image_pixel_m
from amontons.runlog import run_logged
from amontons.simulate.render import render_load_series

log = logging.getLogger(__name__)

RENDER_COLUMNS = [
    "load_mn",
    "rendered_area_um2",
    "solver_area_um2",
    "otsu_threshold",
    "otsu_separation",
    "contact_found",
    "flag",
]


def main(
    fields_path: str,
    psf_path: str,
    rendered_path: str,
    table_path: str,
    pixel_nm: float | None,
    pixel_table: list[str],
    rendering: str,
    confinement_floor_mpa: float,
    otsu: dict,
) -> None:
    fields, per_load, settings = read_load_series(fields_path)
    pixel_m = image_pixel_m(pixel_nm, pixel_table)
    psf_fwhm_m = read_json(psf_path)["fwhm_nm"]["estimate"] * 1e-9
    rendered = []
    if fields:
        rendered = render_load_series(
            fields,
            settings["pixel_nm"] * 1e-9,
            pixel_m=pixel_m,
            psf_fwhm_m=psf_fwhm_m,
            rendering=rendering,
            confinement_floor_pa=confinement_floor_mpa * 1e6,
            otsu=OtsuSettings.from_config(otsu),
        )
    else:
        log.warning("%s: no load simulated (%s); nothing rendered", fields_path, settings["status"])
    rows = []
    for info, render in zip(per_load, rendered, strict=True):
        rows.append(
            {
                "load_mn": info["load_mn"],
                "rendered_area_um2": render.otsu.area_m2 * 1e12,
                "solver_area_um2": info["area_um2"],
                "otsu_threshold": render.otsu.threshold,
                "otsu_separation": render.otsu.separation,
                "contact_found": render.otsu.contact_found,
                "flag": render.otsu.flag or "",
            }
        )
        log.info(
            "%g mN: rendered Otsu area %.1f µm² (solver %.1f µm²)",
            info["load_mn"],
            rows[-1]["rendered_area_um2"],
            info["area_um2"],
        )
    write_load_series(
        rendered_path,
        [{"image": r.image} for r in rendered],
        [
            {"load_mn": info["load_mn"], "otsu_threshold": r.otsu.threshold}
            for info, r in zip(per_load, rendered, strict=True)
        ],
        {
            **settings,
            "image_pixel_nm": pixel_m * 1e9,
            "psf_fwhm_nm": psf_fwhm_m * 1e9,
            "psf_source": psf_path,
            "rendering": rendering,
            "confinement_floor_mpa": confinement_floor_mpa,
        },
    )
    write_table(table_path, pd.DataFrame(rows, columns=RENDER_COLUMNS))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        fields_path=sm.input.fields,
        psf_path=sm.input.psf,
        rendered_path=sm.output.rendered,
        table_path=sm.output.table,
        pixel_nm=sm.params.pixel_nm,
        pixel_table=list(sm.input.pixel_table),
        rendering=sm.params.rendering,
        confinement_floor_mpa=sm.params.confinement_floor_mpa,
        otsu=sm.params.otsu,
    )
