"""Forward model of a fluorescence-lifetime image: mean photon arrival time, ns (Fig. B.3).

Confined rigidochromic molecules in the contact emit later (1.3 ns for PS on glass) than the
free molecules outside; each pixel's mean arrival time scatters with the photon statistics,
modelled as Gaussian noise of ``noise_ns``. Written as float32 ns, like the FLIM software's
mean-arrival-time map.
"""

from __future__ import annotations

import numpy as np


def render_flim(
    contact_mask: np.ndarray,
    in_contact_ns: float = 1.3,
    outside_ns: float = 0.5,
    noise_ns: float = 0.1,
    *,
    rng: np.random.Generator,
) -> np.ndarray:
    """Mean photon arrival time map (ns, float32) of a contact given as a boolean mask."""
    mask = np.asarray(contact_mask, dtype=bool)
    if noise_ns < 0 or in_contact_ns <= 0 or outside_ns <= 0:
        raise ValueError(
            f"arrival times {in_contact_ns}, {outside_ns} ns must be > 0 and noise {noise_ns} "
            "ns ≥ 0"
        )
    mean = np.where(mask, in_contact_ns, outside_ns)
    return (mean + rng.normal(0.0, noise_ns, mask.shape)).astype(np.float32)
