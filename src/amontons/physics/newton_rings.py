"""Newton rings: the gap of a bright ring of a given order (appendix eq. B.1;
docs/models.md §1.5)."""

from __future__ import annotations

import numpy as np

# The appendix's set-up (B.1.1): the 488 nm laser line, formamide between the slip and the
# sphere. Defaults of the library calls; the pipeline takes both from its config
# (optics.newton_rings.wavelength_nm, refractive_index).
APPENDIX_WAVELENGTH_M = 488e-9
FORMAMIDE_REFRACTIVE_INDEX = 1.447


def ring_gap(order, wavelength_m: float, n_medium: float) -> np.ndarray:
    """Gap (m) of the bright ring of order m (eq. B.1): d_m = (m + ½)·λ/2n."""
    return (np.asarray(order, dtype=float) + 0.5) * wavelength_m / (2 * n_medium)
