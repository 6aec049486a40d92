"""Rule plot_amontons_study: appendix Fig. B.13 across materials. Contact area and static
friction over their values at the reference load, against load, for every sphere of every
selected material, with each sphere's hardening model at the k scan's grid's best k (the
scanned value of least distance, docs/study.md §1)."""

import logging

import numpy as np
import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.models import CONTACT_HARDENING
from amontons.runlog import run_logged
from amontons.simulate.scan_record import is_decided
from amontons.study.figures import BEST_K, plot_normalised_study

log = logging.getLogger(__name__)


def main(amontons_paths, best_paths: dict, table_path, figure_paths, reference_load_mn, label):
    measured, models, records = {}, {}, []
    for path in amontons_paths:
        table = pd.read_csv(path)
        for sphere, rows in table.groupby("sphere", sort=False):
            x = rows["normal_force_mn"].to_numpy() / reference_load_mn
            measured[sphere] = (
                x,
                rows["area_over_area_ref"].to_numpy(),
                rows["friction_over_friction_ref"].to_numpy(),
            )
            records += [
                {
                    "sphere": sphere,
                    "series": "measured",
                    "load_over_ref": xi,
                    "area_over_ref": a,
                    "friction_over_ref": s,
                    BEST_K: None,
                }
                for xi, a, s in zip(x, *measured[sphere][1:], strict=True)
            ]
    for sphere, path in best_paths.items():
        best = read_json(path)
        if not is_decided(best):
            log.warning(
                "%s: the k scan was not decided (%s); not drawn", sphere, best["not_decided"]
            )
            continue
        loads = np.array([r["load_mn"] for r in best["best_loads"]])
        areas = np.array([r["simulated_area_um2"] for r in best["best_loads"]])
        if not np.any(np.isclose(loads, reference_load_mn)):
            log.warning("%s: the model has no load at %g mN; not drawn", sphere, reference_load_mn)
            continue
        reference = areas[np.isclose(loads, reference_load_mn)][0]
        models[sphere] = (loads / reference_load_mn, areas / reference)
        records += [
            {
                "sphere": sphere,
                "series": f"{CONTACT_HARDENING.name} model",
                "load_over_ref": xi,
                "area_over_ref": a,
                "friction_over_ref": None,
                BEST_K: best["grid_best"],
            }
            for xi, a in zip(*models[sphere], strict=True)
        ]
    write_table(table_path, pd.DataFrame(records))
    plot_normalised_study(
        measured,
        models,
        reference_load_mn,
        f"Deviation from Amontons' law, normalised at {reference_load_mn:g} mN ({label}); "
        "lines: hardening model at each sphere's grid's best k",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        amontons_paths=list(sm.input.amontons),
        best_paths=sm.params.bests,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        reference_load_mn=sm.params.reference_load_mn,
        label=sm.params.data_label,
    )
