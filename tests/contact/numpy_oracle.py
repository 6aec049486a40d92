"""The numpy Polonsky–Keer loop: the reference the fused kernels are compared with.

A test oracle, not part of the solver: the solver has one control flow
(:func:`amontons.contact.cg.polonsky_keer`, on the fused kernels of
:mod:`amontons.contact.kernels`); this loop runs the same algorithm (docs/models.md §2.2)
in plain numpy passes, with the hard-wall constraint or a bounded one under displacement
control, so the fused iterates can be held to its to round-off. It was the solver's
``kernels=False`` path before issue 38 and is kept as it was.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg.blas import daxpy as _axpy

from amontons.contact import fft as _fft
from amontons.contact.cg import finish_outcome
from amontons.contact.constraints import HardWall
from amontons.contact.result import STALLED, ConvergenceError
from amontons.contact.stall import StallMonitor

_ALIGNED_BACKEND = "pyfftw" if _fft.HAVE_PYFFTW else "numpy"
_EMPTY = np.empty(0, dtype=np.intp)
_EMPTY_F = np.empty(0, dtype=np.float64)
# At most this many changed points (clipped + added) are applied to u as point responses.
SPARSE_MAX = 3
# Reset the conjugation only when the added points exceed this fraction of the free set:
# under the hard wall, and under a bound (the solver's cg_iteration.RESET_FRACTION and
# BOUNDED_RESET_FRACTION, restated: the oracle does not read the solver's constants).
RESET_FRACTION = 0.01
BOUNDED_RESET_FRACTION = 0.1


def numpy_polonsky_keer(
    operator,
    heights,
    options,
    *,
    pixel_area,
    h_scale,
    p_init,
    load=None,
    displacement=None,
    constraint=None,
):
    """:func:`amontons.contact.cg.polonsky_keer`'s algorithm in numpy passes (same
    arguments, same outcome type; pressures Pa, lengths m). Of ``options``
    (:class:`~amontons.contact.options.CGOptions`) it reads ``tol``, ``max_iter``,
    ``refresh`` and ``raise_on_failure``: it has no kernels to thread and no bounded
    load control."""
    tol, max_iter, refresh = options.tol, options.max_iter, options.refresh
    raise_on_failure = options.raise_on_failure
    if (load is None) == (displacement is None):
        raise ValueError("exactly one of load and displacement must be given")
    constraint = HardWall() if constraint is None else constraint
    reset_fraction = BOUNDED_RESET_FRACTION if constraint.bounded else RESET_FRACTION
    if constraint.bounded and load is not None:
        # the solver imposes the load on the free points (bounded_load.impose_bounded_load);
        # this loop only rescales the whole field, which would push points at the bound
        # through it
        raise ValueError(
            "a bounded constraint under load control needs the fused loop (the solver's "
            "cg.polonsky_keer); the numpy loop takes displacement control"
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
            if ol.size > reset_fraction * nc:
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
        calls=calls,
        resets=resets,
        shape=shape,
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
