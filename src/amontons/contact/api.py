"""The public calls: :func:`solve`, :func:`solve_load_series` and :func:`solve_scan`.

The top floor: validates the inputs once into :class:`~.options.SolveOptions` and a
:class:`~.options.LoadStep`, bounds the native thread pools for the call, runs the route
(:mod:`.routes`) and turns its Outcome into a :class:`~.result.ContactResult` after the
checks that make failure loud (non-convergence, non-finite fields, pressure on the window
edge).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence

import numpy as np

from .elastic import COARSE_MIN_SIZE, finite, has_coarse_level
from .errors import (
    STALLED,
    ContactError,
    ContactInputError,
    ConvergenceError,
    FreeBoundaryError,
    IgnoredOptionWarning,
)
from .options import (
    DEFAULT_PLANNER_EFFORT,
    LoadStep,
    SolveOptions,
    check_control,
    check_heights,
    check_loads,
    check_plastic_history,
    check_positive,
    check_warm_start,
    solve_options,
)
from .pools import solve_pools
from .result import ContactResult, SolveInfo
from .routes import check_capacity, run_route


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
    method=None,
    max_outer=None,
    planner_effort=None,
    raise_on_failure=True,
    iteration="polonsky-keer",
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
        Convergence tolerance on the residual (dimensionless, see :mod:`amontons.contact.cg`).
    max_iter : int, optional
        Conjugate-gradient iteration cap per solve on the finest grid (default
        ``1000 + 4(n0 + n1)``).
    threads : int or None
        Threads of the solve: the transforms as ``threads`` slabs at once
        (:mod:`amontons.contact.fft`), the numba kernels on ``threads`` (capped at the grid's
        chunks); None: every core this process may use (its CPU affinity). The numpy FFT
        backend is serial (a warning says so). The native pools are bounded for the call and
        given back after it (:mod:`amontons.contact.pools`). A second thread pays from about
        512² (benchmarks/README.md, "A second core").
    warm_start : array_like, optional
        Initial pressure, Pa (e.g. the pressure of a previous, nearby solve).
    coarse_to_fine : bool
        Elastic solves: start from the prolonged solution of the same problem on 2x, 4x, ...
        coarser grids. Ignored, with an :class:`IgnoredOptionWarning`, with plasticity, with
        a ``warm_start``, or when the grid has no coarse level (a side odd or below
        ``2 * COARSE_MIN_SIZE`` = 64 pixels).
    backend : {"pyfftw", "numpy", "cupy", None}
        ``"pyfftw"``, ``"numpy"``: the CPU solver (numba kernels) with that FFT backend;
        None picks pyfftw when importable. ``"cupy"``: the same Polonsky–Keer loop on the
        GPU (:mod:`amontons.contact.array_kernels`; ``pip install amontons[gpu]``), results
        as numpy arrays; without CuPy or a CUDA device it raises
        :class:`BackendUnavailableError`. (``"numpy-array"``: the GPU route's code on numpy,
        for tests; ``"cupy-array"``, ``"cupy-terms"``: its earlier versions, baselines.)
    plasticity : PenetrationHardness or ContactHardening, optional
        Plasticity law of appendix B.2.3 (None: purely elastic). The result's
        ``plastic_displacement`` is then the plastic displacement of the indenter (m, <= 0
        where material flowed) and ``deformed_heights`` is h + h_pl.
    plastic_displacement : array_like, optional
        Plastic displacement left by earlier loading, m (the history of a load series).
    method : {"winkler", "bounded", "appendix", None}
        Route of a plastic solve. ``"winkler"``: contact hardening, local increments solved
        exactly as an elastic half-space plus a Winkler layer (docs/models.md §2.4);
        ``"bounded"``: penetration hardness, local increments in one bounded CG
        (0 <= p <= p_Y), the plastic displacement the penetration where p = p_Y
        (docs/models.md §2.3); ``"appendix"``: the appendix's iterative scheme (needs
        ``alpha < 1`` for contact hardening). None: ``"winkler"`` or ``"bounded"`` where
        they apply, else ``"appendix"`` (volume-conserving increments). Ignored, with a
        warning, by an elastic solve.
    max_outer : int, optional
        Cap on the outer loop of a plastic solve: plastic updates per approach
        (``"appendix"``, default 200) or active-set rounds (``"winkler"``, default 50).
        Ignored, with a warning, by an elastic solve and by the ``"bounded"`` route (no
        outer loop).
    planner_effort : str, optional
        FFTW planner effort, one of "FFTW_ESTIMATE", "FFTW_MEASURE", "FFTW_PATIENT",
        "FFTW_EXHAUSTIVE". None (default): ``"FFTW_MEASURE"``, each plan timed once per
        machine and kept on disk as FFTW wisdom that every later process imports, so the
        same plan and the same result bytes in every run on the machine
        (:mod:`amontons.contact.wisdom` says where); faster than ESTIMATE's heuristic plans
        (benchmarks/README.md, "FFTW planner effort"). Another thread count's plan differs
        in round-off only (1e-10). Ignored, with a warning, by the numpy backend.
    raise_on_failure : bool
        True (default): a solve that does not converge raises :class:`ConvergenceError`.
        False: it returns a :class:`ContactResult` with ``success=False``, its ``status``
        (1 iteration cap, 2 stalled) and ``message``, holding the last (finite) iterate.
    iteration : {"polonsky-keer", "preconditioned"}
        CG iteration of the elastic, bounded and Winkler routes: Polonsky and Keer's, or the
        preconditioned bound-constrained CG (CPU backends; docs/models.md §2.2).

    Returns
    -------
    ContactResult

    Raises
    ------
    ContactInputError
        Invalid input (names the value and what was expected), always.
    ConvergenceError
        No convergence (carries the residual history and ``status``), unless
        ``raise_on_failure=False``; a solve whose fields hold NaN or inf raises always.
    FreeBoundaryError
        Converged non-periodic solution with pressure on the outermost ring of the window,
        whatever ``raise_on_failure`` (a non-converged iterate is not checked: its edge
        pressure says nothing about the window).

    Warns
    -----
    IgnoredOptionWarning
        An option was given that has no effect on this solve (see the options above).
    """
    h, spacing, e_star, opts = _checked_problem(
        heights,
        spacing,
        e_star,
        periodic=periodic,
        tol=tol,
        max_iter=max_iter,
        threads=threads,
        backend=backend,
        planner_effort=planner_effort,
        plasticity=plasticity,
        method=method,
        max_outer=max_outer,
        raise_on_failure=raise_on_failure,
        iteration=iteration,
    )
    step = _checked_step(
        opts, h.shape, (load, displacement, warm_start, plastic_displacement), coarse_to_fine
    )
    given = {"method": method, "max_outer": max_outer, "coarse_to_fine": coarse_to_fine}
    _warn_ignored(opts, h.shape, **given, warm_start=step.warm_start is not None)
    # BLAS pools on one thread, the kernels' OpenMP on ``threads`` (.pools says why)
    with solve_pools(opts.threads):
        return _solve_step(h, spacing, e_star, opts, step)


