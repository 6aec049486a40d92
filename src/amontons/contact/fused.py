"""The Polonsky–Keer CG loop on fused kernels (the default path of
:func:`amontons.contact.cg.polonsky_keer`; ``kernels=False`` there runs the numpy reference).

Same algorithm, same iterates up to round-off, as the numpy loop in :mod:`.cg` (its module
docstring and docs/models.md §2.2 describe it); what differs is how the element-wise work is
done. One iteration is four sweeps over the grid plus the convolution ``r = K*t``
(:mod:`.kernels`):

1. ``gap_moments``: approach ``d`` (load control), ``G = Σ_Ic g²`` and ``Σ g t_old``;
2. ``direction``: ``t = g·m + β t``;
3. ``step_dots``: ``Σ r t`` and ``Σ_Ic r`` (plus the Winkler term of a hardening solve);
4. ``update``: step, projection, violators, free-set update, ``Σ p`` and ``u -= τ r``.

Load control rescales ``p`` (and so ``u``) to the target force every iteration. Here that
rescale costs no pass: the stored pressure ``P`` and displacement ``U`` carry one common
scale ``sigma`` (true ``p = sigma·P``, ``u = sigma·U``); ``u = K*p`` is linear, so
``U = K*P`` stays true when only ``sigma`` changes.

Convergence, status codes, the full-convolution refresh and the sparse point-response
update are those of :mod:`.cg`.
"""

from __future__ import annotations

import numpy as np

from . import fft as _fft
from . import kernels as _k
from .result import CONVERGED, STALLED, ConvergenceError
from .stall import StallMonitor

# Most changed points (clipped + added) applied to u as point responses instead of a full
# convolution. One point costs a sweep of the real-space kernel (kernels.add_point_responses,
# ~0.6 ms at 1024² periodic, ~0.9 ms at 1024² non-periodic) against ~9 ms for a periodic
# convolution and ~35 ms for a padded one (benchmarks/README.md, "Fewer convolutions"), so
# the break-even is ~15 points periodic and ~40 padded; the limits stay below it.
SPARSE_MAX_PERIODIC = 12
# Largest Σa²/G of the one-pass moments about the previous approach (see _centred_moments).
RECENTRE = 1e3
SPARSE_MAX_PADDED = 32


def fused_polonsky_keer(
    operator,
    heights,
    *,
    pixel_area,
    h_scale,
    p_init,
    load,
    displacement,
    tol,
    max_iter,
    refresh,
    constraint,
    raise_on_failure,
    threads,
    sparse_max,
    reset_fraction,
    finish,
):
    """Fused-kernel version of :func:`amontons.contact.cg.polonsky_keer` (arguments
    validated there; ``finish`` builds its :class:`~amontons.contact.cg.CGOutcome`)."""
    with _k.kernel_threads(threads):
        return _loop(
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
            sparse_max=sparse_max,
            reset_fraction=reset_fraction,
            finish=finish,
        )


def _winkler_parts(operator):
    """``(convolution, compliance)`` of an elastic-plus-Winkler operator (compliance m/Pa,
    added inside :func:`.kernels.step_dots`), or ``(operator, None)``."""
    compliance = getattr(operator, "compliance", None)
    base = getattr(operator, "operator", None)
    if compliance is None or base is None:
        return operator, None
    return base, np.ascontiguousarray(compliance, dtype=np.float64).ravel()


def _bound_array(constraint, n):
    """``(p_max per point, bounded flag)`` for the kernels (Pa)."""
    if not constraint.bounded:
        return np.full(1, np.inf), False
    p_max = np.broadcast_to(np.asarray(constraint.p_max, dtype=np.float64), (n,))
    return np.ascontiguousarray(p_max), True


