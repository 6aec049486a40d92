"""The Polonsky–Keer constrained conjugate gradient: the solver's one iteration.

Problem (SI units): find the pressure ``p >= 0`` (Pa) on the grid such that the gap
``g = K*p - h - d`` (m) satisfies ``g >= 0`` everywhere and ``g = 0`` where ``p > 0``, with
either the total force ``A0 Σp = W`` prescribed (load control; ``d`` is then the Lagrange
multiplier of the force constraint) or the rigid-body approach ``d`` prescribed
(displacement control). ``K*`` is a convolution operator (m/Pa), ``A0`` the pixel area. A
bounded constraint ``0 <= p <= p_max`` (penetration hardness) and an elastic-plus-Winkler
operator (contact hardening) run through the same loop.

Algorithm (docs/models.md §2.2), per iteration on the free set ``Ic`` (``p > 0``):
gap ``g`` (load control: minus its mean over ``Ic``, which is the approach ``d``),
``G = Σ_Ic g²``, conjugate direction ``t = g + δ (G/G_old) t`` on ``Ic`` (0 elsewhere;
load control: minus its mean over ``Ic``), ``r = K*t``, step ``τ = Σ g t / Σ r t``,
``p ← max(p - τ t, 0)``; points with ``p = 0`` and ``g < 0`` (penetrating but unloaded)
get ``p ← -τ g`` and join ``Ic``; load control rescales ``p`` to the target force.
Two departures from the paper (docs/models.md §2.2; measured in benchmarks/README.md): ``t``
is given zero sum over ``Ic`` under load control, so ``Σ r t`` is the quadratic form alone
and can be taken from the spectrum (Parseval); and the conjugation is reset to steepest
descent only when the points added in one iteration exceed ``RESET_FRACTION`` of the free
set. The fixed point is Polonsky & Keer's.

This module owns the control flow: stall detection (:class:`.stall.StallMonitor`), the
full-contact singularity of periodic displacement control, restarts when no descent
direction is left, the refresh of ``u = K*p``, convergence and the outcome's status. The
element-wise work of an iteration is the fused kernel set of :mod:`.kernels` (three sweeps
plus the convolution ``r = K*t``, taken in halves when the operator offers it), and bounded
load control takes its step from :mod:`.bounded_load`.

Convergence: two dimensionless measures,

* ``complementarity = max(rms_Ic |g|, max_violators |g|) / h_scale`` with ``h_scale`` the
  rms height of the indenter: recorded every iteration as the residual;
* ``change = Σ|p - p_old| / Σp``, the relative pressure change, computed only once the
  complementarity is below ``tol``.

The solve has converged when both are below ``tol``, the complementarity re-evaluated with a
freshly convolved ``u`` (never the incrementally updated one); the reported final residual is
the larger of the two. The outcome's ``status`` is 0 (converged), 1 (``max_iter`` reached) or
2 (stalled: a periodic displacement-controlled solve reached full contact, where the mean
pressure is undetermined, or the best residual has stopped falling).

Cost: at most one convolution per iteration. ``u`` follows the step linearly
(``u ← s (u - τ K*t + K*c)``, ``c`` the pressures set by the projection and the violator
step): with no changed point no convolution at all, with at most ``SPARSE_MAX_PERIODIC`` /
``SPARSE_MAX_PADDED`` of them their point responses are added
(:func:`.kernels.add_point_responses`); otherwise, and at least every ``refresh``
iterations and before convergence is declared, ``u = K*p`` is taken afresh and the inverse
transform of ``K*t`` is skipped.

Load control rescales ``p`` (and so ``u``) to the target force every iteration at no cost:
the stored pressure ``P`` and displacement ``U`` carry one common scale ``sigma`` (true
``p = sigma·P``, ``u = sigma·U``); ``U = K*P`` stays true when only ``sigma`` changes.

The constraint is an object with three methods (:class:`HardWall`; :class:`BoundedWall` for
``0 <= p <= p_max``); the operator is a convolution of :mod:`.convolution` or any symmetric
positive-definite linear callable ``op(x, out=...)``, with an optional Winkler compliance
(``operator`` and ``compliance`` attributes) added inside the kernels.
"""

