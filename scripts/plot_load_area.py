"""Rule plot_load_area: normalised load-area table and figure for one material."""

import json

import pandas as pd

from amontons.images import atomic_path
from amontons.plots import plot_normalised_load_area
from amontons.runlog import run_logged


def main(
    spheres: list[str],
    table_paths: list[str],
    fit_paths: list[str],
    out_table: str,
    figure_paths: list[str],
    data_label: str,
    material: str,
    reference_load_mn: float,
) -> None:
    frames = []
    for sphere, table_path, fit_path in zip(spheres, table_paths, fit_paths, strict=True):
        table = pd.read_csv(table_path)
        with open(fit_path) as stream:
            fit = json.load(stream)
        frames.append(
            pd.DataFrame(
                {
                    "sphere": sphere,
                    "load_mN": table["load_mN"],
                    "area_um2": table["area_um2"],
                    # Normalised by the fitted area at the reference load, defined for any series.
                    "area_norm": table["area_um2"] / fit["prefactor"]["estimate"],
                    "fit_exponent": fit["exponent"]["estimate"],
                    "contact_found": table["contact_found"],
                }
            )
        )
    combined = pd.concat(frames, ignore_index=True)
    with atomic_path(out_table) as tmp:
        combined.to_csv(tmp, index=False)
    plot_normalised_load_area(
        combined,
        f"{material}: real contact area vs load ({data_label})",
        figure_paths,
        reference_load_mn,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        spheres=sm.params.spheres,
        table_paths=list(sm.input.tables),
        fit_paths=list(sm.input.fits),
        out_table=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        data_label=sm.params.data_label,
        material=sm.wildcards.material,
        reference_load_mn=sm.params.reference_load_mn,
    )