def _checked_step(opts, shape, given, coarse_to_fine) -> LoadStep:
    """The validated :class:`LoadStep` of one solve from what :func:`solve` was given:
    ``(load N, displacement m, warm start Pa, plastic displacement m)``."""
    load, displacement, warm_start, plastic_displacement = given
    load, displacement = check_control(load, displacement)
    if warm_start is not None:
        warm_start = check_warm_start(warm_start, shape)
    plastic_prev = _plastic_history(opts, plastic_displacement, shape)
    return LoadStep(load, displacement, warm_start, plastic_prev, bool(coarse_to_fine))


def solve_with_options(
    heights, spacing, e_star, opts: SolveOptions, *, load=None, displacement=None
):
    """One cold solve under options already validated (:func:`.inputs.solve_options`, then
    perhaps :func:`dataclasses.replace`): how a test selects a kernel set that
    :func:`solve` does not offer (``bounded_load_sweep=False``). Units as :func:`solve`;
    no warm start, no plastic history, no coarse-to-fine start."""
    h = check_heights(heights)
    load, displacement = check_control(load, displacement)
    plastic_prev = None if opts.law is None else np.zeros(h.shape)
    spacing = check_positive("spacing", spacing, "m")
    e_star = check_positive("e_star", e_star, "Pa")
    with solve_pools(opts.threads):
        return _solve_step(
            h, spacing, e_star, opts, LoadStep(load, displacement, None, plastic_prev)
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
    method=None,
    max_outer=None,
    planner_effort=None,
    raise_on_failure=True,
    warm_starts=None,
    iteration="polonsky-keer",
) -> list[ContactResult]:
    """Solve for increasing loads, each step warm-started from the previous pressure.

    Parameters
    ----------
    heights, spacing, e_star, periodic, tol, max_iter, threads, backend
        As in :func:`solve`.
    loads : sequence of float
        Total forces, N; strictly increasing and positive.
    coarse_to_fine : bool
        Coarse-to-fine start for the first load only (later loads are warm-started).
        Ignored, with one :class:`IgnoredOptionWarning` per call, with plasticity or when
        the grid has no coarse level.
    plasticity : PenetrationHardness or ContactHardening, optional
        Plasticity law; each load step starts from the plastic displacement and the
        pressure of the previous one, so the series carries the plastic history.
    method, max_outer, planner_effort
        As in :func:`solve` (a warning about an ignored option is issued once per call).
    raise_on_failure : bool
        As in :func:`solve`. With False a step that does not converge is returned with
        ``success=False`` and the series goes on from its state: check every result.
    iteration : str
        As in :func:`solve`.
    warm_starts : sequence of array_like or None, optional
        One starting pressure (Pa) per load, e.g. the pressures of the same loads under a
        neighbouring law (:func:`solve_scan`); an entry may be None (no neighbour at that
        load). Where no start is given each step starts from the previous step's pressure
        scaled to its load. The plastic history always comes from the series' own previous
        step.

    Returns
    -------
    list of ContactResult, one per load.

    Raises
    ------
    ContactInputError, ConvergenceError, FreeBoundaryError
        As in :func:`solve`; an error raised by a step carries a note (``__notes__``) naming
        the step and its load. A load that the whole window at the hardness could not carry
        (penetration hardness) is refused before any step is solved.
    """
    h, spacing, e_star, opts = _checked_problem(
        heights,
        spacing,
        e_star,
        periodic=periodic,
        tol=tol,
        max_iter=max_iter,
        threads=threads,
        backend=backend,
        planner_effort=planner_effort,
        plasticity=plasticity,
        method=method,
        max_outer=max_outer,
        raise_on_failure=raise_on_failure,
        iteration=iteration,
    )
    arr = check_loads(loads)
    starts = _checked_starts(warm_starts, arr.size, h.shape)
    _warn_ignored(
        opts,
        h.shape,
        method=method,
        max_outer=max_outer,
        coarse_to_fine=coarse_to_fine,
        warm_start=starts is not None,
    )
    _check_series_capacity(h, spacing, opts, arr)
    plastic = None if opts.law is None else np.zeros(h.shape)
    results = []
    prev = None
    with solve_pools(opts.threads):  # as in solve
        for i, w in enumerate(arr):
            start = starts[i] if starts is not None else None
            if start is None:
                start = _scaled_start(prev, w)
            first_coarse = bool(coarse_to_fine) and i == 0 and starts is None
            try:
                res = _solve_step(
                    h, spacing, e_star, opts, LoadStep(float(w), None, start, plastic, first_coarse)
                )
            except ContactError as err:
                # the error describes the solve; the caller also needs to know which step
                err.add_note(_step_note(i, arr))
                raise
            if opts.law is not None:
                plastic = res.plastic_displacement
            results.append(res)
            prev = res
    return results