def _loop(
    operator,
    heights,
    *,
    pixel_area,
    h_scale,
    p_init,
    load,
    displacement,
    tol,
    max_iter,
    refresh,
    constraint,
    raise_on_failure,
    sparse_max,
    reset_fraction,
    finish,
):
    load_control = load is not None
    shape = heights.shape
    n = heights.size
    backend = "pyfftw" if _fft.HAVE_PYFFTW else "numpy"

    def buf():
        # SIMD-aligned work arrays let the FFT plans run on them without copies
        return _fft.empty(n, np.float64, backend)

    base_op, compliance = _winkler_parts(operator)
    winkler = compliance is not None
    comp_arg = compliance if winkler else np.zeros(1)
    p_max, bounded = _bound_array(constraint, n)
    h = buf()
    h[:] = np.ravel(heights)
    p = buf()
    p[:] = np.ravel(p_init)
    if p.min() < 0:
        raise ValueError("p_init must be >= 0")
    if bounded:
        np.minimum(p, p_max, out=p)
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
    # bounded load control: the force is imposed on the free points only (module docstring)
    bounded_load = bounded and load_control
    target = load / pixel_area if load_control else 0.0  # Σp, Pa
    t = buf()
    t[:] = 0.0
    m = np.empty(n, dtype=np.uint8)
    if bounded_load:
        _k.free_mask(p, m, p_max, bounded)
        impose_bounded_load(p, m, t, p_max, target, np.zeros(n), h)
    u, r = buf(), buf()
    p_old = None  # a copy of p, taken only when the step may converge
    nch = _k.n_chunks(n)
    idx_buf = np.zeros((nch, _k.SLOTS), dtype=np.int64)
    val_buf = np.zeros((nch, _k.SLOTS))
    counts = np.zeros((nch, 2), dtype=np.int64)
    violators = np.zeros(nch, dtype=np.int64)
    conv(p, u)
    sigma = 1.0  # true p = sigma·p, u = sigma·u (module docstring)
    nc = int(_k.free_mask(p, m, p_max, bounded))
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
    if sparse_max is None:
        sparse_max = (
            SPARSE_MAX_PERIODIC if getattr(base_op, "periodic", False) else SPARSE_MAX_PADDED
        )
    green = None
    monitor = StallMonitor()  # as in cg.polonsky_keer
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
            # bound (module doc of .cg): start the free set from the points the constraint
            # says should be free
            if load_control:
                d = fully_bound_approach(sigma * u, h, p, d)
            g = sigma * u - h - d
            mf = np.zeros(n)
            start = constraint.violators(sigma * p, g, mf)
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
        if load_control:
            d, big_g, gt_old, recentred = _centred_moments(u, sigma, h, m, t, d, nc)
            recentres += recentred
        else:
            _, big_g, gt_old, _ = _k.gap_moments(u, sigma, h, m, t, d)
        beta = delta * big_g / g_old if g_old > 0 else 0.0
        g_dot_t = big_g + beta * gt_old if beta else big_g
        tsum = _k.direction(u, sigma, h, m, t, d, beta, p, p_max, bounded, violators)
        g_old = big_g
        conv_t(base_op, t, r, shape)
        calls += 1
        rt, rm = _k.step_dots(r, t, m, comp_arg, winkler)
        if load_control:
            rt -= rm / nc * tsum
        if not (rt > 0 and np.isfinite(rt)):
            # no descent direction (cg.polonsky_keer says when): the solution if the gap on
            # the free set is below tol and nothing penetrates off it, judged on a freshly
            # convolved u; penetrating points join the free set at p = 0 and the next
            # (steepest-descent) iteration moves them
            g = sigma * u - h - d
            ol = constraint.violators(sigma * p, g, m.astype(np.float64))
            pen = float(np.abs(g[ol]).max()) if ol.size else 0.0
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
            delta = 0.0
            g_old = 0.0
            continue
        tau = g_dot_t / rt
        rms_ok = np.sqrt(big_g / max(nc, 1)) / h_scale < tol
        if rms_ok:
            # the convergence test below needs the pressure change: keep the old field
            # (this pass is paid only in the last iterations; otherwise p is updated in place)
            p_old = np.copy(p) if p_old is None else _copy(p, p_old)
        if bounded_load:
            n_clip, n_add, pen, backtracked = bounded_load_step(
                p, u, h, m, t, p_max, d, tau, target
            )
        else:
            psum, pen = _k.update(
                p,
                p,
                u,
                r,
                t,
                h,
                m,
                p_max,
                bounded,
                sigma,
                d,
                tau,
                violators,
                idx_buf,
                val_buf,
                counts,
            )
            n_clip = int(counts[:, 0].sum())
            n_add = int(counts[:, 1].sum())
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
        if bounded_load:
            # sigma stays 1 and the step rescaled the free points only (bounded_load_step):
            # that changes u by a field of its own, so u is recomputed (a second
            # convolution per iteration)
            conv(p, u)
            since_fresh = 0
            updates["full: bounded load"] += 1
        elif since_fresh >= refresh or (changes and not (sparse_ok and changes <= sparse_max)):
            conv(p, u)
            since_fresh = 0
            updates["full: changes" if changes > sparse_max else "full: refresh"] += 1
        else:
            updates["point responses" if changes else "linear"] += 1
            if changes:
                # u (stored, scale sigma_old) += K*c / sigma_old; u = K*p holds for the stored
                # pair whatever their common scale, so the new scale needs no pass
                idx, vals = _changed_points(counts, idx_buf, val_buf)
                if green is None:
                    green = base_op.real_space_kernel()
                _k.add_point_responses(u.reshape(shape), green, idx, vals / sigma_old)
                if winkler:
                    # a point clipped and re-added appears twice: add.at sums both
                    np.add.at(u, idx, compliance[idx] * vals / sigma_old)
            since_fresh += 1
        comp = max(np.sqrt(big_g / max(nc_start, 1)), pen) / h_scale
        residual = comp
        if comp < tol and rms_ok:
            change, psum_true = _k.relative_change(p, sigma, p_old, sigma_old)
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
                    u, h, p, d, load_control, m, t, p_max, bounded
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
    return finish(
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
        extra={"moment_recentres": recentres, "u_updates": updates},
        shape=shape,
    )


