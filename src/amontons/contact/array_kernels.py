"""The array kernel set: :mod:`.kernels`' contracts written once in array-namespace code.

:func:`.cg.polonsky_keer` runs one control flow on a *kernel set* (:func:`.cg.kernel_set`):
the fused numba kernels of :mod:`.kernels` on the CPU, or this set on an array namespace
``xp`` (:mod:`.array_backends`): CuPy on a GPU (``backend="cupy"``), numpy in tests and CI
(``backend="numpy-array"``), which run the same code. Each method keeps the contract of
the :mod:`.kernels` function of its name (arguments, in-place writes, returns); the
differences are the ones a GPU asks for:

* **one chunk.** :meth:`ArrayKernels.n_chunks` is 1: the per-chunk records of ``update``
  and ``rescale_free`` are one row of ``SLOTS`` (>= the most changed points the loop
  applies as point responses, :data:`.cg_iteration.SPARSE_MAX_PADDED`), written only when
  the events fit (else the records are reported incomplete and the loop convolves afresh,
  as it does on the numba set past ``record_max``). ``direction`` counts the violators but
  records none: ``update`` finds them itself in its dense pass.
* **dense passes, element-wise parts fused.** The element-wise parts are small functions
  of arrays and scalars (:func:`_gap`, :func:`_direction_value`, :func:`_should_join`,
  ...), compiled by ``ArrayModule.fuse`` (``cupy.fuse``: one CUDA kernel each; on numpy
  they run as plain numpy). No branch is taken per point: a projection or a join is a
  ``where``.
* **reductions by the namespace.** Sums are ``xp.sum`` over the flat array: numpy's
  pairwise summation, CuPy's block-tree reduction. The order differs from the numba
  set's fixed chunks, so results agree with it to round-off (~1e-15 relative per sum,
  tests/contact/test_array_kernels.py), not bit for bit; on a given namespace and device
  they are deterministic. Maxima and counts are exact.
* **few host reads.** The scalars a method returns are gathered into one array and read
  with one transfer (:meth:`ArrayKernels._floats`): one per kernel call, the loop's only
  synchronisations besides the rare paths below. ``direction`` returns ``Σ t`` as a 0-d
  array of the namespace (the loop does not read it). The numpy routines the loop runs
  on rare paths (a restart of the free set, the bounded load step's shortened or restarted
  step) run on host copies through :meth:`ArrayKernels.on_host`.

On CuPy (``backend="cupy"``) the set is :class:`ReducingKernels`: the four kernels of every
iteration and ``relative_change`` each run as one CUDA kernel of :mod:`.device_sources` that
also takes the pass's sums (per-block partials, folded on the host after one transfer, in an
order fixed by the grid size: deterministic on a device, equal to the array code's sums to
round-off), and the changed points' responses as one kernel. :class:`DeviceKernels`
(``backend="cupy-terms"``, a benchmarks' baseline) runs the same passes as element-wise
kernels whose terms CuPy then sums, one launch per sum.

Arrays are flat float64 of the namespace (the free set ``m`` uint8), in the units of
:mod:`.kernels`.
"""

from __future__ import annotations

import contextlib
import math
from functools import lru_cache

import numpy as np

from . import device_sources as src
from .array_backends import ArrayModule, array_module

# Records per chunk (the one chunk): at least the most changed points the loop applies as
# point responses (.cg_iteration.SPARSE_MAX_PERIODIC, SPARSE_MAX_PADDED), as kernels.SLOTS.
SLOTS = 64


# The element-wise parts: functions of arrays and scalars with one result, so that
# ``cupy.fuse`` compiles each into one kernel. Their arithmetic is written as the numba
# kernels' (same association), so that the element-wise results agree bit for bit where
# the compilers keep it; only the sums differ in order.


def _gap(u, sigma, h, d):
    """The gap ``sigma·u - h - d`` (m)."""
    return sigma * u - h - d


