"""amontons.contact: FFT boundary-element solver for rough frictionless contact.

Self-contained: imports numpy, scipy and (optionally) pyfftw only. SI units throughout:
lengths in m, pressures and moduli in Pa, forces in N.

Sign convention
---------------
* ``heights`` h: the rigid rough indenter; LARGER = CLOSER to the elastic flat, so a sphere
  of radius R touching at its apex is ``h = -r²/(2R)``.
* elastic displacement u: positive INTO the substrate.
* rigid-body approach d: positive when the indenter moves into the substrate.
* gap ``g = u - h - d``; the solution has ``g >= 0`` everywhere and ``g = 0`` where the
  pressure ``p > 0`` (to the solver tolerance).
* periodic solves: the elastic displacement has zero mean (the q = 0 mode is the rigid
  mode, carried by d); non-periodic solves: u is the free half-space displacement, which
  vanishes far away, so d is the absolute approach (Hertz: d = a²/R).

Public API
----------
``solve``, ``solve_load_series``, ``ContactResult``, the plasticity laws
``PenetrationHardness`` and ``ContactHardening`` (:mod:`amontons.contact.plasticity`)
and the exceptions
``ContactInputError``, ``ConvergenceError``, ``FreeBoundaryError``; surface synthesis in
:mod:`amontons.contact.surfaces`.
"""

from .api import solve, solve_load_series
from .plasticity import ContactHardening, PenetrationHardness
from .result import (
    ContactError,
    ContactInputError,
    ContactResult,
    ConvergenceError,
    FreeBoundaryError,
)
from .surfaces import self_affine, sphere

__all__ = [
    "ContactError",
    "ContactHardening",
    "ContactInputError",
    "ContactResult",
    "ConvergenceError",
    "FreeBoundaryError",
    "PenetrationHardness",
    "self_affine",
    "solve",
    "solve_load_series",
    "sphere",
]
