"""Truths from a solver not our own (docs/study.md §7): a validation truth solved by
ContactMechanics (the ContactEngineering group's boundary-element code, from its release on
the package index) instead of :mod:`amontons.contact`, so that a truth's agreement with the
study is not one code's mesh convergence. ContactMechanics solves the elastic and the
penetration-hardness (its ``PlasticTopography``) contact of a rigid rough indenter on a free
half-space (non-periodic, Hockney-padded, like ours); contact hardening is ours alone.

Its conventions: heights larger toward the substrate (ours too); forces per pixel whose sign
for compression has changed between its releases (negative in its early code, positive in
1.8), so the sign is read off their sum against the load, which they must balance; and a
plastic displacement the plastic system carries from one load to the next while loads step
upward (eq. B.2 of the appendix)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from importlib.metadata import version

import numpy as np
from ContactMechanics import FreeFFTElasticHalfSpace
from ContactMechanics.PlasticSystemSpecialisations import PlasticNonSmoothContactSystem
from ContactMechanics.Systems import NonSmoothContactSystem
from SurfaceTopography import PlasticTopography, Topography

__all__ = [
    "IndependentSolverError",
    "TruthField",
    "compressive_pressure",
    "contactmechanics_load_series",
    "solver_label",
]

# iterations a load may take: ContactMechanics' constrained CG restarts where the contact
# set changes, and a plastic load takes thousands
MAX_ITERATIONS = 100_000
# how closely the truth's forces must carry the load (relative)
LOAD_BALANCE = 1e-6


class IndependentSolverError(RuntimeError):
    """A truth the independent solver did not solve (names the load and why)."""


@dataclass(frozen=True)
class TruthField:
    """One load's truth: pressure (Pa), contact mask, the load (N), the contact area (m²) and
    the mean contact pressure (Pa) over it."""

    pressure: np.ndarray
    contact: np.ndarray
    load: float
    area: float

    @property
    def mean_pressure(self) -> float:
        return self.load / self.area if self.area > 0 else 0.0


def solver_label() -> str:
    """The independent solver and its installed release, as a case records it."""
    return f"ContactMechanics {version('contactmechanics')}"


def contactmechanics_load_series(
    heights_m: np.ndarray,
    pixel_m: float,
    e_star_pa: float,
    loads_n: Sequence[float],
    hardness_pa: float | None,
    tol: float,
) -> list[TruthField]:
    """The rough indenter ``heights_m`` (m, on a square grid of pixel ``pixel_m``) pressed
    onto a free half-space of contact modulus ``e_star_pa`` at each of ``loads_n`` (N,
    increasing) by ContactMechanics, elastic or with a penetration hardness ``hardness_pa``
    (Pa; None: elastic), each load's penetration converged to ``tol`` times the indenter's
    rms height."""
    size = (heights_m.shape[0] * pixel_m, heights_m.shape[1] * pixel_m)
    substrate = FreeFFTElasticHalfSpace(heights_m.shape, e_star_pa, size)
    topography = Topography(np.array(heights_m, dtype=float), size)
    if hardness_pa is None:
        system = NonSmoothContactSystem(substrate, topography)
    else:
        system = PlasticNonSmoothContactSystem(
            substrate, PlasticTopography(topography, hardness_pa)
        )
    pentol = tol * float(np.std(heights_m))
    out = []
    for load in loads_n:
        result = system.minimize_proxy(external_force=load, pentol=pentol, maxiter=MAX_ITERATIONS)
        if not result.success:
            raise IndependentSolverError(
                f"ContactMechanics did not converge at {load * 1e3:g} mN: {result.message}"
            )
        pressure = compressive_pressure(np.asarray(system.force), load, pixel_m)
        contact = pressure > 0
        out.append(TruthField(pressure, contact, float(load), float(contact.sum()) * pixel_m**2))
    return out


def compressive_pressure(forces_n: np.ndarray, load_n: float, pixel_m: float) -> np.ndarray:
    """The pressure (Pa) of ContactMechanics' forces per pixel ``forces_n`` (N) at the load
    ``load_n`` (N): compressive positive, whichever sign the release gives it, and checked to
    balance the load (to 1e-6 of it: the load is imposed by rescaling)."""
    total = float(forces_n.sum())
    pressure = np.clip(np.sign(total) * forces_n, 0.0, None) / pixel_m**2
    carried = float(pressure.sum()) * pixel_m**2
    if abs(carried - load_n) > LOAD_BALANCE * load_n:
        raise IndependentSolverError(
            f"ContactMechanics' forces carry {carried:.6g} N at a load of {load_n:.6g} N; "
            "expected the load"
        )
    return pressure
