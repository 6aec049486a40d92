"""amontons.contact: FFT boundary-element solver for rough frictionless contact.

Self-contained: it imports numerical libraries only (numpy, scipy, numba for the fused
kernels, threadpoolctl to bound the native thread pools, and optionally pyfftw), nothing
else of amontons. Built in six floors (docs/models.md §2.0). SI units throughout:
lengths in m, pressures and moduli in Pa, forces in N. The models and their equations are
described in docs/models.md (§2.1 sign conventions and Green's functions, §2.2 the bounded
Polonsky–Keer conjugate gradient, §2.3 penetration hardness, §2.4 contact hardening,
§2.5 Greenwood–Tripp, §2.6 self-affine surfaces, §2.7 analytic checks).

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
``solve(heights, spacing, e_star, *, load | displacement, periodic, tol, max_iter, threads,
warm_start, coarse_to_fine, backend, plasticity, plastic_displacement, method, max_outer,
planner_effort, raise_on_failure) -> ContactResult``, ``solve_load_series(heights,
spacing, e_star, loads, *, ..., warm_starts) -> list[ContactResult]`` and ``solve_scan(heights,
spacing, e_star, loads, laws, **options) -> list[list[ContactResult]]`` (one load series per
law, each warm-started from the previous law's); the plasticity laws
``PenetrationHardness(p_y)`` and ``ContactHardening(k)`` (:mod:`amontons.contact.laws`);
surface synthesis ``sphere`` and ``self_affine`` (:mod:`amontons.contact.surfaces`).

Result (:class:`ContactResult`, frozen; ``==`` is identity)
    Fields ``pressure`` (Pa), ``gap``, ``elastic_displacement``, ``plastic_displacement``
    (m), ``contact`` (bool mask), ``load`` (N), ``displacement`` (m), ``spacing`` (m),
    ``iterations``, ``residual``, ``residual_history``, ``success``, ``status``,
    ``message``, ``periodic``, ``heights`` (m), ``info``; properties ``area`` (m²),
    ``contact_fraction``, ``mean_pressure`` (Pa), ``deformed_heights`` (m) and
    ``converged`` (read-only alias of ``success``).

Status codes (``ContactResult.status``, ``ConvergenceError.status``)
    0 converged; 1 iteration cap reached (``max_iter`` CG iterations, or ``max_outer``
    plastic updates / active-set rounds); 2 stalled (e.g. a periodic displacement-controlled
    solve at full contact, or the load control of a plastic solve finding no approach). By
    default a solve that does not converge raises :class:`ConvergenceError`; with
    ``raise_on_failure=False`` it returns the last (finite) iterate with ``success=False``,
    its status and a message naming the iterations and the residual.
    :class:`ContactInputError` is raised always, and so is :class:`FreeBoundaryError` for a
    converged solution (a non-converged iterate's edge pressure is not checked).

Diagnostics (``ContactResult.info``: :class:`SolveInfo`, frozen, the same fields on every route)
    ``route`` ("elastic", "winkler", "bounded" or "appendix"), ``convolutions``,
    ``steepest_descent_resets``, ``outer_iterations`` (0 for elastic solves),
    ``coarse_levels`` (tuple of :class:`CoarseLevel`), ``plasticity``, ``backend``,
    ``threads``, ``planner_effort``, ``tol``, ``max_iter``, ``max_outer`` (None for elastic
    solves and the "bounded" route), ``wall_time_s`` (s).

Options
    ``method``: route of a plastic solve, ``"winkler"`` (contact hardening with local
    increments, exact elastic-plus-Winkler; the default there), ``"bounded"`` (penetration
    hardness with local increments, one bounded CG under the force constraint; the default
    there) or ``"appendix"`` (the appendix's iterative scheme; the only route for
    volume-conserving increments); None picks the default. ``planner_effort``: FFTW
    planner effort; None (default) is ``"FFTW_MEASURE"``, whose plans are timed once per
    machine and kept on disk as FFTW wisdom (:mod:`amontons.contact.wisdom`), so every
    process uses the same plans and gives the same bytes; ``"FFTW_ESTIMATE"`` plans
    without timing or disk (slower FFTs). An unknown value of either raises
    :class:`ContactInputError` naming the allowed values.

Warnings
    :class:`IgnoredOptionWarning` (a ``UserWarning``), once per call, for an option given
    to a solve that has no effect on it: ``method`` or ``max_outer`` on an elastic solve,
    ``max_outer`` on the "bounded" route;
    ``coarse_to_fine=True`` with plasticity, with a ``warm_start`` or on a grid without a
    coarse level; ``threads > 1`` or a non-default ``planner_effort`` with a backend other
    than pyfftw.

Exceptions
    ``ContactError`` (base) with ``ContactInputError`` (also a ValueError),
    ``ConvergenceError`` and ``FreeBoundaryError`` (also RuntimeErrors), and
    ``amontons.contact.greenwood_tripp.GreenwoodTrippError`` (also a RuntimeError; not
    imported here, to keep ``import amontons.contact`` free of the Greenwood–Tripp tables'
    scipy modules).
"""

from .api import solve, solve_load_series, solve_scan
from .errors import (
    BackendUnavailableError,
    ContactError,
    ContactInputError,
    ConvergenceError,
    FreeBoundaryError,
    IgnoredOptionWarning,
)
from .laws import ContactHardening, PenetrationHardness
from .result import CoarseLevel, ContactResult, SolveInfo
from .surfaces import self_affine, sphere

__all__ = [
    "BackendUnavailableError",
    "CoarseLevel",
    "ContactError",
    "ContactHardening",
    "ContactInputError",
    "ContactResult",
    "ConvergenceError",
    "FreeBoundaryError",
    "IgnoredOptionWarning",
    "PenetrationHardness",
    "SolveInfo",
    "self_affine",
    "solve",
    "solve_load_series",
    "solve_scan",
    "sphere",
]
