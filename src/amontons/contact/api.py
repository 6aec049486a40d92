"""Public solve calls: :func:`solve` and :func:`solve_load_series`."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence

import numpy as np

from .cg import polonsky_keer
from .convolution import get_operator
from .plasticity import ContactHardening, PenetrationHardness, solve_plastic
from .result import ContactInputError, ContactResult, ConvergenceError, FreeBoundaryError

# Coarse levels stop at this many pixels along the shorter side: below it a solve costs
# nothing and the coarse surface no longer resembles the fine one.
COARSE_MIN_SIZE = 32
# Coarse levels only provide a starting guess, so they are solved loosely.
COARSE_TOL = 1e-4


def _check_positive(name, value, unit):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ContactInputError(f"{name} must be a number in {unit}, got {value!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise ContactInputError(f"{name} must be a finite positive number in {unit}, got {v!r}")
    return v


def _check_heights(heights):
    h = np.asarray(heights)
    if h.ndim != 2:
        raise ContactInputError(f"heights must be a 2-D array (m), got an array of shape {h.shape}")
    if min(h.shape) < 2:
        raise ContactInputError(f"heights must be at least 2x2 pixels, got shape {h.shape}")
    if not np.issubdtype(h.dtype, np.number) or np.iscomplexobj(h):
        raise ContactInputError(f"heights must be real numbers (m), got dtype {h.dtype}")
    h = np.ascontiguousarray(h, dtype=np.float64)
    bad = ~np.isfinite(h)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise ContactInputError(
            f"heights contain {int(bad.sum())} non-finite value(s) (NaN or inf), first at "
            f"pixel ({i}, {j}); expected finite heights in m"
        )
    return h


def _check_warm_start(warm_start, shape):
    w = np.asarray(warm_start, dtype=np.float64)
    if w.shape != shape:
        raise ContactInputError(f"warm_start must have the shape of heights {shape}, got {w.shape}")
    if not np.isfinite(w).all():
        raise ContactInputError("warm_start contains NaN or inf; expected a pressure in Pa")
    if (w < 0).any():
        raise ContactInputError(f"warm_start must be a pressure >= 0 (Pa), min is {w.min():.3e}")
    return w


def _default_max_iter(shape):
    # PK needs O(n) iterations on an n x n grid for rough surfaces (~1200 at 2048²);
    # generous, so hitting the cap means something is wrong, not just slow.
    return 1000 + 4 * (shape[0] + shape[1])


def _start_pressure(h, spacing, e_star, load, displacement):
    """Starting pressure (Pa) without a warm start: uniform under load control (the solver
    rescales it to the load), the overlap guess under displacement control."""
    if load is not None:
        return np.ones_like(h)
    return _initial_pressure(h, spacing, e_star, displacement)


def _initial_pressure(h, spacing, e_star, displacement):
    """Starting pressure (Pa) for displacement control: a local-stiffness overlap guess."""
    overlap = np.maximum(h + displacement, 0.0)
    n = np.count_nonzero(overlap)
    if n == 0:
        return np.zeros_like(h)
    # a patch of size L has stiffness ~E*/L, so p ~ E* overlap / L
    return overlap * (e_star / (math.sqrt(n) * spacing))


def _coarsen(h):
    n0, n1 = h.shape
    return h.reshape(n0 // 2, 2, n1 // 2, 2).mean(axis=(1, 3))


def _coarse_start(
    h, spacing, e_star, load, displacement, periodic, backend, threads, min_size, levels
):
    """Pressure (Pa) on the grid of ``h`` from a solve on a 2x coarser grid, or None.

    Heights are block-averaged 2x2 (spacing doubles); the coarse pressure is prolonged by
    pixel replication, which keeps the total force. Recurses down to ``min_size``.
    """
    n0, n1 = h.shape
    if n0 % 2 or n1 % 2 or min(n0, n1) < 2 * min_size:
        return None, levels
    hc = _coarsen(h)
    start, levels = _coarse_start(
        hc, 2 * spacing, e_star, load, displacement, periodic, backend, threads, min_size, levels
    )
    try:
        res = _solve(
            hc,
            2 * spacing,
            e_star,
            load=load,
            displacement=displacement,
            periodic=periodic,
            tol=COARSE_TOL,
            max_iter=_default_max_iter(hc.shape),
            backend=backend,
            threads=threads,
            warm_start=start,
            check_boundary=False,
            raise_on_failure=False,
        )
    except ConvergenceError:  # pragma: no cover - raise_on_failure=False
        return None, levels
    p = res.pressure
    if not np.isfinite(p).all() or not p.any():
        return None, levels
    levels.append(
        {"shape": hc.shape, "iterations": res.iterations, "convolutions": res.info["convolutions"]}
    )
    return _prolong(p), levels


def _prolong(p):
    """Pixel replication 2x2: keeps the total force and the support of the pressure."""
    return np.repeat(np.repeat(p, 2, axis=0), 2, axis=1)


def solve(
    heights,
    spacing,
    e_star,
    *,
    load=None,
    displacement=None,
    periodic=False,
    tol=1e-8,
    max_iter=None,
    threads=1,
    warm_start=None,
    coarse_to_fine=False,
    backend=None,
    plasticity=None,
    plastic_displacement=None,
    iterative=False,
    max_outer=200,
) -> ContactResult:
    """Solve the frictionless contact of a rigid rough indenter on an elastic half-space.

    Parameters
    ----------
    heights : (n0, n1) array_like
        Indenter heights, m. Larger = closer to the elastic flat (a sphere of radius R is
        ``-r²/(2R)``).
    spacing : float
        Grid spacing (square pixels), m.
    e_star : float
        Contact modulus E*, Pa.
    load : float, optional
        Total normal force, N (> 0). Exactly one of ``load`` and ``displacement``.
    displacement : float, optional
        Rigid-body approach d, m (gap ``g = u - h - d``).
    periodic : bool
        Periodic boundary conditions (nominally flat surfaces) or a free half-space with
        Hockney padding (spheres; contact must stay off the window edge).
    tol : float
        Convergence tolerance on the residual (see :mod:`amontons.contact.cg`).
    max_iter : int, optional
        Iteration cap on the finest grid (default ``1000 + 4(n0 + n1)``).
    threads : int
        FFTW threads.
    warm_start : array_like, optional
        Initial pressure, Pa (e.g. the pressure of a previous, nearby solve).
    coarse_to_fine : bool
        Start from the prolonged solution of the same problem on 2x, 4x, ... coarser grids
        (ignored when ``warm_start`` is given or the shape is odd).
    backend : {"pyfftw", "numpy", None}
        FFT backend; None picks pyfftw when importable.
    plasticity : PenetrationHardness or ContactHardening, optional
        Plasticity law of appendix B.2.3 (None: purely elastic). The result's
        ``plastic_displacement`` is then the plastic displacement of the indenter (m, <= 0
        where material flowed) and ``deformed_heights`` is h + h_pl.
    plastic_displacement : array_like, optional
        Plastic displacement left by earlier loading, m (the history of a load series).
    iterative : bool
        Contact hardening with local increments: force the appendix's iterative scheme
        instead of the exact elastic-plus-Winkler route (used as the test oracle).
    max_outer : int
        Cap on the outer (plastic-update or active-set) iterations of a plastic solve.

    Returns
    -------
    ContactResult

    Raises
    ------
    ContactInputError
        Invalid input (names the value and what was expected).
    ConvergenceError
        No convergence within ``max_iter`` (carries the residual history).
    FreeBoundaryError
        Non-periodic solve with pressure on the outermost ring of the window.
    """
    h = _check_heights(heights)
    spacing = _check_positive("spacing", spacing, "m")
    e_star = _check_positive("e_star", e_star, "Pa")
    if (load is None) == (displacement is None):
        raise ContactInputError(
            "give exactly one of load (N) and displacement (m); got "
            f"load={load!r}, displacement={displacement!r}"
        )
    if load is not None:
        load = _check_positive("load", load, "N")
    else:
        try:
            displacement = float(displacement)
        except (TypeError, ValueError):
            raise ContactInputError(
                f"displacement must be a number in m, got {displacement!r}"
            ) from None
        if not math.isfinite(displacement):
            raise ContactInputError(f"displacement must be finite (m), got {displacement!r}")
    tol = _check_positive("tol", tol, "(dimensionless)")
    if max_iter is not None and (int(max_iter) != max_iter or max_iter < 1):
        raise ContactInputError(f"max_iter must be a positive integer, got {max_iter!r}")
    threads = int(threads)
    if threads < 1:
        raise ContactInputError(f"threads must be >= 1, got {threads}")
    if warm_start is not None:
        warm_start = _check_warm_start(warm_start, h.shape)
    if plasticity is not None:
        return _solve_plastic(
            h,
            spacing,
            e_star,
            _check_law(plasticity),
            load=load,
            displacement=displacement,
            plastic_prev=_check_plastic_history(plastic_displacement, h.shape),
            periodic=bool(periodic),
            tol=tol,
            max_iter=_default_max_iter(h.shape) if max_iter is None else int(max_iter),
            backend=backend,
            threads=threads,
            warm_start=warm_start,
            iterative=bool(iterative),
            max_outer=_check_count("max_outer", max_outer),
        )
    if plastic_displacement is not None:
        raise ContactInputError(
            "plastic_displacement was given without a plasticity law; pass plasticity="
            "PenetrationHardness(...) or ContactHardening(...)"
        )
    return _solve(
        h,
        spacing,
        e_star,
        load=load,
        displacement=displacement,
        periodic=bool(periodic),
        tol=tol,
        max_iter=_default_max_iter(h.shape) if max_iter is None else int(max_iter),
        backend=backend,
        threads=threads,
        warm_start=warm_start,
        coarse_to_fine=coarse_to_fine,
    )


def _solve(
    h,
    spacing,
    e_star,
    *,
    load,
    displacement,
    periodic,
    tol,
    max_iter,
    backend,
    threads,
    warm_start,
    coarse_to_fine=False,
    check_boundary=True,
    raise_on_failure=True,
):
    t0 = time.perf_counter()
    op = get_operator(h.shape, spacing, e_star, periodic=periodic, backend=backend, threads=threads)
    levels = []
    p_init = warm_start
    if p_init is None and coarse_to_fine:
        p_init, levels = _coarse_start(
            h, spacing, e_star, load, displacement, periodic, backend, threads, COARSE_MIN_SIZE, []
        )
    if p_init is None:
        p_init = _start_pressure(h, spacing, e_star, load, displacement)
    h_scale = float(np.std(h))
    if not h_scale > 0:
        h_scale = spacing  # a flat indenter: any length works, the gap is exactly 0
    out = polonsky_keer(
        op,
        h,
        pixel_area=spacing**2,
        h_scale=h_scale,
        p_init=p_init,
        load=load,
        displacement=displacement,
        tol=tol,
        max_iter=max_iter,
        raise_on_failure=raise_on_failure,
    )
    _check_finite("solver", out, tol)
    if check_boundary and not periodic:
        _check_free_boundary(out.pressure, spacing)
    info = {
        "convolutions": out.convolutions,
        "steepest_descent_resets": out.info["steepest_descent_resets"],
        "coarse_levels": levels,
        "backend": op.backend,
        "threads": threads,
        "tol": tol,
        "wall_time_s": time.perf_counter() - t0,
    }
    return _finished(
        h,
        spacing,
        periodic,
        out,
        elastic=out.displacement_field,
        plastic=np.zeros_like(out.pressure),
        displacement=out.rigid_displacement,
        info=info,
    )


def _finished(h, spacing, periodic, outcome, *, elastic, plastic, displacement, info):
    """The ContactResult of a converged solve (``outcome``: a CG or plastic state)."""
    p = outcome.pressure
    return ContactResult(
        pressure=p,
        gap=outcome.gap,
        elastic_displacement=elastic,
        plastic_displacement=plastic,
        contact=p > 0,
        load=float(p.sum()) * spacing**2,
        displacement=displacement,
        spacing=spacing,
        iterations=outcome.iterations,
        residual=outcome.residual,
        residual_history=outcome.history,
        converged=outcome.converged,
        periodic=periodic,
        heights=h,
        info=info,
    )


def _check_finite(what, outcome, tol):
    """Raise ConvergenceError when a solve's pressure or gap holds NaN or inf (never return
    them)."""
    if not (np.isfinite(outcome.pressure).all() and np.isfinite(outcome.gap).all()):
        raise ConvergenceError(
            f"{what} produced non-finite pressure or gap (NaN/inf)",
            iterations=outcome.iterations,
            residual=outcome.residual,
            tol=tol,
            residual_history=outcome.history,
        )


def _check_free_boundary(p, spacing):
    """Raise FreeBoundaryError when pressure reaches the outermost ring of the window."""
    contact = p > 0
    edge = np.zeros_like(contact)
    edge[0, :] = edge[-1, :] = edge[:, 0] = edge[:, -1] = True
    on_edge = contact & edge
    n_edge = int(on_edge.sum())
    if n_edge:
        total = float(p.sum()) * spacing**2
        f_edge = float(p[on_edge].sum()) * spacing**2
        raise FreeBoundaryError(
            f"contact reaches the window edge: {n_edge} edge pixel(s) carry "
            f"{f_edge:.3e} N of {total:.3e} N; the non-periodic solution is only valid "
            "if the pressure vanishes at the edge - enlarge the window or lower the load",
            edge_pixels=n_edge,
            edge_force=f_edge,
        )


def _check_law(law):
    if not isinstance(law, PenetrationHardness | ContactHardening):
        raise ContactInputError(
            f"plasticity must be PenetrationHardness(p_y) or ContactHardening(k), got {law!r}"
        )
    return law


def _check_plastic_history(plastic, shape):
    if plastic is None:
        return np.zeros(shape)
    h_pl = np.asarray(plastic, dtype=np.float64)
    if h_pl.shape != shape:
        raise ContactInputError(
            f"plastic_displacement must have the shape of heights {shape}, got {h_pl.shape}"
        )
    if not np.isfinite(h_pl).all():
        raise ContactInputError("plastic_displacement contains NaN or inf; expected metres")
    return h_pl


def _check_count(name, value):
    if int(value) != value or value < 1:
        raise ContactInputError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def _solve_plastic(
    h,
    spacing,
    e_star,
    law,
    *,
    load,
    displacement,
    plastic_prev,
    periodic,
    tol,
    max_iter,
    backend,
    threads,
    warm_start,
    iterative,
    max_outer,
):
    t0 = time.perf_counter()
    op = get_operator(h.shape, spacing, e_star, periodic=periodic, backend=backend, threads=threads)
    p_init = warm_start
    if p_init is None:
        p_init = _start_pressure(h + plastic_prev, spacing, e_star, load, displacement)
    state = solve_plastic(
        op,
        h,
        spacing,
        law,
        load=load,
        displacement=displacement,
        plastic_prev=plastic_prev,
        p_init=p_init,
        periodic=periodic,
        tol=tol,
        max_iter=max_iter,
        max_outer=max_outer,
        iterative=iterative,
    )
    _check_finite("plastic solve", state, tol)
    if not periodic:
        _check_free_boundary(state.pressure, spacing)
    info = {
        "convolutions": state.convolutions,
        "outer_iterations": state.outer_iterations,
        "plasticity": law,
        "backend": op.backend,
        "threads": threads,
        "tol": tol,
        "wall_time_s": time.perf_counter() - t0,
    }
    return _finished(
        h,
        spacing,
        periodic,
        state,
        elastic=state.elastic_displacement,
        plastic=state.plastic_displacement,
        displacement=state.displacement,
        info=info,
    )


def solve_load_series(
    heights,
    spacing,
    e_star,
    loads: Sequence[float],
    *,
    periodic=False,
    tol=1e-8,
    max_iter=None,
    threads=1,
    coarse_to_fine=False,
    backend=None,
    plasticity=None,
    max_outer=200,
) -> list[ContactResult]:
    """Solve for increasing loads, each step warm-started from the previous pressure.

    Parameters
    ----------
    heights, spacing, e_star, periodic, tol, max_iter, threads, backend
        As in :func:`solve`.
    loads : sequence of float
        Total forces, N; strictly increasing and positive.
    coarse_to_fine : bool
        Coarse-to-fine start for the first load only (later loads are warm-started;
        ignored with plasticity).
    plasticity : PenetrationHardness or ContactHardening, optional
        Plasticity law; each load step starts from the plastic displacement and the
        pressure of the previous one, so the series carries the plastic history.
    max_outer : int
        As in :func:`solve`.

    Returns
    -------
    list of ContactResult, one per load.
    """
    arr = np.asarray(loads, dtype=float)
    if arr.ndim != 1 or arr.size == 0:
        raise ContactInputError(f"loads must be a non-empty 1-D sequence (N), got {loads!r}")
    if not np.isfinite(arr).all() or (arr <= 0).any():
        raise ContactInputError(f"loads must be finite and positive (N), got {arr.tolist()}")
    if arr.size > 1 and (np.diff(arr) <= 0).any():
        raise ContactInputError(f"loads must be strictly increasing (N), got {arr.tolist()}")
    results = []
    prev = None
    for i, w in enumerate(arr):
        # scale the previous field to the new load: right total, right shape to first order
        start = None if prev is None else prev.pressure * (w / prev.load)
        res = solve(
            heights,
            spacing,
            e_star,
            load=float(w),
            periodic=periodic,
            tol=tol,
            max_iter=max_iter,
            threads=threads,
            warm_start=start,
            coarse_to_fine=coarse_to_fine and i == 0 and plasticity is None,
            backend=backend,
            plasticity=plasticity,
            plastic_displacement=None
            if prev is None or plasticity is None
            else prev.plastic_displacement,
            max_outer=max_outer,
        )
        results.append(res)
        prev = res
    return results
