"""The plasticity laws of appendix B.2.3: what a caller passes as ``plasticity=``.

:class:`PenetrationHardness` bounds the pressure by p_Y (Pa); :class:`ContactHardening`
bounds it by k·|h_pl| (k in Pa/m). Each takes local (eq. B.2) or volume-conserving (eq. B.3)
plastic increments with over-relaxation ``alpha``; a law is validated when it is made.

A law carries what the solver asks of it, so that no route tests its type: the route that
solves it exactly with local increments (``exact_route``), how the appendix's root find
starts its approach (``appendix_start``), whether that scheme needs ``alpha < 1``
(``appendix_needs_relaxation``), its pressure bound given the plastic displacement
(:meth:`pressure_bound`) and the most a window can carry under it (:meth:`capacity`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar, Literal

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

    # one bounded CG under the load or approach (docs/models.md §2.3)
    exact_route: ClassVar[str] = "bounded"
    # the root find starts from the elastic solution and the bearing-area approach
    appendix_start: ClassVar[str] = "elastic"
    appendix_needs_relaxation: ClassVar[bool] = False

    def __post_init__(self):
        p_y = np.asarray(self.p_y, dtype=float)
        if not np.all(np.isfinite(p_y)) or np.any(p_y <= 0):
            raise ContactInputError(f"p_y must be finite and > 0 (Pa), got min {p_y.min():.3e}")
        _check_increment(self.increment, self.alpha)

    def pressure_bound(self, shape) -> Callable[[np.ndarray], np.ndarray]:
        """``bound(h_pl)``: the bound p_max per pixel (Pa) on a grid of ``shape``, whatever
        the plastic displacement ``h_pl`` (m)."""
        p_y = np.broadcast_to(np.asarray(self.p_y, dtype=float), shape)
        return lambda h_pl: p_y

    def capacity(self, shape) -> np.ndarray:
        """The most each pixel of a ``shape`` window can carry: p_Y (Pa)."""
        return np.broadcast_to(np.asarray(self.p_y, dtype=float), shape)


@dataclass(frozen=True)
class ContactHardening:
    """Local hardening p_Y = k·|h_pl| with hardening coefficient ``k`` in Pa/m.

    (The appendix's k ≈ 7 MPa/nm for PMMA is 7e15 Pa/m.)
    """

    k: float
    increment: Increment = "local"
    alpha: float = 1.0

    # elastic plus Winkler (docs/models.md §2.4)
    exact_route: ClassVar[str] = "winkler"
    # the root find starts from the Winkler state's approach
    appendix_start: ClassVar[str] = "winkler"
    # with alpha = 1 the first update closes every gap at zero pressure, a fixed point of
    # the scheme that is not the hardening state
    appendix_needs_relaxation: ClassVar[bool] = True

    def __post_init__(self):
        if not (np.isfinite(self.k) and self.k > 0):
            raise ContactInputError(f"k must be finite and > 0 (Pa/m), got {self.k!r}")
        _check_increment(self.increment, self.alpha)

    def pressure_bound(self, shape) -> Callable[[np.ndarray], np.ndarray]:
        """``bound(h_pl)``: p_max = k·max(-h_pl, 0) per pixel (Pa) of the plastic
        displacement ``h_pl`` (m); pile-up (h_pl > 0) has not yielded in compression and
        has no hardness."""
        return lambda h_pl: self.k * np.maximum(-h_pl, 0.0)

    def capacity(self, shape) -> None:
        """None: the bound grows with the plastic depth, so no load is out of reach."""
        return None


PLASTICITY_LAWS = (PenetrationHardness, ContactHardening)


def check_law(law):
    """A plasticity law of :data:`PLASTICITY_LAWS`, else ContactInputError naming it."""
    if not isinstance(law, PLASTICITY_LAWS):
        raise ContactInputError(
            f"plasticity must be PenetrationHardness(p_y) or ContactHardening(k), got {law!r}"
        )
    return law