from __future__ import annotations

import numpy as np

from . import kernels as _k
from .array_kernels import array_kernel_set
from .bounded_load import (
    BoundedLoadSweep,
    bounded_load_step,
    fully_bound_approach,
    impose_bounded_load,
)
from .errors import CONVERGED, ITERATION_CAP, STALLED, ConvergenceError
from .options import CGOptions
from .result import Outcome
from .stall import StallMonitor


class HardWall:
    """The hard-wall constraint ``p >= 0`` with complementarity ``p > 0 ⇒ g = 0``.

    Constraint protocol used by :func:`polonsky_keer` (a bounded variant implements the
    same three methods, see :class:`BoundedWall`):

    ``free_mask(p, out, work) -> int``
        write the float 0/1 mask of the free set into ``out`` (``work``: bool scratch of
        the same size); return its size.
    ``project(p, m) -> indices``
        project ``p`` in place onto the admissible set; points that hit a bound leave the
        free set (``m[idx] = 0``); return their flat indices.
    ``violators(p, g, m) -> indices``
        flat indices of constrained points (``m == 0``) whose gap says they should be
        free; the solver moves them by ``-τ g`` and adds them to ``m``.

    The free set is kept as a float mask so restricted sums are BLAS dot products
    (``Σ_Ic x = x·m``), and it is updated sparsely (points leave only by projection and
    enter only as violators), so no full pass is needed to rebuild it every iteration.
    """

    bounded = False

    def free_mask(self, p: np.ndarray, out: np.ndarray, work: np.ndarray) -> int:
        """Write the float 0/1 mask of ``p > 0`` into ``out``; return its size."""
        np.greater(p, 0.0, out=work)
        np.copyto(out, work)
        return int(np.count_nonzero(work))

    def project(self, p: np.ndarray, m: np.ndarray) -> np.ndarray:
        """Clip ``p`` to ``p >= 0`` in place, drop clipped points from ``m``."""
        if p.min() >= 0.0:
            return _EMPTY
        idx = np.flatnonzero(p < 0.0)
        p[idx] = 0.0
        m[idx] = 0.0
        return idx

    def violators(self, p: np.ndarray, g: np.ndarray, m: np.ndarray) -> np.ndarray:
        """Points with ``p = 0`` (outside ``m``) and ``g < 0``: unloaded but penetrating.
        ``g < 0`` holds on few points, so the mask test is a small gather."""
        cand = np.flatnonzero(g < 0.0)
        return cand[m[cand] == 0.0]


class BoundedWall(HardWall):
    """The constraint ``0 <= p <= p_max`` (``p_max`` scalar or per pixel, Pa).

    Free set ``0 < p < p_max`` (under displacement control a free point that reaches
    ``p_max`` exactly stays free until it crosses it; the load-controlled step counts it as
    at the bound); points at ``p_max`` are constrained and become violators
    when their gap opens (``g > 0``). Load control imposes the load on the free points and
    leaves those at the bound (:func:`amontons.contact.bounded_load.impose_bounded_load`); a
    rescale of the whole field would push points through the bound.
    """

    bounded = True

    def __init__(self, p_max):
        self.p_max = p_max if np.isscalar(p_max) else np.ascontiguousarray(p_max, float).ravel()

    def free_mask(self, p, out, work):
        np.greater(p, 0.0, out=work)
        work &= p < self.p_max
        np.copyto(out, work)
        return int(np.count_nonzero(work))

    def project(self, p, m):
        # only free points move in a CG step (t = 0 elsewhere), so only they can cross
        # a bound; constrained points already sitting at p_max are left as they are
        low = np.flatnonzero(p < 0.0) if p.min() < 0.0 else _EMPTY
        p[low] = 0.0
        high = np.flatnonzero(p > self.p_max)
        p[high] = self.p_max if np.isscalar(self.p_max) else self.p_max[high]
        idx = np.concatenate([low, high])
        m[idx] = 0.0
        return idx

    def violators(self, p, g, m):
        cand = np.flatnonzero(m == 0.0)
        gc, pc = g[cand], p[cand]
        upper = self.p_max if np.isscalar(self.p_max) else self.p_max[cand]
        # unloaded and penetrating, with room to rise (p_max = 0 pins the point at 0), or
        # at the bound, open, with room to fall
        rise = (pc <= 0.0) & (gc < 0.0) & (pc < upper)
        fall = (pc >= upper) & (gc > 0.0) & (pc > 0.0)
        return cand[rise | fall]


