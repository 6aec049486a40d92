"""Rule measure_intensity_pressure: mean contact intensity versus mean contact pressure."""

import logging

from amontons.io.files import write_json, write_table
from amontons.io.rawdata import fluorescence_planes
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings
from amontons.measure.intensity import (
    intensity_pressure_record,
    intensity_pressure_table,
    measure_intensity_pressure,
)
from amontons.runlog import run_logged
from amontons.study.plots import plot_intensity_pressure

log = logging.getLogger(__name__)


def main(
    fluorescence,
    table_path: str,
    fit_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float | None,
    images: dict,
    otsu: dict,
    background_margin_px: int,
    pressure_ref_mpa: float,
    confidence: float,
    data_label: str,
    sphere: str,
) -> None:
    paths, choices = fluorescence_planes(fluorescence, loads_mn, images)
    result, backgrounds, excluded = measure_intensity_pressure(
        paths,
        loads_mn,
        optional_nm_to_m(pixel_nm),
        choice=choices,
        otsu=OtsuSettings.from_config(otsu),
        background_margin_px=background_margin_px,
        pressure_ref_pa=pressure_ref_mpa * 1e6,
        confidence=confidence,
    )
    for load, why in excluded.items():
        log.warning("%g mN left out of the intensity-pressure fit: %s", load, why)
    log.info("%s: intensity exponent %.3f", sphere, result.fit.exponent.estimate)
    table = intensity_pressure_table(result, backgrounds)
    write_table(table_path, table)
    write_json(fit_path, intensity_pressure_record(result, excluded))
    plot_intensity_pressure(
        table["mean_pressure_mpa"].to_numpy(),
        table["mean_intensity_counts"].to_numpy(),
        result.fit,
        f"{sphere}: contact intensity versus pressure ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        fluorescence=sm.input.fluorescence,
        table_path=sm.output.table,
        fit_path=sm.output.fit,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        otsu=sm.params.otsu,
        background_margin_px=sm.params.intensity["background_margin_px"],
        pressure_ref_mpa=sm.params.intensity["pressure_ref_mpa"],
        confidence=sm.params.confidence,
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
