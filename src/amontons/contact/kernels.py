"""Fused element-wise kernels of one Polonsky–Keer CG iteration (numba).

The kernel set of :func:`amontons.contact.cg.polonsky_keer`: the element-wise work of one
iteration (masks, reductions, the projection, the violator search, the displacement's
share of the step) in three or four sweeps over the grid (docs/models.md §2.2 gives the
algorithm, :mod:`.cg` the order; a plain numpy loop, the tests' reference, takes ~40):

``gap_moments``   moments of the gap on the free set (approach, ``G``, ``Σ g t_old``,
                  ``Σ t_old``);
``direction``     the conjugate direction ``t = m·(g + β t - shift)``, its violator count
                  per chunk, and the violators of chunks with few of them;
``step_dots``     ``Σ r t`` and ``Σ_Ic r`` from a real-space ``r`` (and the Winkler term
                  ``r += t/k``, so a hardening solve needs no extra pass);
``update``        pressure step, projection onto ``0 <= p <= p_max``, violators, free-set
                  update, ``Σ p`` and, if asked, the displacement axpy ``u -= τ r``, in one
                  sweep, recording the few changed points for the sparse update;
``subtract_scaled``  ``u -= τ r`` when the step left ``u`` alone;
``rescale_free``  bounded load control: the free points scaled to the load, the free set
                  rebuilt and ``u`` carried along (:mod:`.bounded_load`).

Arrays are flat float64 (the free set ``m`` is uint8). Sums are taken over fixed chunks of
``CHUNK`` points and the partial sums added in chunk order, so every result is the same bit
for bit whatever the number of threads (``threads`` only decides who computes which
chunk). Kernels are compiled with ``parallel=True`` and cached on disk (``cache=True``),
and every process runs them from that cache: on a cold one the first call compiles them in
a child process first (:mod:`.jit` says why; the time it takes: benchmarks/README.md,
"Fused kernels"). The thread count is set per call through :func:`numba.set_num_threads`
(see :func:`kernel_threads`).

Units: pressures in Pa, lengths in m; ``sigma`` is the dimensionless scale of the stored
pressure and displacement (true value = ``sigma`` × stored), which lets load control rescale
the field without a pass (see :mod:`amontons.contact.cg_iteration`).

Why one module: numba's disk cache checks only the source file of the function it caches,
so a helper or a constant imported from another file and changed there would leave the
cached machine code stale (numba issue #1833, and numba's notes on ``cache=True``). The
sweeps share their inline helpers (the join test) and the chunk layout (``CHUNK``,
``SLOTS``, ``SCAN``), so they stay in this file (tests/test_architecture.py checks that no
compiled function reads a name imported from another module).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import prange

from . import fft as _fft
from . import jit
from .spectrum import ENTRY_POINTS as SPECTRUM_ENTRY_POINTS

# Points per chunk of a reduction: fixed, so partial sums (and results) do not depend on the
# thread count; small enough to balance 2-8 threads from 512² on, large enough that the
# per-chunk overhead vanishes.
CHUNK = 16384
# Changed points (clipped + added) recorded per chunk. The solver applies changes as point
# responses only when there are at most this many in total (.cg_iteration.SPARSE_MAX_PERIODIC,
# SPARSE_MAX_PADDED), so a chunk never needs more slots than that.
SLOTS = 64
# Points per block of update's search for clipped points and direction's for violators in a
# chunk with a few: blocks without one are passed over after a vectorised test.
SCAN = 256

_JIT = jit.JIT


def n_chunks(n: int) -> int:
    """Number of reduction chunks for ``n`` points."""
    return (n + CHUNK - 1) // CHUNK


def kernel_threads(threads: int):
    """Context: run the kernels on ``threads`` threads (clipped to numba's pool); the first
    call of a process first makes sure they run from numba's disk cache
    (:func:`.jit.kernel_threads`)."""
    return jit.kernel_threads(threads, ENTRY_POINTS)


_INNER = jit.INNER


# Each kernel is a prange over fixed chunks calling an inner loop on the chunk's slices:
# a loop over a slice's own range vectorises, one over ``range(lo, hi)`` of the whole array
# does not, LLVM cannot prove the indices non-negative (benchmarks/README.md, "Why the
# kernels are written as they are").


@numba.njit(**_INNER)
def _moments(u, sigma, h, m, t, shift):
    s1 = 0.0
    s2 = 0.0
    st = 0.0
    tt = 0.0
    for i in range(u.size):
        ti = t[i]
        tt += ti
        # branch-free (vectorises): the mask as a 0/1 factor
        a = (sigma * u[i] - h[i] - shift) * m[i]
        s1 += a
        s2 += a * a
        st += a * ti
    return s1, s2, st, tt


@numba.njit(**_JIT)
def gap_moments(u, sigma, h, m, t, shift):
    """Moments of ``a = sigma·u - h - shift`` (m) on the free set ``m``.

    Returns ``(Σ_m a, Σ_m a², Σ_m a·t, Σ t)``. With ``shift`` the previous approach, the
    approach is ``shift + Σa/nc`` and ``G = Σa² - (Σa)²/nc`` without cancellation (the
    shift is close to the mean).
    """
    n = u.size
    nch = (n + CHUNK - 1) // CHUNK
    part = np.zeros((nch, 4))
    for c in prange(nch):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        s1, s2, st, tt = _moments(u[lo:hi], sigma, h[lo:hi], m[lo:hi], t[lo:hi], shift)
        part[c, 0] = s1
        part[c, 1] = s2
        part[c, 2] = st
        part[c, 3] = tt
    out = np.zeros(4)
    for c in range(nch):
        for k in range(4):
            out[k] += part[c, k]
    return out[0], out[1], out[2], out[3]


@numba.njit(**_INNER)
def _should_join(q, g, ub):
    """The violator test: a constrained point with pressure ``q`` (Pa) and gap ``g`` (m)
    should be free if it is unloaded and penetrating with room to rise, or at ``ub`` and
    open (branch-free, so loops that use it still vectorise)."""
    return ((q <= 0.0) & (g < 0.0) & (q < ub)) | ((q >= ub) & (g > 0.0) & (q > 0.0))


@numba.njit(**_INNER)
def _direction_hard(u, sigma, h, m, t, d, beta, shift):
    """A block of ``direction`` under the hard wall: ``(Σ t, violators)``. A constrained
    point has ``p = 0`` here (points leave the free set only by clipping to 0), so the
    pressure need not be read."""
    acc = 0.0
    k = 0
    for i in range(u.size):
        g = sigma * u[i] - h[i] - d
        v = (g + beta * t[i] - shift) * m[i]
        t[i] = v
        acc += v
        # unloaded and penetrating (branch-free)
        k += (m[i] == 0) & (g < 0.0)
    return acc, k


@numba.njit(**_INNER)
def _direction_bounded(u, sigma, h, m, t, d, beta, shift, p, p_max):
    """A block of ``direction`` under ``0 <= p <= p_max``: ``(Σ t, violators)``."""
    acc = 0.0
    k = 0
    for i in range(u.size):
        g = sigma * u[i] - h[i] - d
        v = (g + beta * t[i] - shift) * m[i]
        t[i] = v
        acc += v
        q = sigma * p[i]
        ub = p_max[i]
        k += (m[i] == 0) & _should_join(q, g, ub)
    return acc, k


@numba.njit(**_JIT)
def direction(u, sigma, h, m, t, d, beta, shift, p, p_max, bounded, violators, vidx, vg):
    """``t ← m·(sigma·u - h - d + beta·t - shift)`` in place (m); returns ``Σ t``.

    Load control passes ``shift = beta·Σ t_old / nc``, which keeps ``Σ t = 0`` on the free
    set (:mod:`.cg`); displacement control passes 0.

    Also counts, per chunk into ``violators``, the constrained points that should be free
    (the violator test of ``update``, which does not depend on the step: ``t = 0`` there).
    A chunk with at most ``SLOTS`` of them records their flat indices into ``vidx[c, :]``
    and their gaps (m) into ``vg[c, :]``, in index order, so that ``update`` visits only
    those points and its clipped ones instead of running its scalar loop over the chunk;
    ``violators[c]`` is then their number as recorded, or ``SLOTS + 1`` if that exceeds the
    slots; a chunk with more than ``SLOTS`` keeps its vectorised count (``update`` only asks
    whether it exceeds ``SLOTS``).
    """
    n = u.size
    nch = (n + CHUNK - 1) // CHUNK
    part = np.zeros(nch)
    for c in prange(nch):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        ubc = p_max[lo:hi] if bounded else p_max
        acc, k = _direction_chunk(
            u[lo:hi], sigma, h[lo:hi], m[lo:hi], t[lo:hi], d, beta, shift, p[lo:hi], ubc,
            bounded, lo, vidx[c], vg[c],
        )  # fmt: skip
        part[c] = acc
        violators[c] = k
    total = 0.0
    for c in range(nch):
        total += part[c]
    return total


@numba.njit(**_INNER)
def _direction_chunk(u, sigma, h, m, t, d, beta, shift, p, p_max, bounded, lo, vidx, vg):
    """One chunk of :func:`direction`, block by block (``SCAN`` points): a block's
    vectorised sweep, then, while the chunk has at most ``SLOTS`` violators, the recording
    of the block's own from L1, not from a second read of the chunk (benchmarks/README.md,
    "Why the kernels are written as they are"). Returns ``(Σ t, violators)`` as
    ``direction`` states them."""
    n = u.size
    acc = 0.0
    k = 0
    recorded = 0
    for b0 in range(0, n, SCAN):
        b1 = min(n, b0 + SCAN)
        if bounded:
            a, kb = _direction_bounded(
                u[b0:b1], sigma, h[b0:b1], m[b0:b1], t[b0:b1], d, beta, shift, p[b0:b1],
                p_max[b0:b1],
            )  # fmt: skip
        else:
            a, kb = _direction_hard(u[b0:b1], sigma, h[b0:b1], m[b0:b1], t[b0:b1], d, beta, shift)
        acc += a
        k += kb
        if kb and k <= SLOTS and recorded <= SLOTS:
            recorded = _record_block_violators(
                u, sigma, h, m, d, p, p_max, bounded, b0, b1, lo, vidx, vg, recorded
            )
    return acc, (k if k > SLOTS else recorded)


@numba.njit(**_INNER)
def _dots(r, t, m):
    rt = 0.0
    rm = 0.0
    for i in range(r.size):
        rt += r[i] * t[i]
        rm += r[i] * m[i]
    return rt, rm


@numba.njit(**_INNER)
def _dots_winkler(r, t, m, compliance):
    rt = 0.0
    rm = 0.0
    for i in range(r.size):
        ri = r[i] + compliance[i] * t[i]
        r[i] = ri
        rt += ri * t[i]
        rm += ri * m[i]
    return rt, rm


@numba.njit(**_JIT)
def step_dots(r, t, m, compliance, winkler):
    """After ``r = K*t``: with ``winkler`` add the Winkler term ``r += compliance·t``
    (compliance m/Pa) in place; return ``(Σ r·t, Σ_m r)``."""
    n = r.size
    nch = (n + CHUNK - 1) // CHUNK
    part = np.zeros((nch, 2))
    for c in prange(nch):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        if winkler:
            rt, rm = _dots_winkler(r[lo:hi], t[lo:hi], m[lo:hi], compliance[lo:hi])
        else:
            rt, rm = _dots(r[lo:hi], t[lo:hi], m[lo:hi])
        part[c, 0] = rt
        part[c, 1] = rm
    out = np.zeros(2)
    for c in range(nch):
        out[0] += part[c, 0]
        out[1] += part[c, 1]
    return out[0], out[1]


@numba.njit(**_JIT)
def update(
    p,
    p_new,
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
    idx,
    val,
    counts,
    keep_mask,
    with_u,
    vidx,
    vg,
    record_max,
):
    """One CG step in one sweep (stored fields, true value = ``sigma`` × stored).

    For each point, with the gap ``g = sigma·u - h - d`` (m) of this iteration:
    free points step to ``p - tau·t`` and are projected onto ``[0, p_max]`` (a clipped
    point leaves the free set and its direction is zeroed); then a constrained point that
    should be free (unloaded and penetrating with room to rise, or at ``p_max`` and open)
    moves by ``-tau·g`` and joins the free set, as in :class:`amontons.contact.constraints.HardWall`
    and :class:`~amontons.contact.constraints.BoundedWall`. With ``with_u``, ``u`` gets
    ``-tau/sigma·r`` in place; without, ``u`` is not written (the gaps of the points that
    may join are still read from it) and ``r`` is not read: the caller brings ``u`` to the
    new pressure itself (:mod:`.cg`).

    ``p_max`` (Pa) has one entry per point when ``bounded`` is 1, else one entry, ignored
    (no upper bound). Changed points are recorded per chunk in ``idx[c, :]`` (flat index)
    and ``val[c, :]`` (pressure added on top of the step, Pa), up to ``SLOTS`` per chunk;
    ``counts[c, 0/1]`` get the number clipped / added in chunk ``c``.

    A chunk's violators were counted, and where few recorded in ``vidx``, ``vg``, by
    ``direction``. A chunk with more than ``min(record_max, SLOTS)`` of them
    (``record_max``: the most changed points the caller applies as point responses; beyond,
    it takes ``u`` afresh and needs no records) runs, under the hard wall without
    ``keep_mask`` or ``with_u``, a branch-free sweep that records nothing but the counts,
    and otherwise a scan of every constrained point that records up to ``SLOTS`` events.
    Any other chunk takes a vectorised step block by block that finds the block's clipped
    points as it goes; only a block with a clipped point or a recorded violator then visits
    those points, in index order, from L1, or, under the hard wall without ``keep_mask`` or
    ``with_u`` once the chunk's events pass that limit, treats its clipped points
    branch-free. One pass over ``p``, ``t`` and ``m``: a chunk's clipped points are not
    counted beforehand.

    With ``keep_mask`` (the bounded load step, :mod:`.bounded_load`) the free set ``m`` and
    the direction ``t`` are left as they were (the events are still recorded), so that the
    step can still be taken again from the old state, and joining points are projected onto
    ``[0, p_max]`` too; the caller rebuilds ``m`` and ``t`` after its rescale.

    Returns ``(Σ p_new, max |g| over the added points, Σ p_new over the points at
    p_max, records complete)`` (stored units; the third is 0 without a bound). The records
    are complete unless a chunk had more events than ``min(record_max, SLOTS)`` (its
    records may then be partial or missing): the caller must then take ``u`` afresh
    whatever the counts say (they would say so too, unless two compiled tests of a gap at
    round-off level disagreed).
    """
    n = p.size
    nch = (n + CHUNK - 1) // CHUNK
    part = np.zeros((nch, 3))
    incomplete = np.zeros(nch, dtype=np.int64)
    # in place (p_new is p, the fused loop): the chunk's step is given the same slice twice,
    # so that LLVM sees one array; two arguments that overlap at run time make it fall back
    # to scalar loops (benchmarks/README.md, "Why the kernels are written as they are")
    inplace = p.ctypes.data == p_new.ctypes.data
    for c in prange(nch):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        uc, rc, tc, hc, mc = u[lo:hi], r[lo:hi], t[lo:hi], h[lo:hi], m[lo:hi]
        ubc = p_max[lo:hi] if bounded else p_max
        pc = p[lo:hi]
        if inplace:
            res = _chunk_update(
                pc, pc, uc, rc, tc, hc, mc, ubc, bounded, sigma, d, tau, idx[c], val[c], lo,
                keep_mask, with_u, vidx[c], vg[c], violators[c], record_max,
            )  # fmt: skip
        else:
            res = _chunk_update(
                pc, p_new[lo:hi], uc, rc, tc, hc, mc, ubc, bounded, sigma, d, tau, idx[c],
                val[c], lo, keep_mask, with_u, vidx[c], vg[c], violators[c], record_max,
            )  # fmt: skip
        acc, accb, pen, nclip, nadd, incomplete[c] = res
        part[c, 0] = acc
        part[c, 1] = pen
        part[c, 2] = accb
        counts[c, 0] = nclip
        counts[c, 1] = nadd
    total = 0.0
    pen = 0.0
    at_bound = 0.0
    complete = True
    for c in range(nch):
        total += part[c, 0]
        pen = max(pen, part[c, 1])
        at_bound += part[c, 2]
        complete = complete and incomplete[c] == 0
    return total, pen, at_bound, complete


@numba.njit(**_INNER)
def _chunk_update(
    pc, pnc, uc, rc, tc, hc, mc, ubc, bounded, sigma, d, tau,
    idx, val, lo, keep_mask, with_u, vidx, vg, nv, record_max,
):  # fmt: skip
    """One chunk of :func:`update` (its docstring), by the cheapest routine its violators
    allow. Returns ``(Σ p_new, Σ p_new at p_max, max |g| over added points, clipped,
    added, records incomplete)``."""
    limit = min(record_max, SLOTS)
    if nv > 0 and nv > limit:
        # the violators alone make the chunk one with many events: no records
        if not (bounded or keep_mask or with_u):
            acc, accb, pen, nclip, nadd = _chunk_bulk_hard(pc, pnc, uc, tc, hc, mc, sigma, d, tau)
        else:
            acc, accb, pen, nclip, nadd = _chunk_scan(
                pc, pnc, uc, rc, tc, hc, mc, ubc, bounded, sigma, d, tau, idx, val, lo,
                keep_mask, with_u,
            )  # fmt: skip
        return acc, accb, pen, nclip, nadd, True
    acc, accb, pen, nclip, nadd = _chunk_step_events(
        pc, pnc, uc, rc, tc, hc, mc, ubc, bounded, sigma, d, tau, idx, val, lo, keep_mask,
        with_u, vidx, vg, nv, limit,
    )  # fmt: skip
    events = nclip + nadd
    return acc, accb, pen, nclip, nadd, events > 0 and events > limit


@numba.njit(**_INNER)
def _block_step(p, p_new, t, m, p_max, bounded, sigma, step):
    """The step ``p_new = p - step·t`` of a block (vectorised); returns ``(Σ p_new, Σ p_new
    over the points at p_max, free points taken out of [0, p_max])`` (stored units; the
    second 0 without a bound)."""
    acc = 0.0
    accb = 0.0
    k = 0
    if bounded:
        for i in range(p.size):
            q = p[i] - step * t[i]
            p_new[i] = q
            acc += q
            s = sigma * q
            # constrained points at p_max keep t = 0, so they stay there
            accb += q * (s >= p_max[i])
            k += (m[i] != 0) & ((s < 0.0) | (s > p_max[i]))
    else:
        for i in range(p.size):
            q = p[i] - step * t[i]
            p_new[i] = q
            acc += q
            k += (m[i] != 0) & (q < 0.0)
    return acc, accb, k


@numba.njit(**_INNER)
def _chunk_step_events(
    p, p_new, u, r, t, h, m, p_max, bounded, sigma, d, tau, idx, val, lo, keep_mask, with_u,
    vidx, vg, nv, limit,
):  # fmt: skip
    """The step of a chunk whose violators ``direction`` recorded (``nv`` of them, in
    ``vidx``, ``vg``), in one pass, block by block (``SCAN`` points): the block's vectorised
    step counts its clipped points; a block with one, or with a recorded violator, then
    gets ``_point_event`` for those points from L1, merged in index order, and its sums
    taken again; no pass of its own counts the clipped points before the step. Records past
    the slots are dropped (the caller knows from the counts).

    Once a block takes the chunk's events past ``limit`` its records are of no use (the
    caller follows the step by a convolution), so under the hard wall (without
    ``keep_mask`` or ``with_u``) that block's and every later block's clipped points are
    handled branch-free (``_block_clips_hard``), not visited one by one
    (benchmarks/README.md, "Why the kernels are written as they are"). Returns
    ``(Σ p_new, Σ p_new at p_max, max |g| of the joining points, clipped, joined)``."""
    step = tau / sigma
    n = p.size
    ev = np.zeros(2, dtype=np.int64)
    acc = 0.0
    accb = 0.0
    pen = 0.0
    vk = 0
    inf = math.inf
    branch_free = not (bounded or keep_mask or with_u)
    pens = np.empty(SCAN)
    for b0 in range(0, n, SCAN):
        b1 = min(n, b0 + SCAN)
        ub_b = p_max[b0:b1] if bounded else p_max
        a, ab, k = _block_step(
            p[b0:b1], p_new[b0:b1], t[b0:b1], m[b0:b1], ub_b, bounded, sigma, step
        )
        if not (k or (vk < nv and vidx[vk] - lo < b1)):
            acc += a
            accb += ab
            continue
        if k and branch_free and ev[0] + ev[1] + k > limit:
            c, j = _block_clips_hard(
                p_new[b0:b1], u[b0:b1], t[b0:b1], h[b0:b1], m[b0:b1], sigma, d, tau,
                pens[: b1 - b0],
            )  # fmt: skip
            ev[0] += c
            ev[1] += j
            if j:
                pen = max(pen, _max_from_zero(pens[: b1 - b0]))
        elif k:
            for i in range(b0, b1):
                if m[i] == 0:
                    continue
                ub = p_max[i] if bounded else inf
                pn = sigma * p_new[i]
                if pn < 0.0 or pn > ub:
                    vk, pen = _recorded_violators_before(
                        i, vk, nv, vidx, vg, lo, p_new, u, t, h, m, p_max, bounded, sigma, d,
                        tau, idx, val, keep_mask, ev, pen,
                    )  # fmt: skip
                    e = _point_event(i, p_new, u, t, h, m, ub, sigma, d, tau, idx, val, lo,
                                     keep_mask, 0.0, False, ev)  # fmt: skip
                    pen = max(pen, e)
        vk, pen = _recorded_violators_before(
            b1, vk, nv, vidx, vg, lo, p_new, u, t, h, m, p_max, bounded, sigma, d, tau, idx,
            val, keep_mask, ev, pen,
        )  # fmt: skip
        a, ab = _chunk_sums(p_new[b0:b1], ub_b, bounded, sigma)
        acc += a
        accb += ab
    if with_u:
        for i in range(n):
            u[i] -= step * r[i]
    return acc, accb, pen, ev[0], ev[1]


@numba.njit(**_INNER)
def _recorded_violators_before(
    stop, vk, nv, vidx, vg, lo, p_new, u, t, h, m, p_max, bounded, sigma, d, tau, idx, val,
    keep_mask, ev, pen,
):  # fmt: skip
    """``_point_event`` for the violators ``direction`` recorded from the ``vk``-th on whose
    index in the chunk (starting at flat index ``lo``) is below ``stop``, with their
    recorded gaps. Returns the next ``vk`` and the running maximum ``pen`` of ``|g|``."""
    while vk < nv and vidx[vk] - lo < stop:
        j = vidx[vk] - lo
        ub = p_max[j] if bounded else math.inf
        e = _point_event(j, p_new, u, t, h, m, ub, sigma, d, tau, idx, val, lo, keep_mask,
                         vg[vk], True, ev)  # fmt: skip
        pen = max(pen, e)
        vk += 1
    return vk, pen


@numba.njit(**_INNER)
def _block_clips_hard(p_new, u, t, h, m, sigma, d, tau, pens):
    """The clipped points of a block after its step (``p_new = p - tau/sigma·t``) under the
    hard wall, branch-free: a free point the step took below 0 leaves the free set at 0,
    its direction zeroed, or stays in it at ``-tau·g/sigma`` if it penetrates, as
    ``_point_event`` rules; constrained points are left alone. ``pens[i]`` gets the
    penetration ``-g`` of a point that stays, 0 elsewhere. Returns ``(clipped, stayed)``."""
    nclip = 0
    nadd = 0
    for i in range(p_new.size):
        free = m[i] != 0
        q = p_new[i]
        clip = free & (q < 0.0)
        g = sigma * u[i] - h[i] - d
        join = clip & (g < 0.0)
        p_new[i] = q if not clip else ((-tau * g) / sigma if join else 0.0)
        m[i] = (free & (not clip)) | join
        t[i] = 0.0 if clip else t[i]
        pens[i] = -g if join else 0.0
        nclip += clip
        nadd += join
    return nclip, nadd


@numba.njit(**_INNER)
def _chunk_bulk_hard(p, p_new, u, t, h, m, sigma, d, tau):
    """The step of a chunk with many events under the hard wall, the free set updated and
    ``u`` left alone, without records: ``_point_event``'s rules written branch-free for the
    vectoriser (a constrained point has ``p = 0`` under the hard wall: points leave the
    free set only by clipping to 0), block by block (``SCAN`` points). A running maximum of
    the penetration keeps LLVM from vectorising the sweep, so each block writes its points'
    penetrations to a small buffer that stays in L1, and the maximum is taken over it
    afterwards (benchmarks/README.md, "Why the kernels are written as they are"). Returns
    as ``_chunk_step_events``."""
    step = tau / sigma
    buf = np.empty(SCAN)
    acc = 0.0
    pen = 0.0
    nclip = 0
    nadd = 0
    for b0 in range(0, p.size, SCAN):
        b1 = min(p.size, b0 + SCAN)
        pens = buf[: b1 - b0]
        a, c, j = _block_bulk_hard(
            p[b0:b1], p_new[b0:b1], u[b0:b1], t[b0:b1], h[b0:b1], m[b0:b1],
            sigma, d, tau, step, pens,
        )  # fmt: skip
        acc += a
        nclip += c
        nadd += j
        if j:
            pen = max(pen, _max_from_zero(pens))
    return acc, 0.0, pen, nclip, nadd


@numba.njit(**_INNER)
def _block_bulk_hard(p, p_new, u, t, h, m, sigma, d, tau, step, pens):
    """One block of :func:`_chunk_bulk_hard`; ``pens[i]`` gets the penetration ``-g`` of a
    joining point, 0 elsewhere. Returns ``(Σ p_new, clipped, added)``."""
    acc = 0.0
    nclip = 0
    nadd = 0
    # boolean lanes and a select for the joining value, not 0/1 float factors
    # (benchmarks/README.md, "Why the kernels are written as they are")
    for i in range(p.size):
        free = m[i] != 0
        q = p[i] - step * t[i]
        clip = free & (q < 0.0)
        g = sigma * u[i] - h[i] - d
        join = (clip | (not free)) & (g < 0.0)
        keep = free & (not clip)
        # as _point_event: a joining point at (0 - tau·g)/sigma, a clipped one at 0
        q = q if keep else ((-tau * g) / sigma if join else 0.0)
        m[i] = keep | join
        t[i] = 0.0 if clip else t[i]
        p_new[i] = q
        acc += q
        pens[i] = -g if join else 0.0
        nclip += clip
        nadd += join
    return acc, nclip, nadd


@numba.njit(**_INNER)
def _max_from_zero(x):
    """``max(0, max(x))`` in four independent running maxima (a single chain waits on each
    compare); NaN entries are passed over, as by ``max(a, nan)``."""
    a0 = a1 = a2 = a3 = 0.0
    n4 = x.size - x.size % 4
    for i in range(0, n4, 4):
        a0 = max(a0, x[i])
        a1 = max(a1, x[i + 1])
        a2 = max(a2, x[i + 2])
        a3 = max(a3, x[i + 3])
    for i in range(n4, x.size):
        a0 = max(a0, x[i])
    return max(max(a0, a1), max(a2, a3))


@numba.njit(cache=True)
def _record_block_violators(u, sigma, h, m, d, p, p_max, bounded, b0, b1, lo, vidx, vg, k):
    """Record the violators of points ``b0:b1`` of a chunk starting at flat index ``lo``
    (``direction``) with ``update``'s test and arithmetic, after the ``k`` already
    recorded; returns the new count, ``SLOTS + 1`` past the slots.

    Compiled inside ``direction`` it takes that kernel's fast-math flags (numba passes them
    to callees), like every helper here: the gaps of the different loops agree because
    LLVM associates ``sigma·u - h - d`` the same way in each, not by guarantee; a gap at
    round-off level that two loops judge differently changes no answer (convergence is
    judged on a fresh ``u``) and cannot corrupt ``u`` (``update`` reports its records
    complete only when no chunk took a sweep without them)."""
    for i in range(b0, b1):
        if m[i] != 0:
            continue
        g = sigma * u[i] - h[i] - d
        hit = _should_join(sigma * p[i], g, p_max[i]) if bounded else g < 0.0
        if hit:
            if k == SLOTS:
                return SLOTS + 1
            vidx[k] = lo + i
            vg[k] = g
            k += 1
    return k


@numba.njit(cache=True)
def _point_event(i, p_new, u, t, h, m, ub, sigma, d, tau, idx, val, lo, keep_mask, g, known, ev):
    """The projection and violator test of point ``i`` of a chunk after its step
    (``p_new[i] = p - tau/sigma·t``): a free point pushed out of ``[0, p_max]`` is clipped
    (and leaves the free set, its direction zeroed, unless ``keep_mask``); a constrained
    point that should be free (unloaded and penetrating, or at ``p_max`` and open) moves by
    ``-tau·g`` (projected onto ``[0, p_max]`` with ``keep_mask``) and joins. ``g`` is its
    gap if ``known``. ``ev`` holds ``[nclip, nadd]``; returns the
    ``|g|`` of a joining point, else 0."""
    free = m[i] != 0
    q = p_new[i]
    pn = sigma * q
    pen = 0.0
    if free:
        cval = 0.0
        if pn < 0.0:
            cval = -pn
            pn = 0.0
            free = False
        elif pn > ub:
            cval = ub - pn
            pn = ub
            free = False
        if not free:
            q = pn / sigma
            if not keep_mask:
                m[i] = 0
                t[i] = 0.0
            k = ev[0] + ev[1]
            if k < SLOTS:
                idx[k] = lo + i
                val[k] = cval
            ev[0] += 1
    if not free:
        if not known:
            g = sigma * u[i] - h[i] - d
        if _should_join(pn, g, ub):
            added = -tau * g
            joined = pn + added
            if keep_mask:
                if joined < 0.0 or joined > ub:
                    joined = min(max(joined, 0.0), ub)
                    added = joined - pn
            else:
                m[i] = 1
            q = joined / sigma
            k = ev[0] + ev[1]
            if k < SLOTS:
                idx[k] = lo + i
                val[k] = added
            ev[1] += 1
            pen = abs(g)
    p_new[i] = q
    return pen


@numba.njit(cache=True)
def _chunk_scan(
    p, p_new, u, r, t, h, m, p_max, bounded, sigma, d, tau, idx, val, lo, keep_mask, with_u
):  # fmt: skip
    """The step of a chunk with more violators than ``direction`` records: the step for
    every point, then ``_point_event`` for its clipped points and every constrained point
    (their gaps taken here), recording into the slots while they last. Returns as
    ``_chunk_step_events``."""
    step = tau / sigma
    for i in range(p.size):
        p_new[i] = p[i] - step * t[i]
    ev = np.zeros(2, dtype=np.int64)
    pen = 0.0
    inf = math.inf
    for i in range(p.size):
        ub = p_max[i] if bounded else inf
        pn = sigma * p_new[i]
        if m[i] == 0:
            # the violator test inline: most constrained points pass it
            g = sigma * u[i] - h[i] - d
            if _should_join(pn, g, ub):
                e = _point_event(i, p_new, u, t, h, m, ub, sigma, d, tau, idx, val, lo,
                                 keep_mask, g, True, ev)  # fmt: skip
                pen = max(pen, e)
        elif pn < 0.0 or pn > ub:
            e = _point_event(i, p_new, u, t, h, m, ub, sigma, d, tau, idx, val, lo, keep_mask,
                             0.0, False, ev)  # fmt: skip
            pen = max(pen, e)
    acc, accb = _chunk_sums(p_new, p_max, bounded, sigma)
    if with_u:
        for i in range(p.size):
            u[i] -= step * r[i]
    return acc, accb, pen, ev[0], ev[1]


@numba.njit(**_INNER)
def _chunk_sums(p_new, p_max, bounded, sigma):
    """``(Σ p_new, Σ p_new over the points at p_max)`` of a chunk (stored units)."""
    acc = 0.0
    accb = 0.0
    if bounded:
        for i in range(p_new.size):
            q = p_new[i]
            acc += q
            accb += q * (sigma * q >= p_max[i])
    else:
        for i in range(p_new.size):
            acc += p_new[i]
    return acc, accb


@numba.njit(cache=True)
def _rescale_chunk(p, u, v, m_old, m_new, t, p_max, s, with_u, idx, val, lo):
    """``rescale_free`` on a chunk starting at flat index ``lo``."""
    acc = 0.0
    accb = 0.0
    left = 0
    joined = 0
    nover = 0
    for i in range(p.size):
        q = p[i]
        ub = p_max[i]
        free = q > 0.0 and q < ub
        if free:
            q *= s
            if q >= ub:
                if nover < SLOTS:
                    idx[nover] = lo + i
                    val[nover] = ub - q
                nover += 1
                q = ub
                free = False
            p[i] = q
        if not free:
            t[i] = 0.0
        if q >= ub:
            accb += q
        acc += q
        m_new[i] = 1 if free else 0
        was = m_old[i] != 0
        left += was and not free
        joined += free and not was
        if with_u:
            u[i] = s * u[i] - (s - 1.0) * v[i]
    return acc, accb, left, joined, nover


@numba.njit(**_JIT)
def rescale_free(p, u, v, m_old, m_new, t, p_max, s, with_u, idx, val, counts):
    """Scale the free points (``0 < p < p_max``) of ``p`` by ``s`` in place, clipping those
    it pushes to ``p_max`` or past it, and rebuild the free set into ``m_new`` (uint8) with
    ``t`` zeroed off it.

    With ``with_u``, ``u ← s·u - (s - 1)·v``: if ``u = K*p`` and ``v = K*p_b`` (m, ``p_b``
    the pressure of the points at the bound, Pa) before the call, ``u = K*p`` after it, up to
    the clipped points. Those are recorded per chunk in ``idx[c, :]``, ``val[c, :]`` (the
    pressure the clip added, Pa, ``<= 0``), ``counts[c, 0]`` (their number); they need
    ``val`` added to ``u`` and ``p_max`` to ``v`` as point responses.

    Returns ``(Σ p, Σ p over the points at p_max, points that left the free set m_old,
    points that joined it)`` (Pa).
    """
    n = p.size
    nch = (n + CHUNK - 1) // CHUNK
    part = np.zeros((nch, 2))
    moved = np.zeros((nch, 2), dtype=np.int64)
    for c in prange(nch):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        acc, accb, left, joined, nover = _rescale_chunk(
            p[lo:hi],
            u[lo:hi],
            v[lo:hi],
            m_old[lo:hi],
            m_new[lo:hi],
            t[lo:hi],
            p_max[lo:hi],
            s,
            with_u,
            idx[c],
            val[c],
            lo,
        )
        part[c, 0] = acc
        part[c, 1] = accb
        moved[c, 0] = left
        moved[c, 1] = joined
        counts[c, 0] = nover
        counts[c, 1] = 0
    total = 0.0
    at_bound = 0.0
    left = 0
    joined = 0
    for c in range(nch):
        total += part[c, 0]
        at_bound += part[c, 1]
        left += moved[c, 0]
        joined += moved[c, 1]
    return total, at_bound, left, joined


@numba.njit(**_INNER)
def _change(p_new, s_new, p, s_old):
    a = 0.0
    b = 0.0
    for i in range(p.size):
        q = s_new * p_new[i]
        a += abs(q - s_old * p[i])
        b += q
    return a, b


@numba.njit(**_JIT)
def relative_change(p_new, s_new, p, s_old):
    """``(Σ|s_new·p_new - s_old·p|, Σ s_new·p_new)``, Pa (stored fields and their scales)."""
    n = p.size
    nch = (n + CHUNK - 1) // CHUNK
    part = np.zeros((nch, 2))
    for c in prange(nch):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        a, b = _change(p_new[lo:hi], s_new, p[lo:hi], s_old)
        part[c, 0] = a
        part[c, 1] = b
    out = np.zeros(2)
    for c in range(nch):
        out[0] += part[c, 0]
        out[1] += part[c, 1]
    return out[0], out[1]


@numba.njit(**_JIT)
def free_mask(p, m, p_max, bounded):
    """``m ← (0 < p < p_max)`` (uint8); returns its size."""
    n = p.size
    k = 0
    for i in prange(n):
        ub = p_max[i] if bounded else math.inf
        f = p[i] > 0.0 and p[i] < ub
        m[i] = 1 if f else 0
        k += 1 if f else 0
    return k


@numba.njit(**_JIT)
def worst_violation(p, u, h, d, m, p_max, bounded):
    """Largest ``|g|`` (m) over constrained points that should be free (``update``'s test),
    with ``g = u - h - d``; 0 when there are none."""
    n = p.size
    pen = 0.0
    for i in prange(n):
        ub = p_max[i] if bounded else math.inf
        g = u[i] - h[i] - d
        pi = p[i]
        if m[i] == 0 and _should_join(pi, g, ub):
            pen = max(pen, abs(g))
    return pen


@numba.njit(**_JIT)
def add_point_responses(u, green, idx, values):
    """``u[i, j] += Σ_k values_k · green[(i - a_k) mod N0, (j - b_k) mod N1]`` in place, with
    ``(a_k, b_k)`` the 2-D position of flat index ``idx[k]`` on ``u``'s grid.

    ``u`` (n0, n1), m; ``green`` (N0, N1) the real-space kernel of the convolution, m/Pa
    (periodic: N = n; Hockney-padded: N = the operator's padded_shape, m >= 2n, the same
    discrete operator as the FFT path);
    ``values`` Pa. One sweep over ``u`` whatever the number of points (each row adds every
    point's kernel row while it is in cache), rows in parallel; each element sums the points
    in the same order, so the result does not depend on the thread count.
    """
    n0, n1 = u.shape
    big0, big1 = green.shape
    npts = idx.size
    for i in prange(n0):
        row = u[i]
        for k in range(npts):
            a = idx[k] // n1
            b = idx[k] - a * n1
            v = values[k]
            g = green[(i - a) % big0]
            # columns j >= b read g[j - b]; columns j < b wrap to g[big1 - b + j]. On
            # slices: a loop indexing g[j - b] does not vectorise (LLVM cannot prove the
            # index non-negative; benchmarks/README.md, §1)
            _add_scaled(row[b:], g[: n1 - b], v)
            _add_scaled(row[:b], g[big1 - b : big1], v)


@numba.njit(**_INNER)
def _add_scaled(y, x, v):
    """``y += v·x`` in place."""
    for j in range(y.size):
        y[j] += v * x[j]


@numba.njit(**_JIT)
def subtract_scaled(u, r, step):
    """``u -= step·r`` in place (the displacement's share of a CG step, m)."""
    for i in prange(u.size):
        u[i] -= step * r[i]


def changed_points(counts, idx_buf, val_buf):
    """Flat indices and added pressures (Pa) of the points ``update`` (or
    ``rescale_free``) recorded per chunk."""
    per = counts.sum(axis=1)
    rows = np.flatnonzero(per)
    if not rows.size:
        return np.empty(0, dtype=np.int64), np.empty(0)
    idx = np.concatenate([idx_buf[c, : per[c]] for c in rows])
    vals = np.concatenate([val_buf[c, : per[c]] for c in rows])
    return idx, vals


# The host side of the kernel-set protocol (cg.kernel_set): this set's arrays are numpy
# arrays in host memory, so there is nothing to move.
xp = np
# SIMD-aligned work arrays (pyfftw's when importable) let the FFT plans run without copies
_ALIGNED = "pyfftw" if _fft.HAVE_PYFFTW else "numpy"
asarray = np.asarray
to_host = np.asarray
add_at = np.add.at


def empty(n: int, dtype=np.float64) -> np.ndarray:
    """An uninitialised flat work array of ``n`` points, SIMD-aligned."""
    return _fft.empty(n, dtype, _ALIGNED)


def event_counts(counts) -> tuple[int, int]:
    """The points ``update`` clipped and added, over every chunk of ``counts``."""
    return int(counts[:, 0].sum()), int(counts[:, 1].sum())


def on_host(fn, *args, writes=()):
    """``fn(*args)``: the arrays are on the host already (``writes`` is the array set's
    concern, :meth:`.array_kernels.ArrayKernels.on_host`)."""
    return fn(*args)


# the kernels called from Python (the others are compiled into them)
ENTRY_POINTS = (
    gap_moments,
    direction,
    step_dots,
    update,
    rescale_free,
    relative_change,
    free_mask,
    worst_violation,
    add_point_responses,
    subtract_scaled,
    *SPECTRUM_ENTRY_POINTS,
)
