"""The Polonsky–Keer constrained conjugate gradient: the solver's one iteration, its entry.

Problem (SI units): find the pressure ``p >= 0`` (Pa) on the grid such that the gap
``g = K*p - h - d`` (m) satisfies ``g >= 0`` everywhere and ``g = 0`` where ``p > 0``, with
either the total force ``A0 Σp = W`` prescribed (load control; ``d`` is then the Lagrange
multiplier of the force constraint) or the rigid-body approach ``d`` prescribed
(displacement control). ``K*`` is a convolution operator (m/Pa), ``A0`` the pixel area. A
bounded constraint ``0 <= p <= p_max`` (penetration hardness) and an elastic-plus-Winkler
operator (contact hardening) run through the same loop.

:func:`polonsky_keer` is the entry: it picks the kernel set (:func:`kernel_set`: the fused
numba kernels of :mod:`.kernels`, or the array kernels of :mod:`.array_kernels`) and its
threads, runs the iteration of :mod:`.cg_iteration` (the algorithm, its cost and its
convergence test are described there; docs/models.md §2.2), and builds the outcome. The
outcome's ``status`` is 0 (converged), 1 (``max_iter`` reached) or 2 (stalled: a periodic
displacement-controlled solve reached full contact, where the mean pressure is
undetermined, or the best residual has stopped falling).

The constraint is an object with three methods (:class:`.constraints.HardWall`;
:class:`.constraints.BoundedWall` for ``0 <= p <= p_max``); the operator is a convolution
of :mod:`.convolution` or any symmetric positive-definite linear callable
``op(x, out=...)``, with an optional Winkler compliance (``operator`` and ``compliance``
attributes) added inside the kernels.
"""

from __future__ import annotations

import numpy as np

from . import kernels as _k
from .array_kernels import array_kernel_set
from .bounded_load import fully_bound_approach
from .cg_iteration import CGIteration
from .constraints import HardWall
from .errors import CONVERGED, ITERATION_CAP, STALLED, ConvergenceError
from .options import CGOptions
from .result import Outcome


def polonsky_keer(
    operator,
    heights,
    options: CGOptions,
    *,
    pixel_area,
    h_scale,
    p_init,
    load=None,
    displacement=None,
    constraint=None,
) -> Outcome:
    """Solve the contact problem by constrained conjugate gradients.

    Parameters
    ----------
    operator : callable
        ``operator(x, out=array) -> array``: symmetric positive-definite linear map from
        pressure (Pa) to displacement (m) on the grid of ``heights``.
    heights : ndarray
        Rigid indenter heights, m (larger = closer to the substrate).
    options : CGOptions
        ``tol`` (on the residual, dimensionless), ``max_iter``, ``refresh`` (``u = K*p``
        recomputed from scratch at least every ``refresh`` iterations, a safeguard against
        drift of the incremental update; convergence is always declared on a fresh ``u``),
        ``raise_on_failure`` (raise :class:`ConvergenceError` when the solve stops without
        converging, status 1 or 2; else return the last iterate with that status),
        ``threads`` of the kernels (None: the operator's FFTW ``threads``, else 1) and
        ``bounded_load_sweep`` (bounded load control: True takes the fused step that keeps
        ``u = K*p`` without a convolution, :class:`.bounded_load.BoundedLoadSweep`; False
        the numpy step and a convolution per step, :func:`.bounded_load.bounded_load_step`,
        the reference the tests compare with). A route's are :attr:`.SolveOptions.cg`.
    pixel_area : float
        Area of one grid cell, m².
    h_scale : float
        Length scale of the complementarity residual, m (rms height of the indenter).
    p_init : ndarray
        Initial pressure, Pa (>= 0; load control rescales it to the load).
    load : float, optional
        Total force W, N (load control).
    displacement : float, optional
        Rigid-body approach d, m (displacement control).
    constraint : HardWall, optional
        The inequality constraint (default: hard wall).
    """
    if (load is None) == (displacement is None):
        raise ValueError("exactly one of load and displacement must be given")
    constraint = HardWall() if constraint is None else constraint
    ks = kernel_set(options)
    with ks.kernel_threads(
        _kernel_threads(operator, options.threads, ks.n_chunks(np.size(heights)))
    ):
        state = CGIteration(
            ks,
            operator,
            heights,
            options,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p_init,
            load=load,
            displacement=displacement,
            constraint=constraint,
        )
        return run_to_outcome(state)


