"""Polonsky & Keer (1999) constrained conjugate gradient for the hard-wall contact problem.

Problem (SI units): find the pressure ``p >= 0`` (Pa) on the grid such that the gap
``g = K*p - h - d`` (m) satisfies ``g >= 0`` everywhere and ``g = 0`` where ``p > 0``, with
either the total force ``A0 Σp = W`` prescribed (load control; ``d`` is then the Lagrange
multiplier of the force constraint) or the rigid-body approach ``d`` prescribed
(displacement control). ``K*`` is a convolution operator (m/Pa), ``A0`` the pixel area.

Algorithm (docs/models.md §2.2), per iteration on the free set ``Ic`` (``p > 0``):
gap ``g`` (load control: minus its mean over ``Ic``, which is the approach ``d``),
``G = Σ_Ic g²``, conjugate direction ``t = g + δ (G/G_old) t`` on ``Ic`` (0 elsewhere;
load control: minus its mean over ``Ic``), ``r = K*t``, step ``τ = Σ g t / Σ r t``,
``p ← max(p - τ t, 0)``; points with ``p = 0`` and ``g < 0`` (penetrating but unloaded)
get ``p ← -τ g`` and join ``Ic``; load control rescales ``p`` to the target force.

Departures from the paper, measured in benchmarks/README.md. Under load control Polonsky &
Keer keep ``t`` as built and subtract the mean of ``r`` over ``Ic`` in the step; here ``t``
itself is given zero sum over ``Ic`` (it loses it where points were clipped), so the step
keeps the force on ``Ic`` and ``Σ r t = Σ t·(K*t)`` needs nothing of ``r`` but the quadratic
form, which the fused loop takes from the spectrum (Parseval) before the inverse transform.
Iterations to 1e-8 stay within 3 % of Polonsky & Keer's form on rough surfaces (97 against
100 at 512², 123 against 123 at 1024², periodic and not) and drop on a small sphere (21-28
against 25-29 at 64²); the fixed point is the same. Second, Polonsky & Keer reset the
conjugation to steepest descent (``δ = 0``) whenever *any* point is added. On rough
surfaces a handful of edge points is added almost every iteration, so the original rule
runs steepest descent ~90 % of the time. Here the reset happens only when the added points
exceed ``RESET_FRACTION`` (1 %) of the free set; small additions keep the conjugation.
Iterations to 1e-8 drop 2-4x (e.g. 368 → 100 at 512², 483 → 123 at 1024²) and the
converged field is the same (the fixed point does not depend on the direction rule).

Convergence: two dimensionless measures,

* ``complementarity = max(rms_Ic |g|, max_violators |g|) / h_scale`` with ``h_scale`` the
  rms height of the indenter (the natural length scale of the problem): the rms gap left
  on the contact set and the worst penetration off it. It costs nothing (it comes from
  ``G``), so it is recorded every iteration as the residual;
* ``change = Σ|p - p_old| / Σp``, the relative pressure change, computed (3 passes) only
  once the complementarity is below ``tol``.

The solve has converged when both are below ``tol``, the complementarity re-evaluated
with a freshly convolved ``u`` (never the incrementally updated one); the reported final
residual is the larger of the two. The outcome's ``status`` is 0 (converged), 1
(``max_iter`` reached) or 2 (stalled: a periodic displacement-controlled solve reached full
contact, where the mean pressure is undetermined, or the best residual has not fallen by
``STALL_FACTOR`` in ``STALL_WINDOW`` iterations, see :class:`.stall.StallMonitor`); see
:class:`amontons.contact.ContactResult`.

Cost: ``r = K*t`` is at most one convolution per iteration. ``u = K*p`` would be a second
one, but
the new pressure is ``s (p - τ t + c)`` with ``c`` non-zero only on the points the
projection clipped or the violator step added, so ``u ← s (u - τ K*t + K*c)``: with no such
point this needs no convolution at all, and with at most ``SPARSE_MAX`` of them an operator
that offers ``add_point_responses`` (the periodic one) adds their responses directly (a
few grid passes each). Otherwise, and at least every ``refresh`` iterations and before
convergence is declared, ``u`` is recomputed from scratch. The free set is updated
sparsely (see :class:`HardWall`), the axpy updates use BLAS, and work arrays are
SIMD-aligned so the FFTW plans run on them without copies. The fused loop takes ``r = K*t``
in halves: when ``u`` is recomputed anyway it skips the inverse transform of ``K*t``,
which only the incremental update needs (:mod:`amontons.contact.fused`).

Two implementations of the same loop: the default runs the element-wise work in four fused
numba sweeps (:mod:`amontons.contact.fused`, :mod:`amontons.contact.kernels`; point
responses for up to 12 periodic / 32 non-periodic changed points, sums independent of the
thread count); ``kernels=False`` runs the numpy loop below, the reference the tests compare
against (benchmarks/README.md, benchmark 1).

Extension points: the constraint is an object with three methods (:class:`HardWall`;
:class:`BoundedWall` for ``0 <= p <= p_max``, displacement control), and the operator is
any symmetric positive-definite linear callable ``op(x, out=...)``, so a Winkler term
``K*t + t/k`` is a wrapper around the convolution.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial

import numpy as np
from scipy.linalg.blas import daxpy as _axpy

from . import fft as _fft
from .result import CONVERGED, ITERATION_CAP, STALLED, ConvergenceError
from .stall import StallMonitor

_ALIGNED_BACKEND = "pyfftw" if _fft.HAVE_PYFFTW else "numpy"


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
    when their gap opens (``g > 0``). Load control runs on the fused loop only, which
    imposes the load on the free points and leaves those at the bound
    (:func:`amontons.contact.bounded_load.impose_bounded_load`); a rescale of the whole field, as
    the numpy loop does, would push points through the bound.
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
_EMPTY_F = np.empty(0, dtype=np.float64)
# At most this many changed points (clipped + added) are applied to u as point responses
# (a few grid passes each) instead of a full convolution.
SPARSE_MAX = 3
# Reset the conjugation to steepest descent only when the points added to the free set in
# one iteration exceed this fraction of it (module docstring; 0 = the original PK rule).
RESET_FRACTION = 0.01


@dataclass
class CGOutcome:
    """Raw output of :func:`polonsky_keer` (fields in SI units).

    ``status``: 0 converged, 1 ``max_iter`` reached, 2 stalled; ``message`` says which,
    with the iterations and the residual.
    """

    pressure: np.ndarray
    displacement_field: np.ndarray
    gap: np.ndarray
    rigid_displacement: float
    iterations: int
    residual: float
    history: np.ndarray
    status: int
    message: str
    convolutions: float
    info: dict = field(default_factory=dict)

    @property
    def converged(self) -> bool:
        """True when ``status == 0``."""
        return self.status == CONVERGED


def polonsky_keer(
    operator,
    heights,
    *,
    pixel_area,
    h_scale,
    p_init,
    load=None,
    displacement=None,
    tol=1e-8,
    max_iter=1000,
    refresh=100,
    constraint=None,
    raise_on_failure=True,
    kernels=True,
    threads=None,
) -> CGOutcome:
    """Solve the contact problem by constrained conjugate gradients.

    Parameters
    ----------
    operator : callable
        ``operator(x, out=array) -> array``: symmetric positive-definite linear map from
        pressure (Pa) to displacement (m) on the grid of ``heights``.
    heights : ndarray
        Rigid indenter heights, m (larger = closer to the substrate).
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
    tol : float
        Tolerance on the residual (dimensionless).
    max_iter : int
        Iteration cap.
    refresh : int
        Recompute ``u = K*p`` from scratch at least every ``refresh`` iterations. The
        incrementally updated ``u`` drifts from a fresh ``K*p`` by ~2e-15 of its peak over
        50-100 linear and sparse updates (512² and 1024² benchmark surfaces, fused path;
        benchmarks/README.md), and convergence is always declared on a fresh ``u``, so the
        refresh is a safeguard, not an accuracy knob.
    constraint : HardWall, optional
        The inequality constraint (default: hard wall).
    raise_on_failure : bool
        Raise :class:`ConvergenceError` when the solve stops without converging (status 1
        or 2); else return the last iterate with that status.
    kernels : bool
        True (default): run the iteration's element-wise work in fused numba kernels
        (:mod:`amontons.contact.fused`); False: the numpy loop below, kept as the reference
        the tests compare against (same iterates up to round-off).
    threads : int, optional
        Threads of the fused kernels (default: the operator's FFTW ``threads``, else 1).
    """
    if (load is None) == (displacement is None):
        raise ValueError("exactly one of load and displacement must be given")
    constraint = HardWall() if constraint is None else constraint
    if constraint.bounded and load is not None and not kernels:
        # the fused loop imposes the load on the free points (bounded_load.impose_bounded_load);
        # the numpy reference loop only rescales the whole field, which would push points
        # at the bound through it
        raise ValueError(
            "a bounded constraint under load control needs the fused loop (kernels=True); "
            "the numpy loop takes displacement control"
        )
    if kernels:
        from .fused import fused_polonsky_keer  # numba import and kernel load on first use

        return fused_polonsky_keer(
            operator,
            heights,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p_init,
            load=load,
            displacement=displacement,
            tol=tol,
            max_iter=max_iter,
            refresh=refresh,
            constraint=constraint,
            raise_on_failure=raise_on_failure,
            threads=_kernel_threads(operator, threads),
            sparse_max=None,
            reset_fraction=RESET_FRACTION,
            finish=partial(_finish, constraint, tol, raise_on_failure, pixel_area),
        )
    load_control = load is not None
    shape = heights.shape
    n = heights.size

    def buf():
        # SIMD-aligned work arrays let the FFT plans run on them without copies
        return _fft.empty(n, np.float64, _ALIGNED_BACKEND)

    h = buf()
    h[:] = np.ravel(heights)
    p = buf()
    p[:] = np.ravel(p_init)
    if p.min() < 0:
        raise ValueError("p_init must be >= 0")
    if constraint.bounded:
        # a warm start from another problem may exceed this one's bound; start admissible
        np.minimum(p, constraint.p_max, out=p)
    calls = 0

    def conv(x, out):
        nonlocal calls
        calls += 1
        operator(x.reshape(shape), out=out.reshape(shape))
        return out

    if load_control:
        total = p.sum()
        if not total > 0:
            p[:] = 1.0
            total = p.size
        p *= load / (pixel_area * total)
    u, g, gm, m, r, tmp, p_new = (buf() for _ in range(7))
    t = buf()
    t[:] = 0.0
    bwork = np.empty(n, dtype=bool)
    conv(p, u)
    nc = constraint.free_mask(p, m, bwork)
    delta = 0.0
    g_old = 1.0
    since_fresh = 0
    resets = 0  # iterations that added violators and fell back to steepest descent
    history = []
    d = 0.0 if load_control else float(displacement)
    residual = np.inf
    converged = False
    stalled = None  # message when the solve cannot go on (status 2)
    it = 0
    # periodic kernel with q = 0 set to 0: a uniform pressure over the whole grid costs no
    # displacement, so displacement control is singular once every point is in contact
    singular_full = getattr(operator, "periodic", False) and not load_control
    # operators that can add the response of a few point loads cheaply (the periodic one)
    sparse_ok = hasattr(operator, "add_point_responses")
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
            it -= 1  # this iteration did not run
            break
        # --- gap on the free set m (maintained sparsely, see HardWall) ---------------
        np.subtract(u, h, out=g)
        if nc == 0:
            # only possible in displacement control (load control keeps Σp = W > 0):
            # start the free set from the points the constraint says should be free
            # (penetrating and unloaded; with a bound, also open points at the bound -
            # those at the bound that penetrate are where they belong)
            g -= d
            m[:] = 0.0
            start = constraint.violators(p, g, m)
            nc = int(start.size)
            if nc == 0:
                # every point is at a bound or open and unloaded: already the solution
                residual = 0.0
                history.append(0.0)
                converged = True
                since_fresh = 1  # recompute u below
                break
            m[start] = 1.0
        elif load_control:
            # rigid-body approach = mean of (u - h) over the contact set (Lagrange mult.)
            d = float(np.dot(g, m)) / nc
            g -= d
        else:
            g -= d
        np.multiply(g, m, out=gm)
        big_g = float(np.dot(gm, gm))
        # --- conjugate direction (t is already 0 off the free set) -------------------
        beta = delta * big_g / g_old if g_old > 0 else 0.0
        if beta:
            # t_new = g + β t_old built in gm's buffer by one axpy, then the buffers swap
            # (gm is not needed again this iteration); Σ g t_new = G + β Σ g t_old
            g_dot_t = big_g + beta * float(np.dot(gm, t))
            # load control: t_old loses its sum over the free set where points were
            # clipped; take it out again (t is 0 off the free set, so t.sum() is that sum)
            # so the step keeps the total force. Σ_Ic g = 0 leaves Σ g t_new unchanged
            shift = beta * float(t.sum()) / nc if load_control else 0.0
            _axpy(t, gm, a=beta)
            t, gm = gm, t
            if shift:
                _axpy(m, t, a=-shift)
        else:
            np.copyto(t, gm)
            g_dot_t = big_g
        g_old = big_g
        conv(t, r)
        # load control: Σ_Ic t = 0 (above), so the mean of r over Ic, which Polonsky &
        # Keer subtract, drops out of Σ r t. A one-point free set has no direction that
        # keeps its force (its t is round-off): no descent direction (below)
        rt = 0.0 if load_control and nc == 1 else float(np.dot(r, t))
        if not (rt > 0 and np.isfinite(rt)):
            # no descent direction: the gap on the free set is nil or round-off (uniform
            # full contact; a one-pixel free set, whose gap is 0 by definition of d under
            # load control) or conjugacy was lost to round-off. The solution if that gap is
            # below tol and nothing penetrates off the free set; penetrating points join the
            # free set at p = 0 and the next (steepest-descent) iteration moves them
            ol = constraint.violators(p, g, m)
            pen = float(np.abs(g[ol]).max()) if ol.size else 0.0
            residual = max(np.sqrt(big_g / nc), pen) / h_scale
            if residual < tol and since_fresh:
                # judge it on a freshly convolved u, never the incremental one
                conv(p, u)
                since_fresh = 0
                history.append(residual)
                continue
            if residual < tol:
                history.append(residual)
                converged = True
                break
            m[ol] = 1.0
            nc += ol.size
            # lost conjugacy to round-off: restart from steepest descent
            delta = 0.0
            g_old = 0.0
            history.append(residual)
            continue
        tau = g_dot_t / rt
        # --- update ---------------------------------------------------------------
        np.multiply(t, -tau, out=p_new)
        p_new += p
        clipped = constraint.project(p_new, m)
        if clipped.size:
            # pressure added by the projection (for the sparse displacement update)
            c_clip = p_new[clipped] - (p[clipped] - tau * t[clipped])
            t[clipped] = 0.0  # clipped points leave the free set, and the direction
        ol = constraint.violators(p_new, g, m)
        if ol.size:
            p_new[ol] -= tau * g[ol]
            m[ol] = 1.0
            if ol.size > RESET_FRACTION * nc:
                delta = 0.0
                resets += 1
            else:
                delta = 1.0
        else:
            delta = 1.0
        nc += ol.size - clipped.size
        s = 1.0
        if load_control:
            s = load / (pixel_area * p_new.sum())
            p_new *= s
        changes = clipped.size + ol.size
        if since_fresh >= refresh or (changes and not (sparse_ok and changes <= SPARSE_MAX)):
            conv(p_new, u)
            since_fresh = 0
        else:
            # linearity: K*(s (p - τ t + c)) = s (u - τ K*t + K*c), c the few pressures set
            # by projection and violators: no convolution needed
            _axpy(r, u, a=-tau)
            if changes:
                idx = np.concatenate([clipped, ol])
                vals = np.concatenate([c_clip if clipped.size else _EMPTY_F, -tau * g[ol]])
                operator.add_point_responses(u.reshape(shape), idx, vals)
            u *= s
            since_fresh += 1
        p, p_new = p_new, p
        # complementarity of the *previous* p, free from this iteration's numbers: the rms
        # gap on the free set and the worst penetration off it
        pen = float(np.abs(g[ol]).max()) if ol.size else 0.0
        comp = max(np.sqrt(big_g / nc_prev(nc, ol, clipped)), pen) / h_scale
        residual = comp
        if comp < tol:
            # only now pay for the relative pressure change (3 passes) and a fresh check
            np.subtract(p, p_new, out=tmp)
            np.abs(tmp, out=tmp)
            psum = p.sum()
            change = float(tmp.sum() / psum) if psum > 0 else 0.0
            residual = max(change, comp)
            if change < tol:
                if since_fresh:
                    conv(p, u)
                    since_fresh = 0
                comp_now, d_now = _final_complementarity(
                    u, h, p, d, load_control, constraint, m, g, gm, bwork
                )
                comp_now /= h_scale
                residual = max(change, comp_now)
                if comp_now < tol:
                    d = d_now
                    converged = True
                # the fresh mask replaces the sparsely maintained one
                nc = int(m.sum())
                np.multiply(t, m, out=t)
        history.append(residual)
        if converged:
            break
    if since_fresh:
        conv(p, u)
    return _finish(
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
        calls=calls,
        resets=resets,
        shape=shape,
    )


def _kernel_threads(operator, threads):
    """Threads for the fused kernels: ``threads``, else the operator's, else 1."""
    if threads is None:
        base = getattr(operator, "operator", operator)  # a Winkler wrapper's convolution
        threads = getattr(base, "threads", 1)
    if not (isinstance(threads, int | np.integer) and threads >= 1):
        raise ValueError(f"threads must be a positive integer, got {threads!r}")
    return int(threads)


def _finish(
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
    """The CGOutcome of a finished loop (``p`` Pa and ``u = K*p`` m, flat and fresh);
    raises ConvergenceError on failure when ``raise_on_failure``. ``p`` and ``u`` are the
    loop's own arrays, allocated for this solve: the outcome holds them without a copy (at
    2048² two copies and a temporary cost ~0.2 s of fresh pages per solve)."""
    gap = np.subtract(u, h)
    if load_control and p.sum() > 0:
        m = np.empty(p.size)
        nc = constraint.free_mask(p, m, np.empty(p.size, dtype=bool))
        if nc:
            d = float(np.dot(gap, m) / nc)
        else:
            # bounded, every loaded point at the bound: the force does not fix d
            from .bounded_load import fully_bound_approach

            d = fully_bound_approach(u, h, p, d)
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
    return CGOutcome(
        pressure=p.reshape(shape),
        displacement_field=u.reshape(shape),
        gap=gap.reshape(shape),
        rigid_displacement=float(d),
        iterations=it,
        residual=float(residual),
        history=hist,
        status=status,
        message=message,
        convolutions=calls,
        info={"steepest_descent_resets": resets, **(extra or {})},
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


def nc_prev(nc, ol, clipped):
    """Size of the free set at the start of the iteration (for the rms gap)."""
    return max(nc - ol.size + clipped.size, 1)


def _final_complementarity(u, h, p, d, load_control, constraint, m, g, gm, bwork):
    """Complementarity measure (m) and rigid-body approach for the final ``p``."""
    np.subtract(u, h, out=g)
    nc = constraint.free_mask(p, m, bwork)
    if load_control and nc:
        d = float(np.dot(g, m)) / nc
    g -= d
    np.multiply(g, m, out=gm)
    rms = np.sqrt(float(np.dot(gm, gm)) / nc) if nc else 0.0
    ol = constraint.violators(p, g, m)
    pen = float(np.abs(g[ol]).max()) if ol.size else 0.0
    return max(rms, pen), d
