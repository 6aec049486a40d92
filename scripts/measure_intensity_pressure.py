"""Rule measure_intensity_pressure: mean contact intensity versus mean contact pressure."""

import json
import logging

from amontons.images import atomic_path
from amontons.measurements import measure_intensity_pressure
from amontons.optics.area import OtsuSettings
from amontons.plots import plot_intensity_pressure
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    fluorescence_dir: str,
    table_path: str,
    fit_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float,
    otsu: dict,
    background_margin_px: int,
    pressure_ref_mpa: float,
    confidence: float,
    data_label: str,
    sphere: str,
) -> None:
    result, backgrounds, excluded = measure_intensity_pressure(
        fluorescence_dir,
        loads_mn,
        pixel_nm * 1e-9,
        otsu=OtsuSettings.from_config(otsu),
        background_margin_px=background_margin_px,
        pressure_ref_pa=pressure_ref_mpa * 1e6,
        confidence=confidence,
    )
    table = result.table
    out = table.assign(
        load_mN=table["load_N"] * 1e3,
        area_um2=table["area_m2"] * 1e12,
        mean_pressure_MPa=table["mean_pressure_Pa"] * 1e-6,
        background_counts=backgrounds,
    )[["load_mN", "area_um2", "mean_pressure_MPa", "mean_intensity_counts", "background_counts"]]
    with atomic_path(table_path) as tmp:
        out.to_csv(tmp, index=False)
    fit = {
        "quantity": "background-subtracted mean contact intensity versus mean contact pressure "
        "F/A, I = I_ref (p / p_ref)^exponent (appendix Fig. B.4: exponent 1/2)",
        "units": {"prefactor": "counts (intensity at p_ref)", "x_ref": "Pa"},
        **result.fit.to_dict(),
        # images in which no contact stands out have no contact intensity: left out, with why
        "excluded_loads_mN": list(excluded),
        "exclusion_flags": list(excluded.values()),
    }
    for load, why in excluded.items():
        log.warning("%g mN left out of the intensity-pressure fit: %s", load, why)
    log.info("%s: intensity exponent %.3f", fluorescence_dir, result.fit.exponent.estimate)
    with atomic_path(fit_path) as tmp:
        tmp.write_text(json.dumps(fit, indent=2))
    plot_intensity_pressure(
        out["mean_pressure_MPa"].to_numpy(),
        out["mean_intensity_counts"].to_numpy(),
        result.fit,
        f"{sphere}: contact intensity versus pressure ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        fluorescence_dir=sm.params.fluorescence_dir,
        table_path=sm.output.table,
        fit_path=sm.output.fit,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        otsu=sm.params.otsu,
        background_margin_px=sm.params.intensity["background_margin_px"],
        pressure_ref_mpa=sm.params.intensity["pressure_ref_mpa"],
        confidence=sm.params.confidence,
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