def kernel_set(options: CGOptions):
    """The kernel set a solve runs on: the fused numba kernels (the module :mod:`.kernels`)
    unless ``options.array_module`` names an array namespace, then the array kernels of
    :mod:`.array_kernels` on it (``"cupy"``: on the GPU).

    A kernel set offers the functions of :mod:`.kernels` that the iteration calls, under
    their contracts, and the host side of its arrays: ``xp`` (the array namespace),
    ``empty(n, dtype)``, ``asarray`` (host to the set's memory), ``to_host``, ``on_host(fn,
    *args, writes=())`` (a numpy routine on host copies, the arrays at ``writes`` copied
    back; the numba set calls ``fn`` as it is), ``add_at`` (``np.add.at``),
    ``event_counts`` (the points ``update`` clipped and added, as ints), ``kernel_threads``,
    ``n_chunks`` and ``SLOTS``."""
    if options.array_module is None:
        return _k
    return array_kernel_set(options.array_module)


def run_to_outcome(state: CGIteration) -> Outcome:
    """Run a :class:`.cg_iteration.CGIteration` set up on its kernel set (within the set's
    ``kernel_threads``) to its end, and build its outcome."""
    state.run()
    p, u, h = state.host_fields()
    return finish_outcome(
        state.constraint,
        state.tol,
        state.raise_on_failure,
        state.pixel_area,
        p=p,
        u=u,
        h=h,
        d=state.d,
        load_control=state.load_control,
        converged=state.converged,
        stalled=state.stalled,
        it=state.it,
        residual=state.residual,
        history=state.history,
        # a forward transform whose inverse was skipped is half a convolution's FFT work
        calls=state.calls + 0.5 * state.forward_only,
        resets=state.resets,
        extra=state.counters(),
        shape=state.shape,
    )


def _kernel_threads(operator, threads, chunks):
    """Threads for the fused kernels: ``threads``, else the operator's, else 1, and no more
    than the grid's ``chunks``: a thread without a chunk only pays its wake-up in every
    kernel (benchmarks/README.md, "A second core")."""
    if threads is None:
        base = getattr(operator, "operator", operator)  # a Winkler wrapper's convolution
        threads = getattr(base, "threads", 1)
    if not (isinstance(threads, int | np.integer) and threads >= 1):
        raise ValueError(f"threads must be a positive integer, got {threads!r}")
    return min(int(threads), chunks)


def finish_outcome(
    constraint,
    tol,
    raise_on_failure,
    pixel_area,
    *,
    p,
    u,
    h,
    d,
    load_control,
    converged,
    stalled,
    it,
    residual,
    history,
    calls,
    resets,
    shape,
    extra=None,
    method="Polonsky-Keer CG",
):
    """The :class:`~.result.Outcome` of a finished loop (``p`` Pa and ``u = K*p`` m, flat
    and fresh); raises ConvergenceError on failure when ``raise_on_failure``. ``p`` and
    ``u`` are the loop's own arrays, allocated for this solve: the outcome holds them
    without a copy."""
    gap = np.subtract(u, h)
    if load_control and p.sum() > 0:
        m = np.empty(p.size)
        nc = constraint.free_mask(p, m, np.empty(p.size, dtype=bool))
        # bounded, every loaded point at the bound (nc = 0): the force does not fix d
        d = float(np.dot(gap, m) / nc) if nc else fully_bound_approach(u, h, p, d)
    gap -= d
    hist = np.asarray(history)
    status, message = _status_message(converged, stalled, it, residual, tol, shape, p, method)
    if status != CONVERGED and raise_on_failure:
        raise ConvergenceError(
            message,
            iterations=it,
            residual=float(residual),
            tol=tol,
            residual_history=hist,
            status=status,
        )
    return Outcome(
        pressure=p.reshape(shape),
        gap=gap.reshape(shape),
        elastic_displacement=u.reshape(shape),
        plastic_displacement=None,
        displacement=float(d),
        iterations=it,
        residual=float(residual),
        history=hist,
        convolutions=calls,
        status=status,
        message=message,
        resets=resets,
        info=dict(extra or {}),
    )


def _status_message(converged, stalled, it, residual, tol, shape, p, method):
    """Status code (0, 1, 2) and message of a finished CG solve (``method``: its name)."""
    if converged:
        return CONVERGED, (
            f"{method} converged in {it} iterations: residual {residual:.3e} < tol {tol:.1e}"
        )
    if stalled is not None:
        return STALLED, f"{stalled}; stopped after {it} iterations at residual {residual:.3e}"
    return ITERATION_CAP, (
        f"{method} did not converge in {it} iterations: residual "
        f"{residual:.3e} > tol {tol:.1e} (grid {shape[0]}x{shape[1]}, "
        f"{int(np.count_nonzero(p))} contact pixels)"
    )
