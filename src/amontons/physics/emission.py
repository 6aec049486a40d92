"""Emission law of the rigidochromic probe (appendix Fig. B.4; docs/models.md §1.2)."""

from __future__ import annotations

import numpy as np


def confined_emission(pressure_pa: np.ndarray, contact: np.ndarray, floor_pa: float) -> np.ndarray:
    """Emission (√Pa) of the probe layer: √max(p, ``floor_pa``) where ``contact``, else 0.

    Molecules light up where they are confined in the contact and brighten as √(local
    pressure); a molecule trapped in the contact stays confined where the pressure vanishes,
    so ``floor_pa`` (the confinement floor p_c, ≥ 0) bounds its emission from below.
    """
    if floor_pa < 0:
        raise ValueError(f"confinement floor {floor_pa:g} Pa is negative; expected >= 0")
    return np.where(contact, np.sqrt(np.maximum(pressure_pa, floor_pa)), 0.0)