_EMPTY = np.empty(0, dtype=np.intp)
# Reset the conjugation to steepest descent only when the points added to the free set in
# one iteration exceed this fraction of it (module docstring; 0 = the original PK rule).
RESET_FRACTION = 0.01
# Most changed points (clipped + added) applied to u as point responses instead of a full
# convolution, periodic and padded: about where the points' responses cost a convolution
# less its inverse (benchmarks/bench_point_responses.py; benchmarks/README.md, "Fewer
# convolutions").
SPARSE_MAX_PERIODIC = 12
SPARSE_MAX_PADDED = 32
# Largest Σa²/G of the one-pass moments about the previous approach (see _centred_moments).
RECENTRE = 1e3


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
        return _loop(
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


def kernel_set(options: CGOptions):
    """The kernel set a solve runs on: the fused numba kernels (the module :mod:`.kernels`)
    unless ``options.array_module`` names an array namespace, then the array kernels of
    :mod:`.array_kernels` on it (``"cupy"``: on the GPU).

    A kernel set offers the functions of :mod:`.kernels` that :func:`_loop` calls, under
    their contracts, and the host side of its arrays: ``xp`` (the array namespace),
    ``empty(n, dtype)``, ``asarray`` (host to the set's memory), ``to_host``, ``on_host(fn,
    *args, writes=())`` (a numpy routine on host copies, the arrays at ``writes`` copied
    back; the numba set calls ``fn`` as it is), ``add_at`` (``np.add.at``),
    ``event_counts`` (the points ``update`` clipped and added, as ints), ``kernel_threads``,
    ``n_chunks`` and ``SLOTS``."""
    if options.array_module is None:
        return _k
    return array_kernel_set(options.array_module)


def _winkler_parts(operator):
    """``(convolution, compliance)`` of an elastic-plus-Winkler operator (compliance m/Pa,
    added inside :func:`.kernels.step_dots`), or ``(operator, None)``."""
    compliance = getattr(operator, "compliance", None)
    base = getattr(operator, "operator", None)
    if compliance is None or base is None:
        return operator, None
    # a fresh writable copy: a read-only array is another type to the compiled kernels,
    # which would then compile in this process (.jit)
    return base, np.array(compliance, dtype=np.float64).ravel()


def _bound_array(constraint, n):
    """``(p_max per point, bounded flag)`` for the kernels (Pa)."""
    if not constraint.bounded:
        return np.full(1, np.inf), False
    # a fresh writable copy (broadcast_to gives a read-only view), as in _winkler_parts
    return np.array(np.broadcast_to(constraint.p_max, (n,)), dtype=np.float64), True


def _loop(
    ks,
    operator,
    heights,
    options,
    *,
    pixel_area,
    h_scale,
    p_init,
    load,
    displacement,
    constraint,
):
    tol, max_iter, refresh = options.tol, options.max_iter, options.refresh
    raise_on_failure = options.raise_on_failure
    reset_fraction = RESET_FRACTION  # read per solve (benchmarks/bench_convergence.py sets it)
    load_control = load is not None
    shape = heights.shape
    n = heights.size
    xp = ks.xp

    def buf():
        # the numba set's are SIMD-aligned: the FFT plans run on them without copies
        return ks.empty(n, np.float64)

    base_op, compliance = _winkler_parts(operator)
    winkler = compliance is not None
    if winkler:
        compliance = ks.asarray(compliance)
    comp_arg = compliance if winkler else xp.zeros(1)
    p_max, bounded = _bound_array(constraint, n)
    p_max = ks.asarray(p_max)
    h = buf()
    h[:] = ks.asarray(np.ravel(heights))
    p = buf()
    p[:] = ks.asarray(np.ravel(p_init))
    if p.min() < 0:
        raise ValueError("p_init must be >= 0")
    calls = 0

    def conv(x, out):
        nonlocal calls
        calls += 1
        base_op(x.reshape(shape), out=out.reshape(shape))
        if winkler:
            # the elastic-plus-Winkler operator's K*x + x/k (winkler.WinklerOperator), with the
            # compliance in the kernel set's memory
            out += compliance * x
        return out

    if load_control:
        total = p.sum()
        if not total > 0:
            p[:] = 1.0
            total = p.size
        p *= load / (pixel_area * total)
    if bounded:
        # after the load's rescale, which may push a start's points through the bound
        xp.minimum(p, p_max, out=p)
    # bounded load control: the force is imposed on the free points only (module docstring)
    bounded_load = bounded and load_control
    target = load / pixel_area if load_control else 0.0  # Σp, Pa
    t = buf()
    t[:] = 0.0
    m = ks.empty(n, np.uint8)
    if bounded_load:
        ks.free_mask(p, m, p_max, bounded)
        ks.on_host(impose_bounded_load, p, m, t, p_max, target, np.zeros(n), h, writes=(0, 1, 2))
    u, r = buf(), buf()
    p_old = None  # a copy of p, taken only when the step may converge
    nch = ks.n_chunks(n)
    idx_buf = xp.zeros((nch, ks.SLOTS), dtype=np.int64)
    val_buf = xp.zeros((nch, ks.SLOTS))
    counts = xp.zeros((nch, 2), dtype=np.int64)
    violators = xp.zeros(nch, dtype=np.int64)
    # the violators of chunks with few, recorded by direction for update (kernels.direction)
    vidx = xp.zeros((nch, ks.SLOTS), dtype=np.int64)
    vg = xp.zeros((nch, ks.SLOTS))
    found = (violators, vidx, vg)
    conv(p, u)
    sigma = 1.0  # true p = sigma·p, u = sigma·u (module docstring)
    nc = int(ks.free_mask(p, m, p_max, bounded))
    delta = 0.0
    g_old = 1.0
    since_fresh = 0
    resets = 0
    recentres = 0  # second moment passes (see _centred_moments)
    # how u was updated after each step (for benchmarks/bench_iteration.py)
    updates = dict.fromkeys(
        ("linear", "point responses", "full: changes", "full: refresh", "full: bounded load"), 0
    )
    history = []
    d = 0.0 if load_control else float(displacement)
    residual = np.inf
    converged = False
    stalled = None
    it = 0
    singular_full = getattr(operator, "periodic", False) and not load_control
    # every operator of .convolution offers its real-space kernel; a custom one may not
    sparse_ok = hasattr(base_op, "real_space_kernel")
    sparse_max = SPARSE_MAX_PERIODIC if getattr(base_op, "periodic", False) else SPARSE_MAX_PADDED
    green = None
    sweep = None
    # the convolution r = K*t taken in halves (operator.forward, .multiply_energy, .inverse):
    # an iteration that takes u = K*p afresh then skips the inverse, half an FFT pair. A
    # Winkler term needs r in real space (step_dots); the bounded load step updates u itself
    split = getattr(base_op, "splits", False) and not winkler and not bounded_load
    forward_only = 0  # forward transforms whose inverse was skipped
    if bounded_load and options.bounded_load_sweep and not winkler:
        sweep = BoundedLoadSweep(
            ks, base_op, shape, p_max, target, sparse_max, sparse_ok, conv, buf
        )
    monitor = StallMonitor()
    while it < max_iter:
        if history and monitor.update(history[-1]):
            stalled = monitor.message()
            break
        it += 1
        if singular_full and nc == n:
            stalled = (
                "periodic displacement-controlled solve reached full contact: the mean "
                "pressure is then undetermined (the q = 0 mode is the rigid mode); use load "
                f"control or a smaller displacement (d = {d:.3e} m)"
            )
            if raise_on_failure:
                raise ConvergenceError(
                    stalled,
                    iterations=it,
                    residual=float(residual),
                    tol=tol,
                    residual_history=np.asarray(history),
                    status=STALLED,
                )
            it -= 1
            break
        if nc == 0:
            # displacement control, or bounded load control with every loaded point at the
            # bound: start the free set from the points the constraint says should be free
            if load_control:
                d = ks.on_host(fully_bound_approach, sigma * u, h, p, d)
            g = sigma * u - h - d
            mf = xp.zeros(n)
            # a restart of the free set, rare: the constraint's numpy test on the host
            start = ks.asarray(ks.on_host(constraint.violators, sigma * p, g, mf))
            nc = int(start.size)
            if nc == 0:
                residual = 0.0
                history.append(0.0)
                converged = True
                since_fresh = 1
                break
            m[:] = 0
            m[start] = 1
            t[:] = 0.0
            if sweep is not None:
                sweep.forget_bound_displacement()
        if load_control:
            d, big_g, gt_old, t_old_sum, recentred = _centred_moments(ks, u, sigma, h, m, t, d, nc)
            recentres += recentred
        else:
            _, big_g, gt_old, _ = ks.gap_moments(u, sigma, h, m, t, d)
            t_old_sum = 0.0
        beta = delta * big_g / g_old if g_old > 0 else 0.0
        g_dot_t = big_g + beta * gt_old if beta else big_g
        # load control: Σ_Ic t = 0 (t_old loses its sum where points were
        # clipped); the mean of r over Ic then drops out of Σ r t
        shift = beta * t_old_sum / nc
        ks.direction(u, sigma, h, m, t, d, beta, shift, p, p_max, bounded, *found)
        g_old = big_g
        if split:
            # r = K*t in halves: Σ r t from the spectrum now, the inverse only if u follows
            # the step incrementally (below)
            base_op.forward(t.reshape(shape))
            rt = base_op.multiply_energy()
            forward_only += 1
        else:
            conv_t(base_op, t, r, shape)
            calls += 1
            rt, _ = ks.step_dots(r, t, m, comp_arg, winkler)
        if load_control and nc == 1:
            # a one-point free set has no direction that keeps its force (its t is
            # round-off): no descent direction
            rt = 0.0
        if not (rt > 0 and np.isfinite(rt)):
            # no descent direction (the gap on the free set is nil or round-off, or conjugacy
            # was lost to round-off): the solution if the gap on
            # the free set is below tol and nothing penetrates off it, judged on a freshly
            # convolved u; penetrating points join the free set at p = 0 and the next
            # (steepest-descent) iteration moves them
            g = sigma * u - h - d
            ol = ks.asarray(ks.on_host(constraint.violators, sigma * p, g, m.astype(np.float64)))
            pen = float(abs(g[ol]).max()) if ol.size else 0.0
            residual = max(np.sqrt(big_g / nc), pen) / h_scale
            history.append(residual)
            if residual < tol and since_fresh:
                conv(p, u)
                since_fresh = 0
                continue
            if residual < tol:
                converged = True
                break
            m[ol] = 1
            nc += int(ol.size)
            if sweep is not None:
                sweep.forget_bound_displacement()
            delta = 0.0
            g_old = 0.0
            continue
        tau = g_dot_t / rt
        rms_ok = np.sqrt(big_g / max(nc, 1)) / h_scale < tol
        if rms_ok:
            # the convergence test below needs the pressure change: keep the old field
            # (this pass is paid only in the last iterations; otherwise p is updated in place)
            p_old = xp.copy(p) if p_old is None else _copy(xp, p, p_old)
        how = None  # how u followed the step, when the bounded load step says
        complete = True  # update's records hold every changed point (kernels.update)
        if sweep is not None:
            p, m, n_clip, n_add, pen, how, backtracked = sweep.step(
                p, u, r, t, h, m, d, tau, found, idx_buf, val_buf, counts
            )
        elif bounded_load:
            n_clip, n_add, pen, backtracked = ks.on_host(
                bounded_load_step, p, u, h, m, t, p_max, d, tau, target, writes=(0, 3, 4)
            )
            # the step rescaled the free points only: u is taken afresh
            conv(p, u)
            how = "full: bounded load"
        else:
            psum, pen, _, complete = ks.update(
                p, p, u, r, t, h, m, p_max, bounded, sigma, d, tau,
                violators, idx_buf, val_buf, counts, False, not split, vidx, vg,
                sparse_max if sparse_ok else -1,
            )  # fmt: skip
            n_clip, n_add = ks.event_counts(counts)
            backtracked = False
        if backtracked:
            delta = 0.0
            resets += 1
        elif n_add:
            if n_add > reset_fraction * nc:
                delta = 0.0
                resets += 1
            else:
                delta = 1.0
        else:
            delta = 1.0
        nc_start = nc
        nc += n_add - n_clip
        sigma_old = sigma
        if load_control and not bounded_load:
            sigma = load / (pixel_area * psum)
        changes = n_clip + n_add
        # a chunk with more events than its records hold: u cannot follow by point
        # responses either
        too_many = changes > sparse_max or not complete
        if how is not None:
            # the bounded load step brought u to K*p itself (sigma stays 1)
            if how.startswith("full"):
                since_fresh = 0
            elif since_fresh >= refresh:
                conv(p, u)
                since_fresh = 0
                sweep.forget_bound_displacement()
                how = "full: refresh"
            else:
                since_fresh += 1
            updates[how] += 1
        elif since_fresh >= refresh or (changes and (too_many or not sparse_ok)):
            conv(p, u)
            since_fresh = 0
            updates["full: changes" if too_many else "full: refresh"] += 1
        else:
            updates["point responses" if changes else "linear"] += 1
            if split:
                # the inverse the step skipped: u -= τ/σ K*t
                base_op.inverse(r.reshape(shape))
                forward_only -= 1
                calls += 1
                ks.subtract_scaled(u, r, tau / sigma_old)
            if changes:
                # u (stored, scale sigma_old) += K*c / sigma_old; u = K*p holds for the stored
                # pair whatever their common scale, so the new scale needs no pass
                idx, vals = ks.changed_points(counts, idx_buf, val_buf)
                if green is None:
                    green = base_op.real_space_kernel()
                ks.add_point_responses(u.reshape(shape), green, idx, vals / sigma_old)
                if winkler:
                    # a point clipped and re-added appears twice: add.at sums both
                    ks.add_at(u, idx, compliance[idx] * vals / sigma_old)
            since_fresh += 1
        comp = max(np.sqrt(big_g / max(nc_start, 1)), pen) / h_scale
        residual = comp
        if comp < tol and rms_ok:
            change, psum_true = ks.relative_change(p, sigma, p_old, sigma_old)
            change = float(change / psum_true) if psum_true > 0 else 0.0
            residual = max(change, comp)
            if change < tol:
                # settle the scale into the fields (two passes, only here)
                p *= sigma
                if since_fresh:
                    conv(p, u)
                    since_fresh = 0
                else:
                    u *= sigma
                sigma = 1.0
                comp_now, d_now, nc = _final_complementarity(
                    ks, u, h, p, d, load_control, m, t, p_max, bounded
                )
                comp_now /= h_scale
                residual = max(change, comp_now)
                if comp_now < tol:
                    d = d_now
                    converged = True
                t *= m  # the fresh mask replaces the sparsely maintained one
        history.append(residual)
        if converged:
            break
    if sigma != 1.0:
        p *= sigma
        u *= sigma
    if since_fresh:
        conv(p, u)
    # the outcome is built on the host (numpy arrays; the numba set's are already)
    p, u, h = ks.to_host(p), ks.to_host(u), ks.to_host(h)
    return finish_outcome(
        constraint,
        tol,
        raise_on_failure,
        pixel_area,
        p=p,
        u=u,
        h=h,
        d=d,
        load_control=load_control,
        converged=converged,
        stalled=stalled,
        it=it,
        residual=residual,
        history=history,
        # a forward transform whose inverse was skipped is half a convolution's FFT work
        calls=calls + 0.5 * forward_only,
        resets=resets,
        extra={
            "moment_recentres": recentres,
            "u_updates": updates,
            "forward_only_transforms": forward_only,
        },
        shape=shape,
    )


def _copy(xp, src, dst):
    xp.copyto(dst, src)
    return dst


def conv_t(base_op, t, r, shape):
    """``r = K*t`` with the plain convolution (a Winkler term is added by ``step_dots``)."""
    base_op(t.reshape(shape), out=r.reshape(shape))


def _centred_moments(ks, u, sigma, h, m, t, d_old, nc):
    """Load control: the approach ``d`` (m, the mean of ``sigma·u - h`` on the free set),
    ``G = Σ_Ic g²`` (m²) and ``Σ g·t`` with ``g`` centred on it, ``Σ t`` (m), and whether a
    second pass was needed.

    One pass takes the moments about the previous approach; when that is far from the new
    one (the first iteration, a warm start), ``G = Σa² - (Σa)²/nc`` would cancel
    catastrophically (relative error ~ 1e-16 · Σa²/G), so the moments are taken again about
    the new approach whenever ``Σa² > RECENTRE · G``: G is then good to ~1e-13.
    """
    s1, s2, st, tsum = ks.gap_moments(u, sigma, h, m, t, d_old)
    mean = s1 / nc
    d = d_old + mean
    big_g = max(s2 - s1 * mean, 0.0)
    if s2 <= RECENTRE * big_g:
        return d, big_g, st - mean * tsum, tsum, 0
    s1, s2, st, tsum = ks.gap_moments(u, sigma, h, m, t, d)
    mean = s1 / nc
    return d + mean, max(s2 - s1 * mean, 0.0), st - mean * tsum, tsum, 1


def _final_complementarity(ks, u, h, p, d, load_control, m, t, p_max, bounded):
    """Complementarity (m), approach (m) and free-set size for the final ``p`` (fresh mask)."""
    nc = int(ks.free_mask(p, m, p_max, bounded))
    if load_control and nc:
        s1, _, _, _ = ks.gap_moments(u, 1.0, h, m, t, 0.0)
        d = s1 / nc
    elif load_control:
        d = ks.on_host(fully_bound_approach, u, h, p, d)
    s1, s2, _, _ = ks.gap_moments(u, 1.0, h, m, t, d)
    rms = np.sqrt(max(s2, 0.0) / nc) if nc else 0.0
    pen = ks.worst_violation(p, u, h, d, m, p_max, bounded)
    return max(rms, pen), d, nc


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
    status, message = _status_message(converged, stalled, it, residual, tol, shape, p)
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


def _status_message(converged, stalled, it, residual, tol, shape, p):
    """Status code (0, 1, 2) and message of a finished CG solve."""
    if converged:
        return CONVERGED, (
            f"Polonsky-Keer CG converged in {it} iterations: residual {residual:.3e} < "
            f"tol {tol:.1e}"
        )
    if stalled is not None:
        return STALLED, f"{stalled}; stopped after {it} iterations at residual {residual:.3e}"
    return ITERATION_CAP, (
        f"Polonsky-Keer CG did not converge in {it} iterations: residual "
        f"{residual:.3e} > tol {tol:.1e} (grid {shape[0]}x{shape[1]}, "
        f"{int(np.count_nonzero(p))} contact pixels)"
    )
