"""Rule fit_load_area: power law A = A_ref·(F/F_ref)^α for one sphere."""

import json
import logging

import pandas as pd

from amontons.images import atomic_path
from amontons.powerlaw import fit_power_law
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(table_path: str, fit_path: str, reference_load_mn: float, confidence: float) -> None:
    table = pd.read_csv(table_path)
    found = table["contact_found"].astype(bool)
    usable = table[found]
    excluded = table.loc[~found, "load_mN"].tolist()
    flags = table.loc[~found, "flag"].tolist()
    if excluded:
        log.warning("%s: loads %s mN excluded (no contact found): %s", table_path, excluded, flags)
    fit = fit_power_law(
        usable["load_mN"].to_numpy(),
        usable["area_um2"].to_numpy(),
        x_ref=reference_load_mn,
        confidence=confidence,
    )
    result = {
        "quantity": "real contact area versus normal load, A = A_ref (F / F_ref)^exponent",
        "units": {"prefactor": "um2 (area at the reference load)", "x_ref": "mN"},
        "excluded_loads_mN": excluded,
        "exclusion_flags": flags,
        **fit.to_dict(),
    }
    log.info(
        "%s: exponent %.4f ± %.4f", table_path, fit.exponent.estimate, fit.exponent.standard_error
    )
    with atomic_path(fit_path) as tmp:
        tmp.write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        table_path=sm.input.table,
        fit_path=sm.output.fit,
        reference_load_mn=sm.params.load_area["reference_load_mn"],
        confidence=sm.params.load_area["confidence"],
    )
