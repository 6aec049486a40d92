"""What every virtual instrument reads: one load's contact on its image grid."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ContactState:
    """One load's contact on the image grid (origin at the image centre, square pixels).

    ``pressure_pa``: pressure averaged over each pixel (Pa); ``emission_sqrt_pa``: the probe
    layer's emission (:func:`amontons.virtual.fluorescence.confined_emission`, √Pa) averaged
    over each pixel - what the fluorescence sums, since each molecule responds to its local
    pressure; ``gap_m``: gap at pixel centres
    (m, 0 in contact; None where no instrument needs it); ``contact``: pixels in contact;
    ``area_m2``: the true contact area; ``edge_gap_m``: the average gap at the contact edge
    (m), what the Newton rings extrapolate to (None with ``gap_m``); ``edge_profiles``: the
    true edge of each ray and the gap there (JSON-ready, µm and nm;
    :func:`amontons.virtual.rough_contact.edge_profile_truth`; None with ``gap_m`` and for
    the analytic Hertz sphere, whose edge is a circle).
    """

    load_n: float
    pressure_pa: np.ndarray
    emission_sqrt_pa: np.ndarray
    gap_m: np.ndarray | None
    contact: np.ndarray
    area_m2: float
    edge_gap_m: float | None
    centre_px: tuple[float, float]
    edge_profiles: dict | None = None


def load_index(loads_n, load_n: float) -> int | None:
    """Index of ``load_n`` in ``loads_n`` (N), matched to 1e-9 relative; None if absent."""
    return next(
        (i for i, f in enumerate(loads_n) if np.isclose(f, load_n, rtol=1e-9, atol=0)), None
    )
