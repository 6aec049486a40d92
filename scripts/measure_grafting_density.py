"""Rule measure_grafting_density: probe molecules per µm² from the absorbance spectrum."""

import logging

from amontons.io.files import write_json
from amontons.measure.grafting import measure_grafting_density
from amontons.physics.beer_lambert import M2_PER_MOL_PER_L_PER_MOL_CM
from amontons.runlog import run_logged
from amontons.study.plots import plot_absorbance

log = logging.getLogger(__name__)


def main(
    absorbance_path: str,
    density_path: str,
    figure_paths: list[str],
    lowess_frac: float,
    coated_faces: int,
    epsilon_l_per_mol_cm: float,
    data_label: str,
    sphere: str,
) -> None:
    result = measure_grafting_density(
        absorbance_path,
        frac=lowess_frac,
        n_faces=coated_faces,
        epsilon_m2_per_mol=epsilon_l_per_mol_cm * M2_PER_MOL_PER_L_PER_MOL_CM,
    )
    log.info("%s: %.4g molecules/µm²", absorbance_path, result.density_per_um2)
    write_json(density_path, {**result.to_record(), "spectrum": absorbance_path})
    plot_absorbance(
        result.wavelength_nm,
        result.absorbance,
        result.smoothed,
        result.peak_wavelength_nm,
        result.peak_absorbance,
        result.density_per_um2,
        f"{sphere}: absorbance of the probe cover slip ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        absorbance_path=sm.input.absorbance,
        density_path=sm.output.density,
        figure_paths=[sm.output.png, sm.output.pdf],
        lowess_frac=sm.params.absorbance["lowess_frac"],
        coated_faces=sm.params.absorbance["coated_faces"],
        epsilon_l_per_mol_cm=sm.params.absorbance["epsilon_l_per_mol_cm"],
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
