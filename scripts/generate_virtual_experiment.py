"""Rule generate_virtual_experiment: one sphere's raw data (every instrument) with known truth."""

import os
from pathlib import Path

if "snakemake" in globals():
    # The contact solve's BLAS calls spin OpenBLAS threads beyond the rule's (benchmarks/README)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", str(snakemake.threads))  # noqa: F821

from amontons.runlog import run_logged
from amontons.virtual.experiment import generate_sphere
from amontons.virtual.settings import InstrumentSettings, OutputFormats, SurfaceSettings


def main(
    truth_path: str,
    sphere: str,
    diameter_mm: float,
    e_star_gpa: float,
    roughness_rms_nm: float,
    true_model: str,
    true_value: float | None,
    loads_mn: list[float],
    reflection_load_mn: float,
    flim_load_mn: float | None,
    shear_strength_mpa: float,
    pixel_nm: float,
    settings: dict,
    newton_rings: dict,
    seed: int,
    threads: int,
) -> None:
    generate_sphere(
        Path(truth_path).parent,
        sphere=sphere,
        diameter_m=diameter_mm * 1e-3,
        e_star_pa=e_star_gpa * 1e9,
        roughness_rms_m=roughness_rms_nm * 1e-9,
        true_model=true_model,
        true_value=true_value,
        loads_n=[load * 1e-3 for load in loads_mn],
        pixel_m=pixel_nm * 1e-9,
        reflection_load_n=reflection_load_mn * 1e-3,
        flim_load_n=None if flim_load_mn is None else flim_load_mn * 1e-3,
        shear_strength_pa=shear_strength_mpa * 1e6,
        settings=InstrumentSettings.from_config(settings, newton_rings),
        surface=SurfaceSettings.from_config(settings),
        seed=seed,
        threads=threads,
        formats=OutputFormats.from_config(settings),
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        truth_path=sm.output.truth,
        sphere=sm.params.sphere,
        diameter_mm=sm.params.diameter_mm,
        e_star_gpa=sm.params.e_star_gpa,
        roughness_rms_nm=sm.params.roughness_rms_nm,
        true_model=sm.params.true_model,
        true_value=sm.params.true_value,
        loads_mn=sm.params.loads_mn,
        reflection_load_mn=sm.params.reflection_load_mn,
        flim_load_mn=sm.params.flim_load_mn,
        shear_strength_mpa=sm.params.shear_strength_mpa,
        pixel_nm=sm.params.pixel_nm,
        settings=sm.params.settings,
        newton_rings=sm.params.newton_rings,
        seed=sm.params.seed,
        threads=sm.threads,
    )
