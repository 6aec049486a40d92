"""The element-wise passes of the preconditioned iteration (:mod:`.preconditioned`).

Each pass is one compiled sweep over flat float64 arrays: pressures ``p`` and bounds
``p_max`` in Pa, displacements ``u``, heights ``h``, gaps and the gradient ``gf`` in m, the
preconditioned gradient ``w`` and the direction ``t`` in Pa. A bound ``p_max`` is an array
of the grid's size or of size 1 (one bound for every point; ``inf`` for the hard wall). The
free set is a uint8 mask: the points strictly between their bounds, and those at a bound
whose gap pulls them off it (docs/models.md §2.2, "The preconditioned iteration").

The passes run on one thread: the iteration's transforms, not these sweeps, set its cost
(benchmarks/README.md, benchmark 3).
"""

from __future__ import annotations

import numba
import numpy as np

from . import jit

_SERIAL = {"cache": True, "nogil": True, "fastmath": jit.FASTMATH}


@numba.njit(**_SERIAL)
def _bound(p_max, i):
    """The upper bound of point ``i`` (Pa)."""
    return p_max[i] if p_max.size > 1 else p_max[0]


@numba.njit(**_SERIAL)
def interior_approach(u, h, p, p_max):
    """``(Σ (u - h), count)`` over the points strictly between their bounds: the load
    control's approach ``d`` is their mean gap before ``d`` (m)."""
    total = 0.0
    count = 0
    for i in range(p.size):
        if 0.0 < p[i] < _bound(p_max, i):
            total += u[i] - h[i]
            count += 1
    return total, count


@numba.njit(**_SERIAL)
def free_gradient(u, h, p, p_max, d, free, gf):
    """Mark the free set in ``free`` and write the gap ``u - h - d`` on it into ``gf`` (0
    elsewhere). Returns ``(Σ gf, free points, Σ g² over the interior, interior points,
    largest |g| of a point at a bound whose gap pulls it off)``: the last three give the
    complementarity residual."""
    total = 0.0
    squares = 0.0
    worst = 0.0
    n_free = 0
    n_interior = 0
    for i in range(p.size):
        g = u[i] - h[i] - d
        upper = _bound(p_max, i)
        if 0.0 < p[i] < upper:
            n_interior += 1
            squares += g * g
            pulled = True
        elif (p[i] <= 0.0 and g < 0.0 and upper > 0.0) or (
            p[i] >= upper and g > 0.0 and p[i] > 0.0
        ):
            worst = max(worst, abs(g))
            pulled = True
        else:
            pulled = False
        if pulled:
            free[i] = 1
            gf[i] = g
            total += g
            n_free += 1
        else:
            free[i] = 0
            gf[i] = 0.0
    return total, n_free, squares, n_interior, worst


@numba.njit(**_SERIAL)
def shift_free(x, free, shift):
    """``x -= shift`` on the free set (a mean taken out: load control's zero-sum)."""
    for i in range(x.size):
        if free[i]:
            x[i] -= shift


@numba.njit(**_SERIAL)
def preconditioned_sums(w, gf, t, free):
    """``(Σ w, Σ gf·w, Σ t)`` over the free set: the preconditioned gradient ``w``'s mean
    and its product with the gradient, and the sum of the last direction ``t`` over the
    new free set (which the zero-sum next direction takes out)."""
    total = 0.0
    dot = 0.0
    total_t = 0.0
    for i in range(w.size):
        if free[i]:
            total += w[i]
            dot += gf[i] * w[i]
            total_t += t[i]
    return total, dot, total_t


@numba.njit(**_SERIAL)
def next_direction(w, gf, free, shift, beta, t):
    """``t = w + β t - shift`` on the free set, 0 off it. Returns ``Σ gf·t``."""
    dot = 0.0
    for i in range(t.size):
        if free[i]:
            value = w[i] + beta * t[i] - shift
            t[i] = value
            dot += gf[i] * value
        else:
            t[i] = 0.0
    return dot


@numba.njit(**_SERIAL)
def step(p, t, tau, p_max, floor, idx, added):
    """``p ← clip(p - τ t, 0, p_max)`` in place, a pressure below ``floor`` (round-off of
    the field's, Pa) set to 0. The first ``idx.size`` points the clip moved are recorded:
    their flat index in ``idx`` and the pressure the clip added to the step in ``added``
    (Pa). Returns ``(Σ p, Σ p strictly between the bounds, Σ |Δp|, points clipped, max
    p)`` after the step."""
    total = 0.0
    inner = 0.0
    change = 0.0
    clipped = 0
    peak = 0.0
    for i in range(p.size):
        old = p[i]
        free = old - tau * t[i]
        upper = _bound(p_max, i)
        new = free
        if free < floor:
            new = 0.0
        elif free >= upper:
            new = upper
        else:
            inner += new
        if new != free:
            if clipped < idx.size:
                idx[clipped] = i
                added[clipped] = new - free
            clipped += 1
        p[i] = new
        total += new
        change += abs(new - old)
        peak = max(peak, new)
    return total, inner, change, clipped, peak


@numba.njit(**_SERIAL)
def follow_step(u, r, t, tau, compliance, factor):
    """``u ← factor·(u - τ (r + c t))``: the displacement (m) after a step along ``t`` whose
    response ``r = K t`` is known, ``c`` a Winkler compliance per point (m/Pa; an empty
    array for none), the whole field then scaled by ``factor`` (load control)."""
    winkler = compliance.size > 0
    for i in range(u.size):
        du = r[i] + compliance[i] * t[i] if winkler else r[i]
        u[i] = factor * (u[i] - tau * du)


@numba.njit(**_SERIAL)
def scale_interior(p, p_max, factor):
    """Scale the points strictly between their bounds by ``factor``, clipped to their
    bound. Returns ``(Σ p, Σ p strictly between the bounds)`` after (Pa)."""
    total = 0.0
    inner = 0.0
    for i in range(p.size):
        upper = _bound(p_max, i)
        if 0.0 < p[i] < upper:
            value = p[i] * factor
            if value >= upper:
                value = upper
            else:
                inner += value
            p[i] = value
        total += p[i]
    return total, inner


@numba.njit(**_SERIAL)
def interior_sum(p, p_max):
    """``(Σ p, Σ p over the points strictly between their bounds)`` (Pa)."""
    total = 0.0
    inner = 0.0
    for i in range(p.size):
        total += p[i]
        if 0.0 < p[i] < _bound(p_max, i):
            inner += p[i]
    return total, inner


def bounds_array(constraint, n: int) -> np.ndarray:
    """The constraint's upper bound as the array the passes read (size 1 or ``n``, Pa)."""
    p_max = getattr(constraint, "p_max", np.inf)
    if np.isscalar(p_max):
        return np.array([float(p_max)])
    return np.ascontiguousarray(p_max, dtype=np.float64).reshape(n)