# Rounds of rescale-and-clip allowed to impose the load on the free points; each round clips
# at least one point at p_max or ends, and one or two suffice in practice.
MAX_LOAD_ROUNDS = 50


def impose_bounded_load(p, m, t, p_max, target, u, h):
    """Bounded load control: make ``Σp = target`` (Pa) keeping ``0 <= p <= p_max``.

    The points at ``p_max`` keep their pressure; the free ones (``0 < p < p_max``) are
    scaled by the common factor that makes the sum right: the load control of the hard wall
    restricted to the points whose pressure no bound fixes. A free point the scale pushes
    past ``p_max`` is clipped there and leaves the free set (``m = 0``, ``t = 0``), and the
    scale is taken again; a negative pressure (a point falling from the bound by more than
    its pressure) is clipped to 0 first. Two cases leave nothing to scale and restart the
    field (the caller rebuilds ``m`` and resets the conjugation):

    * every loaded point at the bound and load missing: the deficit goes to the unloaded
      points next to touch, largest ``u - h`` first (``u``, ``h`` in m; ``u`` may be the
      step's linear update, it only orders the candidates), each up to its ``p_max`` —
      what raising the approach until they touch would do;
    * the points at the bound alone carry more than the load: the excess is taken off the
      points at the bound that are most open, largest ``u - h`` first, each down to 0 —
      what lowering the approach until they leave contact would do.

    Flat arrays, in place; ``m`` is uint8. Returns ``(points clipped, restarted)``.
    """
    clipped = 0
    restarted = False
    negative = np.flatnonzero(p < 0.0) if p.min() < 0.0 else None
    if negative is not None:
        p[negative] = 0.0
        m[negative] = 0
        t[negative] = 0.0
        clipped += int(negative.size)
    for _ in range(MAX_LOAD_ROUNDS):
        below = p < p_max
        free_sum = float(p.sum(where=below))
        rest = target - float(p.sum(where=~below))
        if rest < 0.0:
            _release_bound_points(p, p_max, float(p.sum()) - target, u, h)
            restarted = True
            continue
        if not free_sum > 0.0:
            if rest > 0.0:
                _fill_next_points(p, p_max, rest, u, h)
                restarted = True
            return clipped, restarted
        scale = rest / free_sum
        if scale == 1.0:
            return clipped, restarted
        p[below] *= scale
        over = np.flatnonzero(below & (p > p_max))
        if not over.size:
            return clipped, restarted
        p[over] = p_max[over]
        m[over] = 0
        t[over] = 0.0
        clipped += int(over.size)
    return clipped, restarted