def _direction_value(u, sigma, h, d, beta, t, shift, m):
    """``m·(g + beta·t - shift)`` (kernels.direction)."""
    return (sigma * u - h - d + beta * t - shift) * m


def _should_join(q, g, ub):
    """The violator test of a constrained point (kernels._should_join): unloaded and
    penetrating with room to rise, or at the bound ``ub`` and open."""
    return ((q <= 0.0) & (g < 0.0) & (q < ub)) | ((q >= ub) & (g > 0.0) & (q > 0.0))


def _violates(m, q, g, ub):
    """A constrained point (``m == 0``) that should be free."""
    return (m == 0) & _should_join(q, g, ub)


def _masked(x, mask):
    """``x`` where ``mask``, else 0."""
    return x * mask


def _where(xp):
    def pick(cond, a, b):
        return xp.where(cond, a, b)

    return pick


@lru_cache(maxsize=4)
def array_kernel_set(name: str) -> ArrayKernels:
    """The array kernel set on the namespace of backend ``name``
    (:func:`.array_backends.array_module`; raises there without CuPy or a device):
    :class:`ReducingKernels` where the namespace compiles CUDA source with its sums (CuPy,
    ``"cupy"``), :class:`DeviceKernels` where only the element-wise passes
    (``"cupy-terms"``), else :class:`ArrayKernels`."""
    module = array_module(name)
    if module.compile is None:
        return ArrayKernels(module)
    return DeviceKernels(module) if module.compile_reducing is None else ReducingKernels(module)