def _check_series_capacity(h, spacing, opts, loads) -> None:
    """Refuse a series with a load (N) the window at the hardness cannot carry before any
    step is solved (routes.check_capacity): its step would refuse it anyway, after the steps
    below it were solved for nothing (a p_Y scan's softest values; docs/study.md §1). The
    error names the first such step, as that step's own error does."""
    for i, w in enumerate(loads):
        try:
            check_capacity(opts.law, h, spacing**2, float(w), opts.periodic)
        except ContactError as err:
            err.add_note(_step_note(i, loads))
            raise


def _step_note(i: int, loads) -> str:
    """The note an error of a series' step ``i`` (from 0) carries: the step and its load (N)."""
    return f"load step {i + 1} of {loads.size} (W = {loads[i]:.6e} N)"


def solve_scan(heights, spacing, e_star, loads: Sequence[float], laws: Sequence, **options):
    """Load series of one surface under each plasticity law of ``laws`` in turn (a scan of
    p_Y or k), each series warm-started load by load from the previous law's pressures.

    Neighbouring laws give neighbouring contacts, so the previous law's pressure at the same
    load is a closer start than the series' own previous load (benchmarks/README.md,
    benchmark 7): order ``laws`` so that neighbours follow each other. ``options`` are those
    of :func:`solve_load_series` (not ``plasticity`` nor ``warm_starts``).

    Returns
    -------
    list of lists of ContactResult: one series per law, in the order given.

    Raises
    ------
    As :func:`solve_load_series`; the error carries a note naming the law.
    """
    for key in ("plasticity", "warm_starts"):
        if key in options:
            raise ContactInputError(f"solve_scan sets {key} itself; got {key}={options[key]!r}")
    scan = []
    previous = None
    for i, law in enumerate(laws):
        starts = None if previous is None else [r.pressure for r in previous]
        try:
            series = solve_load_series(
                heights, spacing, e_star, loads, plasticity=law, warm_starts=starts, **options
            )
        except ContactError as err:
            err.add_note(f"scan value {i + 1} of {len(laws)} ({law!r})")
            raise
        scan.append(series)
        previous = series
    return scan


