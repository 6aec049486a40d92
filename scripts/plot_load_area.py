"""Rule plot_load_area: normalised load-area table and figure for one material."""

import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.measure.load_area import normalised_load_area
from amontons.runlog import run_logged
from amontons.study.plots import plot_normalised_load_area


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
    combined = normalised_load_area(
        spheres,
        [pd.read_csv(p) for p in table_paths],
        [read_json(p) for p in fit_paths],
        reference_load_mn,
    )
    write_table(out_table, combined)
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