class ArrayKernels:
    """The kernel set on the namespace of ``module`` (an :class:`.array_backends.ArrayModule`).
    Methods as the functions of :mod:`.kernels` of the same name (module docstring)."""

    SLOTS = SLOTS

    def __init__(self, module: ArrayModule):
        self.module = module
        self.xp = xp = module.xp
        fuse = module.fuse
        self.to_host = module.to_host
        self.add_at = module.add_at
        self.asarray = xp.asarray
        self._gap = fuse(_gap)
        self._direction_value = fuse(_direction_value)
        self._violates = fuse(_violates)
        self._masked = fuse(_masked)
        self._where = _where(xp)

    # -- the host side of the protocol (cg.kernel_set) --

    def n_chunks(self, n: int) -> int:
        """One chunk (module docstring)."""
        return 1

    def kernel_threads(self, threads: int):
        """No thread pool to set: a no-op context."""
        return contextlib.nullcontext()

    def empty(self, n: int, dtype=np.float64):
        """An uninitialised flat array of the namespace."""
        return self.xp.empty(n, dtype=dtype)

    def on_host(self, fn, *args, writes=()):
        """``fn(*args)`` with the namespace's arrays among ``args`` as numpy copies; the
        arrays at the positions ``writes`` (those ``fn`` changes in place) are copied back.
        On numpy, ``fn(*args)`` itself."""
        if self.xp is np:
            return fn(*args)
        array = self.xp.ndarray
        host = [self.to_host(a) if isinstance(a, array) else a for a in args]
        out = fn(*host)
        for i in writes:
            args[i][...] = self.xp.asarray(host[i])
        return out

    def _floats(self, *values) -> list:
        """The namespace's scalars as Python numbers, in one transfer."""
        return self.to_host(self.xp.stack(values)).tolist()

    def _bound(self, p_max, bounded):
        return p_max if bounded else math.inf

    # -- the kernels --

    def free_mask(self, p, m, p_max, bounded):
        """``m ← (0 < p < p_max)`` (uint8); returns its size."""
        free = p > 0.0
        if bounded:
            free &= p < p_max
        m[...] = free
        return int(self.xp.count_nonzero(free))

    def gap_moments(self, u, sigma, h, m, t, shift):
        """``(Σ_m a, Σ_m a², Σ_m a·t, Σ t)`` of ``a = sigma·u - h - shift`` on ``m``."""
        a = self._masked(self._gap(u, sigma, h, shift), m)
        return tuple(self._floats(a.sum(), (a * a).sum(), (a * t).sum(), t.sum()))

    def direction(self, u, sigma, h, m, t, d, beta, shift, p, p_max, bounded, violators, vidx, vg):
        """``t ← m·(sigma·u - h - d + beta·t - shift)`` in place; ``violators[0]`` gets the
        number of constrained points that should be free (none is recorded in ``vidx``,
        ``vg``: module docstring). Returns ``Σ t`` as a 0-d array of the namespace."""
        g = self._gap(u, sigma, h, d)
        ub = self._bound(p_max, bounded)
        violators[0] = self.xp.count_nonzero(self._violates(m, sigma * p, g, ub))
        t[...] = self._direction_value(u, sigma, h, d, beta, t, shift, m)
        return t.sum()

    def step_dots(self, r, t, m, compliance, winkler):
        """With ``winkler``, ``r += compliance·t`` in place; ``(Σ r·t, Σ_m r)``."""
        if winkler:
            r += compliance * t
        rt, rm = self._floats((r * t).sum(), self._masked(r, m).sum())
        return rt, rm

    def update(
        self, p, p_new, u, r, t, h, m, p_max, bounded, sigma, d, tau, violators, idx, val,
        counts, keep_mask, with_u, vidx, vg, record_max,
    ):  # fmt: skip
        """One CG step in dense passes, as :func:`.kernels.update` (its docstring): step,
        projection onto ``[0, p_max]``, violators joining at ``-tau·g``, the free set and
        ``t`` updated (unless ``keep_mask``), ``u -= tau/sigma·r`` with ``with_u``.
        ``violators``, ``vidx``, ``vg`` are not read (the violators are found here). The
        changed points are recorded in ``idx[0]``, ``val[0]`` (clipped ones first, then
        the added ones, each in index order) when they are at most ``min(record_max,
        SLOTS)``; ``counts[0]`` gets ``(clipped, added)``. Returns ``(Σ p_new, max |g| over
        the added points, Σ p_new at p_max, records complete)``."""
        xp, pick = self.xp, self._where
        ub = self._bound(p_max, bounded)
        step = tau / sigma
        g = self._gap(u, sigma, h, d)
        free = m != 0
        q = p - step * t
        pn = sigma * q
        low = free & (pn < 0.0)
        high = free & (pn > ub)
        clip = low | high
        pc = pick(low, 0.0, pick(high, ub, pn))  # the projected true pressure
        cval = pc - pn  # the pressure the projection added (0 off the clipped points)
        join = (~free | clip) & _should_join(pc, g, ub)
        added = -tau * g
        joined = pc + added
        if keep_mask:
            inside = (joined >= 0.0) & (joined <= ub)
            joined_in = xp.minimum(xp.maximum(joined, 0.0), ub)
            added = pick(inside, added, joined_in - pc)
            joined = joined_in
        p_new[...] = pick(join, joined / sigma, pick(clip, pc / sigma, q))
        if not keep_mask:
            m[...] = (free & ~clip) | join
            t[...] = pick(clip, 0.0, t)
        if with_u:
            u -= step * r
        at_bound = self._masked(p_new, sigma * p_new >= p_max).sum() if bounded else xp.zeros(())
        pen = self._masked(xp.abs(g), join).max()
        events = (clip, join, cval, added)
        return self._step_results(p_new, pen, at_bound, events, counts, idx, val, record_max)

    def _step_results(self, p_new, pen, at_bound, events, counts, idx, val, record_max):
        """What ``update`` returns, from its arrays: ``events`` is ``(clip, join, cval,
        added)``, the clipped and joined points (masks or 0/1 flags) and the pressure the
        projection and the join added there. Writes the counts into ``counts[0]`` and, when
        they fit, the records; one host read. Returns ``(Σ p_new, pen, at_bound, records
        complete)``."""
        xp = self.xp
        clip, join = events[:2]
        counted = (xp.count_nonzero(clip), xp.count_nonzero(join))
        counts[0] = xp.stack(counted)
        psum, pen, at_bound, n_clip, n_add = self._floats(p_new.sum(), pen, at_bound, *counted)
        complete = self._record_events(int(n_clip) + int(n_add), events, idx, val, record_max)
        return psum, pen, at_bound, complete

    def _record_events(self, n_events, events, idx, val, record_max) -> bool:
        """The step's clipped then joined points (``events`` as in :meth:`_step_results`)
        into ``idx[0]``, ``val[0]`` when their number ``n_events`` fits the records
        (``min(record_max, SLOTS)``); whether the records are complete."""
        complete = not (n_events > 0 and n_events > min(record_max, SLOTS))
        if n_events and complete:
            clip, join, cval, added = events
            where_clip = self.xp.flatnonzero(clip)
            where_join = self.xp.flatnonzero(join)
            self._record(idx, val, where_clip, cval[where_clip], where_join, added[where_join])
        return complete

    def _record(self, idx, val, *pairs):
        """Write the ``(indices, values)`` pairs one after the other into ``idx[0]``,
        ``val[0]``."""
        k = 0
        for where, values in zip(pairs[::2], pairs[1::2], strict=True):
            n = where.size
            idx[0, k : k + n] = where
            val[0, k : k + n] = values
            k += n

    def subtract_scaled(self, u, r, step):
        """``u -= step·r`` in place."""
        u -= step * r

    def relative_change(self, p_new, s_new, p, s_old):
        """``(Σ|s_new·p_new - s_old·p|, Σ s_new·p_new)``."""
        q = s_new * p_new
        a, b = self._floats(self.xp.abs(q - s_old * p).sum(), q.sum())
        return a, b

    def worst_violation(self, p, u, h, d, m, p_max, bounded):
        """Largest ``|g|`` over constrained points that should be free (``g = u - h - d``);
        0 when there are none."""
        g = self._gap(u, 1.0, h, d)
        hit = self._violates(m, p, g, self._bound(p_max, bounded))
        return self._floats(self._masked(self.xp.abs(g), hit).max())[0]

    def rescale_free(self, p, u, v, m_old, m_new, t, p_max, s, with_u, idx, val, counts):
        """As :func:`.kernels.rescale_free`: the free points of ``p`` scaled by ``s`` and
        clipped at ``p_max`` (recorded in ``idx[0]``, ``val[0]`` when at most ``SLOTS``;
        ``counts[0] = (clipped, 0)``), the free set rebuilt into ``m_new``, ``t`` zeroed
        off it, ``u ← s·u - (s - 1)·v`` with ``with_u``. Returns ``(Σ p, Σ p at p_max,
        left, joined)``."""
        xp, pick = self.xp, self._where
        free = (p > 0.0) & (p < p_max)
        scaled = pick(free, p * s, p)
        over = free & (scaled >= p_max)
        q = pick(over, p_max, scaled)
        now = free & ~over
        was = m_old != 0
        m_new[...] = now
        t[...] = pick(now, t, 0.0)
        if with_u:
            u[...] = s * u - (s - 1.0) * v
        n_over = xp.count_nonzero(over)
        counts[0, 0] = n_over
        counts[0, 1] = 0
        total, at_bound, left, joined, n_over = self._floats(
            q.sum(),
            self._masked(q, q >= p_max).sum(),
            xp.count_nonzero(was & ~now),
            xp.count_nonzero(now & ~was),
            n_over,
        )
        if 0 < n_over <= SLOTS:
            where = xp.flatnonzero(over)
            self._record(idx, val, where, (p_max - scaled)[where])
        p[...] = q
        return total, at_bound, int(left), int(joined)

    def event_counts(self, counts) -> tuple[int, int]:
        """The points ``update`` clipped and added, in one transfer."""
        n_clip, n_add = self.to_host(counts.sum(axis=0)).tolist()
        return int(n_clip), int(n_add)

    def changed_points(self, counts, idx_buf, val_buf):
        """Flat indices and added pressures (Pa) recorded by the last ``update`` or
        ``rescale_free`` (arrays of the namespace)."""
        k = int(self.to_host(counts[0]).sum())
        return idx_buf[0, :k], val_buf[0, :k]

    def add_point_responses(self, u, green, idx, values):
        """``u[i, j] += Σ_k values_k · green[(i - a_k) mod N0, (j - b_k) mod N1]`` in place
        (as :func:`.kernels.add_point_responses`): one gather of the kernel and one axpy on
        ``u`` per point (a few points: the loop applies at most ``SPARSE_MAX_*``)."""
        xp = self.xp
        n0, n1 = u.shape
        big0, big1 = green.shape
        rows0, cols0 = xp.arange(n0), xp.arange(n1)
        ids, vals = self.to_host(idx).tolist(), self.to_host(values).tolist()
        for k, v in zip(ids, vals, strict=True):
            a, b = divmod(int(k), n1)
            rows = (rows0 - a) % big0
            cols = (cols0 - b) % big1
            u += v * green[rows[:, None], cols[None, :]]