def _checked_problem(heights, spacing, e_star, **options):
    """``(heights, spacing, e_star, SolveOptions)`` validated (m, m, Pa): every option
    of :func:`solve` but the load step's (:func:`.options.solve_options`)."""
    h = check_heights(heights)
    spacing = check_positive("spacing", spacing, "m")
    e_star = check_positive("e_star", e_star, "Pa")
    return h, spacing, e_star, solve_options(h.shape, **options)


def _plastic_history(opts, plastic_displacement, shape) -> np.ndarray | None:
    """The validated plastic displacement left by earlier loading (m; zeros when none is
    given), or None for an elastic solve, which refuses one."""
    if opts.law is None and plastic_displacement is not None:
        raise ContactInputError(
            "plastic_displacement was given without a plasticity law; pass plasticity="
            "PenetrationHardness(...) or ContactHardening(...)"
        )
    if opts.law is None:
        return None
    return check_plastic_history(plastic_displacement, shape)


def _checked_starts(warm_starts, count: int, shape) -> list[np.ndarray | None] | None:
    """One validated starting pressure (or None) per load, or None."""
    if warm_starts is None:
        return None
    if len(warm_starts) != count:
        raise ContactInputError(
            f"warm_starts must hold one pressure per load ({count}), got {len(warm_starts)}"
        )
    return [None if w is None else check_warm_start(w, shape) for w in warm_starts]


def _scaled_start(prev, load):
    """The previous step's pressure scaled to ``load`` (N): right total, right shape to first
    order; None for the first step (or a previous step without load)."""
    if prev is None or not prev.load > 0:
        return None
    return prev.pressure * (load / prev.load)


def _warn_ignored(opts, shape, *, method, max_outer, coarse_to_fine, warm_start=False):
    """Warn (IgnoredOptionWarning, from the caller's caller) about each ignored option."""
    notes = _ignored_options(
        opts,
        shape,
        method=method,
        max_outer=max_outer,
        coarse_to_fine=coarse_to_fine,
        warm_start=warm_start,
    )
    for note in notes:
        warnings.warn(note, IgnoredOptionWarning, stacklevel=3)


def _ignored_options(opts, shape, *, method, max_outer, coarse_to_fine, warm_start):
    """Messages naming every option given to a solve that has no effect on it."""
    notes = []
    if opts.law is None and method is not None:
        notes.append(
            f"method={method!r} is ignored: it picks the route of a plastic solve and this "
            "solve is elastic (plasticity=None)"
        )
    if opts.law is None and max_outer is not None:
        notes.append(
            f"max_outer={max_outer!r} is ignored: it caps the outer loop of a plastic solve "
            "and this solve is elastic (plasticity=None)"
        )
    if opts.route == "bounded" and max_outer is not None:
        notes.append(
            f"max_outer={max_outer!r} is ignored: the 'bounded' route of penetration hardness "
            "is one bounded solve with no outer loop"
        )
    if opts.route == "appendix" and opts.iteration != "polonsky-keer":
        notes.append(
            f"iteration={opts.iteration!r} is ignored: the appendix route runs Polonsky and "
            "Keer's iteration"
        )
    if coarse_to_fine:
        reason = _coarse_to_fine_obstacle(opts, shape, warm_start)
        if reason:
            notes.append(f"coarse_to_fine=True is ignored: {reason}")
    if opts.backend != "pyfftw" and opts.threads > 1:
        notes.append(f"threads={opts.threads} is ignored: the {opts.backend} backend sets none")
    if opts.backend != "pyfftw" and opts.planner_effort != DEFAULT_PLANNER_EFFORT:
        notes.append(
            f"planner_effort={opts.planner_effort!r} is ignored: the {opts.backend} backend "
            "does not plan with FFTW"
        )
    return notes