# Halvings of the step allowed in bounded_load_step before the load is imposed by moving
# points on or off the bound instead.
MAX_BACKTRACK = 30


def bounded_load_step(p, u, h, m, t, p_max, d, tau, target):
    """One CG step under ``0 <= p <= p_max`` and ``Σp = target`` (bounded load control).

    As ``kernels.update`` (free points step to ``p - τ t``, constrained points that should be
    free move by ``-τ g`` and join, everything is projected onto ``[0, p_max]``), then the
    load is imposed on the free points (:func:`impose_bounded_load`). A step that clips so
    many free points to ``p_max`` that the bound alone carries more than the load (or none
    is left free to carry a deficit) is halved until it does not: the step that leaves the
    previous, admissible field (τ → 0) always qualifies. ``u`` (m) must be ``K*p`` of the
    current ``p`` (Pa); the free set ``m`` is rebuilt from the new field and ``t`` is zeroed
    off it. Flat arrays, in place.

    Returns ``(points that left the free set, points that joined it, max |g| over the
    joining points (m), whether the step was shortened or the load imposed by a
    restart)``: either way the conjugation is reset.
    """
    g = u - h - d
    free = m != 0
    rise = ~free & (p <= 0.0) & (g < 0.0) & (p_max > 0.0)
    fall = ~free & (p >= p_max) & (g > 0.0) & (p > 0.0)
    add = np.flatnonzero(rise | fall)
    pen = float(np.abs(g[add]).max()) if add.size else 0.0
    step = tau
    shortened = False
    for _ in range(MAX_BACKTRACK):
        q = p - step * t
        q[add] = p[add] - step * g[add]
        np.clip(q, 0.0, p_max, out=q)
        below = q < p_max
        rest = target - float(q.sum(where=~below))
        if rest >= 0.0 and (rest == 0.0 or float(q.sum(where=below)) > 0.0):
            break
        step *= 0.5
        shortened = True
    p[:] = q
    _, restarted = impose_bounded_load(p, m, t, p_max, target, u, h)
    new = (p > 0.0) & (p < p_max)
    left = int(np.count_nonzero(free & ~new))
    joined = int(np.count_nonzero(~free & new))
    m[:] = new
    t *= m
    return left, joined, pen, shortened or restarted


def _fill_next_points(p, p_max, deficit, u, h):
    """Put ``deficit`` (Pa, summed) on the unloaded points next to touch, smallest gap
    ``u - h - d`` (so smallest ``u - h``) first, each up to its ``p_max``
    (impose_bounded_load)."""
    cand = np.flatnonzero((p <= 0.0) & (p_max > 0.0))
    order = cand[np.argsort(u[cand] - h[cand], kind="stable")]
    room = np.cumsum(p_max[order])
    k = int(np.searchsorted(room, deficit)) + 1  # points needed
    take = order[:k]
    p[take] = p_max[take]
    # the last one takes what is left (its room minus the overshoot)
    p[take[-1]] -= room[k - 1] - deficit if k <= room.size else 0.0