class DeviceKernels(ArrayKernels):
    """The array set with the element-wise passes of the four kernels of every iteration
    (``gap_moments``, ``direction``, ``step_dots``, ``update``) as the user-defined kernels
    of :mod:`.device_sources`, compiled by ``module.compile`` (CuPy): one launch per pass,
    which writes the terms the namespace then sums (one launch per sum), in place of one
    launch per array operation. Contracts, host reads and records as
    :class:`ArrayKernels`' (whose array code the sources follow); the rare paths are its
    array code."""

    def __init__(self, module: ArrayModule):
        super().__init__(module)
        build = module.compile
        self._gap_terms = build(src.GAP_TERMS)
        self._direction = build(src.DIRECTION)
        self._step_terms = build(src.STEP_TERMS)
        self._update = build(src.UPDATE)
        self._point_responses = build(src.POINT_RESPONSES)

    def add_point_responses(self, u, green, idx, values):
        """As :meth:`ArrayKernels.add_point_responses`, every point in one pass over ``u``
        (``idx`` int64 and ``values`` float64, contiguous, of the namespace), where the array
        code gathers the kernel and updates ``u`` once per point, and reads the points on
        the host to loop over them."""
        k = int(idx.size)
        if k == 0:
            return
        n1 = u.shape[1]
        big0, big1 = green.shape
        flat = self.xp.ascontiguousarray(green).reshape(-1)
        self._point_responses(flat, idx, values, k, n1, big0, big1, u)

    def _terms(self, n: int, count: int) -> list:
        """``count`` uninitialised float64 arrays of ``n`` points."""
        return [self.xp.empty(n) for _ in range(count)]

    def gap_moments(self, u, sigma, h, m, t, shift):
        """``(Σ_m a, Σ_m a², Σ_m a·t, Σ t)`` of ``a = sigma·u - h - shift`` on ``m``."""
        a, a2, at = self._terms(u.size, 3)
        self._gap_terms(u, sigma, h, shift, m, t, a, a2, at)
        return tuple(self._floats(a.sum(), a2.sum(), at.sum(), t.sum()))

    def direction(self, u, sigma, h, m, t, d, beta, shift, p, p_max, bounded, violators, vidx, vg):
        """As :meth:`ArrayKernels.direction`: ``t`` in place, the violators counted into
        ``violators[0]``; returns ``Σ t`` as a 0-d array of the namespace."""
        flags = self.xp.empty(u.size, np.int8)
        ub = self._bound(p_max, bounded)
        self._direction(u, sigma, h, d, beta, shift, m, p, ub, t, flags)
        violators[0] = self.xp.count_nonzero(flags)
        return t.sum()

    def step_dots(self, r, t, m, compliance, winkler):
        """With ``winkler``, ``r += compliance·t`` in place; ``(Σ r·t, Σ_m r)``."""
        if winkler:
            r += compliance * t
        rt, rm = self._terms(r.size, 2)
        self._step_terms(r, t, m, rt, rm)
        rt, rm = self._floats(rt.sum(), rm.sum())
        return rt, rm

    def update(
        self, p, p_new, u, r, t, h, m, p_max, bounded, sigma, d, tau, violators, idx, val,
        counts, keep_mask, with_u, vidx, vg, record_max,
    ):  # fmt: skip
        """As :meth:`ArrayKernels.update`, the step's pass one kernel (``p_new`` may be
        ``p``: the kernel reads each point's ``p`` before it writes it)."""
        xp = self.xp
        if p_new is not p:
            p_new[...] = p
        n = p.size
        clipped, joined = xp.empty(n, np.int8), xp.empty(n, np.int8)
        cval, added, gj, at_bound = self._terms(n, 4)
        ub = self._bound(p_max, bounded)
        step = (r, h, sigma, d, tau, tau / sigma, ub, int(keep_mask), int(with_u))
        self._update(*step, p_new, m, t, u, clipped, joined, cval, added, gj, at_bound)
        on_bound = at_bound.sum() if bounded else xp.zeros(())
        events = (clipped, joined, cval, added)
        return self._step_results(p_new, gj.max(), on_bound, events, counts, idx, val, record_max)


