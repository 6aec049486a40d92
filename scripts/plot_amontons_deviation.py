"""Rule plot_amontons_deviation: area and static friction versus load, normalised at the
reference load, for the spheres of one material (appendix Fig. B.13)."""

import pandas as pd

from amontons.io.files import write_table
from amontons.measure.friction import amontons_table
from amontons.runlog import run_logged
from amontons.study.plots import plot_amontons_deviation


def main(
    spheres: list[str],
    area_paths: list[str],
    friction_paths: list[str],
    out_table: str,
    figure_paths: list[str],
    data_label: str,
    material: str,
    reference_load_mn: float,
) -> None:
    table = amontons_table(
        spheres,
        [pd.read_csv(p) for p in area_paths],
        [pd.read_csv(p) for p in friction_paths],
        reference_load_mn,
    )
    write_table(out_table, table)
    plot_amontons_deviation(
        table,
        f"{material}: deviation from Amontons' law ({data_label})",
        figure_paths,
        reference_load_mn,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        spheres=sm.params.spheres,
        area_paths=list(sm.input.areas),
        friction_paths=list(sm.input.friction),
        out_table=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        data_label=sm.params.data_label,
        material=sm.wildcards.material,
        reference_load_mn=sm.params.reference_load_mn,
    )