def _release_bound_points(p, p_max, excess, u, h):
    """Take ``excess`` (Pa, summed) off the points at the bound that open first as the
    approach falls, largest gap ``u - h - d`` (so largest ``u - h``) first, each down to 0
    (impose_bounded_load)."""
    cand = np.flatnonzero(p >= p_max)
    order = cand[np.argsort(h[cand] - u[cand], kind="stable")]
    held = np.cumsum(p[order])
    k = min(int(np.searchsorted(held, excess)) + 1, held.size)  # points to release
    take = order[:k]
    p[take[-1]] = held[k - 1] - excess if held[k - 1] > excess else 0.0
    p[take[:-1]] = 0.0


def fully_bound_approach(u, h, p, d):
    """Approach (m) of a load-controlled bounded solve without free points: every loaded
    point sits at ``p_max``, so the force does not fix the approach; any ``d`` with
    ``g = u - h - d <= 0`` on the loaded points and ``>= 0`` on the others is a solution.
    The smallest, ``max(u - h)`` over the loaded points, is taken: the least penetration
    (for penetration hardness, the least plastic flow that carries the load). ``d`` is
    returned unchanged when no point is loaded."""
    loaded = p > 0.0
    if not loaded.any():
        return d
    return float(np.max(u[loaded] - h[loaded]))


def _copy(src, dst):
    np.copyto(dst, src)
    return dst


def conv_t(base_op, t, r, shape):
    """``r = K*t`` with the plain convolution (a Winkler term is added by ``step_dots``)."""
    base_op(t.reshape(shape), out=r.reshape(shape))


def _centred_moments(u, sigma, h, m, t, d_old, nc):
    """Load control: the approach ``d`` (m, the mean of ``sigma·u - h`` on the free set),
    ``G = Σ_Ic g²`` (m²) and ``Σ g·t`` with ``g`` centred on it, and whether a second pass
    was needed.

    One pass takes the moments about the previous approach; when that is far from the new
    one (the first iteration, a warm start), ``G = Σa² - (Σa)²/nc`` would cancel
    catastrophically (relative error ~ 1e-16 · Σa²/G), so the moments are taken again about
    the new approach whenever ``Σa² > RECENTRE · G``: G is then good to ~1e-13.
    """
    s1, s2, st, tsum = _k.gap_moments(u, sigma, h, m, t, d_old)
    mean = s1 / nc
    d = d_old + mean
    big_g = max(s2 - s1 * mean, 0.0)
    if s2 <= RECENTRE * big_g:
        return d, big_g, st - mean * tsum, 0
    s1, s2, st, tsum = _k.gap_moments(u, sigma, h, m, t, d)
    mean = s1 / nc
    return d + mean, max(s2 - s1 * mean, 0.0), st - mean * tsum, 1


def _changed_points(counts, idx_buf, val_buf):
    """Flat indices and added pressures (Pa) of the points ``update`` recorded."""
    per = counts.sum(axis=1)
    rows = np.flatnonzero(per)
    idx = np.concatenate([idx_buf[c, : per[c]] for c in rows])
    vals = np.concatenate([val_buf[c, : per[c]] for c in rows])
    return idx, vals


def _final_complementarity(u, h, p, d, load_control, m, t, p_max, bounded):
    """Complementarity (m), approach (m) and free-set size for the final ``p`` (fresh mask)."""
    nc = int(_k.free_mask(p, m, p_max, bounded))
    if load_control and nc:
        s1, _, _, _ = _k.gap_moments(u, 1.0, h, m, t, 0.0)
        d = s1 / nc
    elif load_control:
        d = fully_bound_approach(u, h, p, d)
    s1, s2, _, _ = _k.gap_moments(u, 1.0, h, m, t, d)
    rms = np.sqrt(max(s2, 0.0) / nc) if nc else 0.0
    pen = _k.worst_violation(p, u, h, d, m, p_max, bounded)
    return max(rms, pen), d, nc


__all__ = ["CONVERGED", "fused_polonsky_keer"]