def fold_partials(partials: np.ndarray, reduced) -> list[float]:
    """The sums and maxima of a reducing kernel from its ``(blocks, K)`` partials (host
    numpy), the ops of ``reduced`` (``.device_sources.ReducingKernel.reduced``): each column
    folded in block order (numpy's pairwise sum of a contiguous row), so a given point count
    always sums in the same order."""
    columns = np.ascontiguousarray(partials.T)
    return [
        float(np.sum(col) if op == "sum" else np.max(col))
        for col, (_, op) in zip(columns, reduced, strict=True)
    ]


class ReducingKernels(DeviceKernels):
    """The device set whose every-iteration kernels (``gap_moments``, ``direction``,
    ``step_dots``, ``update``) and ``relative_change`` each run as one reducing kernel of
    :mod:`.device_sources`: the element-wise pass and its sums in one launch, whose blocks'
    partials the host reads in one transfer and folds (:func:`fold_partials`), in place of a
    pass that writes its terms and one launch per sum (:class:`DeviceKernels`). The sums are
    taken in another order than the array code's, so they agree with it to round-off (as
    the numba set's do); the element-wise results are the same expressions."""

    def __init__(self, module: ArrayModule):
        super().__init__(module)
        build = module.compile_reducing
        self._gap_reduce = build(src.REDUCING_GAP)
        self._direction_reduce = build(src.REDUCING_DIRECTION)
        self._step_reduce = build(src.REDUCING_STEP)
        self._update_reduce = build(src.REDUCING_UPDATE)
        self._change_reduce = build(src.REDUCING_RELATIVE_CHANGE)
        # (counts array, clipped, added) of the last update: its host copy, which spares
        # event_counts and changed_points a transfer; forgotten when rescale_free rewrites
        self._counted = None

    def _folded(self, kernel, spec, *args) -> list[float]:
        """``kernel``'s sums and maxima on the host: one launch, one transfer."""
        return fold_partials(self.to_host(kernel(*args)), spec.reduced)

    def gap_moments(self, u, sigma, h, m, t, shift):
        """``(Σ_m a, Σ_m a², Σ_m a·t, Σ t)`` of ``a = sigma·u - h - shift`` on ``m``."""
        return tuple(self._folded(self._gap_reduce, src.REDUCING_GAP, u, sigma, h, shift, m, t))

    def direction(self, u, sigma, h, m, t, d, beta, shift, p, p_max, bounded, violators, vidx, vg):
        """As :meth:`ArrayKernels.direction`: ``t`` in place, the violators counted into
        ``violators[0]``; returns ``Σ t`` as a 0-d array of the namespace (folded on the
        device: the loop does not read either)."""
        ub = self._bound(p_max, bounded)
        partials = self._direction_reduce(u, sigma, h, d, beta, shift, m, p, ub, t)
        totals = partials.sum(axis=0)
        violators[0] = totals[0].astype(violators.dtype)
        return totals[1]

    def step_dots(self, r, t, m, compliance, winkler):
        """With ``winkler``, ``r += compliance·t`` in place; ``(Σ r·t, Σ_m r)``."""
        if winkler:
            r += compliance * t
        rt, rm = self._folded(self._step_reduce, src.REDUCING_STEP, r, t, m)
        return rt, rm

    def update(
        self, p, p_new, u, r, t, h, m, p_max, bounded, sigma, d, tau, violators, idx, val,
        counts, keep_mask, with_u, vidx, vg, record_max,
    ):  # fmt: skip
        """As :meth:`ArrayKernels.update`: the step, its sums and its event counts in one
        kernel and one transfer; the records, when they fit, from its flags."""
        xp = self.xp
        if p_new is not p:
            p_new[...] = p
        n = p.size
        clipped, joined = xp.empty(n, np.int8), xp.empty(n, np.int8)
        cval, added = xp.empty(n), xp.empty(n)
        ub = self._bound(p_max, bounded)
        args = (r, h, sigma, d, tau, tau / sigma, ub, int(keep_mask), int(with_u))
        outs = (p_new, m, t, u, clipped, joined, cval, added)
        psum, pen, at_bound, n_clip, n_add = self._folded(
            self._update_reduce, src.REDUCING_UPDATE, *args, *outs
        )
        # two scalar fills (launches that wait for nothing), not a copy from the host, which
        # would wait for the device
        counts[0, 0], counts[0, 1] = int(n_clip), int(n_add)
        self._counted = (counts, int(n_clip), int(n_add))
        events = (clipped, joined, cval, added)
        complete = self._record_events(int(n_clip) + int(n_add), events, idx, val, record_max)
        return psum, pen, at_bound if bounded else 0.0, complete

    def _counts_of(self, counts):
        """The last update's ``(clipped, added)`` where ``counts`` holds them, else None."""
        if self._counted is not None and self._counted[0] is counts:
            return self._counted[1:]
        return None

    def event_counts(self, counts) -> tuple[int, int]:
        """The points ``update`` clipped and added: its host copy, else one transfer."""
        known = self._counts_of(counts)
        return known if known is not None else super().event_counts(counts)

    def changed_points(self, counts, idx_buf, val_buf):
        """As :meth:`ArrayKernels.changed_points`, the count from the last update's host
        copy where it wrote ``counts``."""
        known = self._counts_of(counts)
        if known is None:
            return super().changed_points(counts, idx_buf, val_buf)
        k = sum(known)
        return idx_buf[0, :k], val_buf[0, :k]

    def rescale_free(self, p, u, v, m_old, m_new, t, p_max, s, with_u, idx, val, counts):
        """As :meth:`ArrayKernels.rescale_free` (which rewrites ``counts``)."""
        self._counted = None
        return super().rescale_free(p, u, v, m_old, m_new, t, p_max, s, with_u, idx, val, counts)

    def relative_change(self, p_new, s_new, p, s_old):
        """``(Σ|s_new·p_new - s_old·p|, Σ s_new·p_new)``."""
        change, total = self._folded(
            self._change_reduce, src.REDUCING_RELATIVE_CHANGE, p_new, s_new, p, s_old
        )
        return change, total
