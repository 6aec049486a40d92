"""The load–area power law A = A_ref·(F/F_ref)^α of a sphere from its Otsu areas, and the
table of areas normalised by it (appendix Figs. 5.2, B.12; docs/models.md §1.4)."""

from __future__ import annotations

import logging
from collections.abc import Sequence

import pandas as pd

from amontons.power_law import fit_power_law

log = logging.getLogger(__name__)


def fit_load_area(table: pd.DataFrame, reference_load_mn: float, confidence: float) -> dict:
    """JSON-ready record of the power-law fit to a contact_area table (columns load_mn,
    area_um2, contact_found, flag): estimate, standard error and interval of the exponent and
    the prefactor (the area at ``reference_load_mn``, µm²). Loads without a contact are left
    out and listed with their flags."""
    found = table["contact_found"].astype(bool)
    usable = table[found]
    excluded = table.loc[~found, "load_mn"].tolist()
    flags = table.loc[~found, "flag"].tolist()
    if excluded:
        log.warning("loads %s mN excluded (no contact found): %s", excluded, flags)
    fit = fit_power_law(
        usable["load_mn"].to_numpy(),
        usable["area_um2"].to_numpy(),
        x_ref=reference_load_mn,
        confidence=confidence,
    )
    return {
        "quantity": "real contact area versus normal load, A = A_ref (F / F_ref)^exponent",
        "units": {"prefactor": "um2 (area at the reference load)", "x_ref": "mN"},
        "excluded_loads_mn": excluded,
        "exclusion_flags": flags,
        **fit.to_record(),
    }


def reference_area_um2(table: pd.DataFrame, reference_load_mn: float, sphere: str) -> float:
    """The area measured at the reference load (µm²), from a contact_area table; ValueError
    naming the sphere when that load was not measured or its image shows no contact."""
    rows = table[(table["load_mn"] - reference_load_mn).abs() < 1e-9]
    if rows.empty or not bool(rows["contact_found"].iloc[0]):
        why = "was not measured" if rows.empty else f"shows no contact ({rows['flag'].iloc[0]})"
        raise ValueError(
            f"sphere {sphere}: the reference load {reference_load_mn:g} mN "
            f"(load_area.reference_load_mn) {why}; expected a measured contact to normalise by"
        )
    return float(rows["area_um2"].iloc[0])


def normalised_load_area(
    spheres: Sequence[str],
    tables: Sequence[pd.DataFrame],
    fits: Sequence[dict],
    reference_load_mn: float,
) -> pd.DataFrame:
    """Every sphere's areas divided by the area measured at the reference load, as the
    Amontons-deviation table normalises them (appendix Fig. B.13), with the fitted power law
    on the same scale (``fit_norm``: the fit's area at the reference over the measured one)."""
    frames = []
    for sphere, table, fit in zip(spheres, tables, fits, strict=True):
        reference = reference_area_um2(table, reference_load_mn, sphere)
        frames.append(
            pd.DataFrame(
                {
                    "sphere": sphere,
                    "load_mn": table["load_mn"],
                    "area_um2": table["area_um2"],
                    "area_norm": table["area_um2"] / reference,
                    "fit_exponent": fit["exponent"]["estimate"],
                    "fit_norm": fit["prefactor"]["estimate"] / reference,
                    "contact_found": table["contact_found"],
                }
            )
        )
    return pd.concat(frames, ignore_index=True)