def _coarse_to_fine_obstacle(opts, shape, warm_start):
    """Why a coarse-to-fine start cannot run, or None when it can."""
    if opts.law is not None:
        return "the coarse-to-fine start is only implemented for elastic solves"
    if warm_start:
        return "warm_start gives the starting pressure"
    if not has_coarse_level(shape):
        return (
            f"a {shape[0]}x{shape[1]} grid has no coarse level (both sides must be even and "
            f"at least {2 * COARSE_MIN_SIZE} pixels)"
        )
    return None


def _solve_step(h, spacing, e_star, opts, step: LoadStep):
    """One validated solve of ``step`` by the route of ``opts``, elastic or plastic from the
    plastic state ``step.plastic_prev`` (m), checked and made into a ContactResult."""
    t0 = time.perf_counter()
    out = run_route(h, spacing, e_star, opts, step)
    what = "solver" if opts.law is None else "plastic solve"
    return _finished(h, spacing, opts, out, info=_solve_info(opts, out, t0), what=what)


def _solve_info(opts, out, t0):
    """The SolveInfo of a solve (Outcome ``out``) that started at ``t0`` (perf_counter, s)."""
    return SolveInfo(
        route=opts.route,
        convolutions=float(out.convolutions),
        steepest_descent_resets=int(out.resets),
        outer_iterations=int(out.outer_iterations),
        coarse_levels=tuple(out.coarse_levels),
        plasticity=opts.law,
        backend=opts.backend,
        threads=opts.threads,
        planner_effort=opts.planner_effort,
        tol=opts.tol,
        max_iter=opts.max_iter,
        max_outer=opts.max_outer,
        wall_time_s=time.perf_counter() - t0,
        iteration="polonsky-keer" if opts.route == "appendix" else opts.iteration,
    )


def _finished(h, spacing, opts, outcome, *, info, what):
    """The ContactResult of a solve (``outcome``: the route's Outcome), after the checks:
    non-convergence (raises unless ``raise_on_failure=False``), non-finite fields (raise
    always) and, for a converged non-periodic solution, pressure on the window edge (raises
    always; a non-converged iterate's edge pressure says nothing about the window)."""
    if not outcome.converged and opts.raise_on_failure:
        raise ConvergenceError(
            outcome.message,
            iterations=outcome.iterations,
            residual=outcome.residual,
            tol=opts.tol,
            residual_history=outcome.history,
            status=outcome.status,
        )
    _check_finite(what, outcome, opts.tol)
    if outcome.converged and not opts.periodic:
        _check_free_boundary(outcome.pressure, spacing)
    p = outcome.pressure
    return ContactResult(
        pressure=p,
        gap=outcome.gap,
        elastic_displacement=outcome.elastic_displacement,
        plastic_displacement=outcome.plastic_displacement,
        contact=p > 0,
        load=float(p.sum()) * spacing**2,
        displacement=outcome.displacement,
        spacing=spacing,
        iterations=outcome.iterations,
        residual=outcome.residual,
        residual_history=outcome.history,
        success=outcome.converged,
        status=outcome.status,
        message=outcome.message,
        periodic=opts.periodic,
        heights=h,
        info=info,
    )


def _check_finite(what, outcome, tol):
    """Raise ConvergenceError when a solve's pressure or gap holds NaN or inf (never return
    them, whatever ``raise_on_failure``)."""
    if not finite(outcome):
        raise ConvergenceError(
            f"{what} produced non-finite pressure or gap (NaN/inf)",
            iterations=outcome.iterations,
            residual=outcome.residual,
            tol=tol,
            residual_history=outcome.history,
            status=STALLED,
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
