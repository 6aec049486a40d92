"""The plasticity laws of appendix B.2.3: what a caller passes as ``plasticity=``.

:class:`PenetrationHardness` bounds the pressure by p_Y (Pa); :class:`ContactHardening`
bounds it by k·|h_pl| (k in Pa/m). Each takes local (eq. B.2) or volume-conserving (eq. B.3)
plastic increments with over-relaxation ``alpha``; a law is validated when it is made.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from .errors import ContactInputError

Increment = Literal["local", "volume"]


def _check_increment(increment: str, alpha: float) -> None:
    if increment not in ("local", "volume"):
        raise ContactInputError(
            f"increment must be 'local' (eq. B.2) or 'volume' (eq. B.3), got {increment!r}"
        )
    if not 0 < alpha <= 1:
        raise ContactInputError(f"over-relaxation alpha must be in (0, 1], got {alpha!r}")
    if increment == "volume" and alpha == 1:
        raise ContactInputError(
            "volume-conserving increments (eq. B.3) need over-relaxation alpha < 1; got 1"
        )


@dataclass(frozen=True)
class PenetrationHardness:
    """Pressure bounded by the penetration hardness ``p_y`` (Pa; scalar or per-pixel array)."""

    p_y: float | np.ndarray
    increment: Increment = "local"
    alpha: float = 1.0

    def __post_init__(self):
        p_y = np.asarray(self.p_y, dtype=float)
        if not np.all(np.isfinite(p_y)) or np.any(p_y <= 0):
            raise ContactInputError(f"p_y must be finite and > 0 (Pa), got min {p_y.min():.3e}")
        _check_increment(self.increment, self.alpha)


@dataclass(frozen=True)
class ContactHardening:
    """Local hardening p_Y = k·|h_pl| with hardening coefficient ``k`` in Pa/m.

    (The appendix's k ≈ 7 MPa/nm for PMMA is 7e15 Pa/m.)
    """

    k: float
    increment: Increment = "local"
    alpha: float = 1.0

    def __post_init__(self):
        if not (np.isfinite(self.k) and self.k > 0):
            raise ContactInputError(f"k must be finite and > 0 (Pa/m), got {self.k!r}")
        _check_increment(self.increment, self.alpha)
