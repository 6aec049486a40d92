"""Load control under ``0 <= p <= p_max`` (penetration hardness, docs/models.md §2.3).

The force is imposed on the free points (``0 < p < p_max``) only: the points at the bound
keep their pressure and the free ones share what is left by one common factor
(:func:`impose_bounded_load`). One CG step of it comes in two versions:

* :func:`bounded_load_step`, numpy: the step, the projection, the rescale, and a shortened
  step when the bound alone would carry more than the load. It leaves ``u`` stale, so a
  convolution ``u = K*p`` follows every step. It is the reference the tests compare with,
  and the fallback of the other version in the cases it does not take.
* :class:`BoundedLoadSweep`, the default: the step in the fused ``kernels.update`` sweep and
  the rescale in ``kernels.rescale_free``, keeping ``u = K*p`` without a convolution where
  few points change (``K*t`` brought from the spectrum then, its inverse transform skipped
  where ``u`` is taken afresh anyway). The
  rescale multiplies the free part of the pressure by ``s`` and leaves the bound part
  ``p_b``, so ``K*p`` becomes ``s·K*p - (s - 1)·K*p_b``; ``v = K*p_b`` is carried from step
  to step by point responses of the few points that join or leave the bound. It is dropped,
  and taken afresh (one convolution) at the next step that can use it, after a step that
  changed too many points, a scale far from 1, the numpy fallback, a restart of the free
  set, and whenever the solver changes the free set or ``u`` itself (a refresh; violators
  added without a step).

The two differ in one detail: the fused step, like ``kernels.update`` on every other route,
lets a free point clipped to 0 rejoin in the same step when it penetrates; the numpy step
adds only points that were constrained before it. Both converge to the same state.

Flat float64 arrays, pressures in Pa, lengths in m; the free set ``m`` is uint8.
"""

from __future__ import annotations

import numpy as np

# Rounds of rescale-and-clip allowed to impose the load on the free points; each round clips
# at least one point at p_max or ends, and one or two suffice in practice.
MAX_LOAD_ROUNDS = 50
# Largest rescale of the free points that BoundedLoadSweep follows by s·u - (s - 1)·v; a
# larger one (a start far from the load) takes u afresh instead.
MAX_SPARSE_SCALE = 2.0


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
      points next to touch, smallest gap (smallest ``u - h``) first (``u``, ``h`` in m; ``u``
      may be the step's linear update, it only orders the candidates), each up to its
      ``p_max`` — what raising the approach until they touch would do;
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
    key = u[cand] - h[cand]
    # the points needed cannot outnumber deficit / (smallest p_max): order only that many
    # (sorting every unloaded point took 12 ms a call, 18 calls in PS's p_Y chain), and
    # every point where the round-off of the sums needs more
    for count in (int(deficit / float(p_max[cand].min())) + 2, cand.size):
        order = cand[_stable_order_head(key, count)]
        room = np.cumsum(p_max[order])
        k = int(np.searchsorted(room, deficit)) + 1  # points needed
        if k <= room.size or order.size == cand.size:
            break
    take = order[:k]
    p[take] = p_max[take]
    # the last one takes what is left (its room minus the overshoot)
    p[take[-1]] -= room[k - 1] - deficit if k <= room.size else 0.0


def _stable_order_head(key, count):
    """The first ``count`` or more indices of ``argsort(key, kind="stable")``, the same
    (every key up to the ``count``-th smallest, ties in index order), without sorting the
    rest."""
    if count >= key.size:
        return np.argsort(key, kind="stable")
    head = np.flatnonzero(key <= np.partition(key, count - 1)[count - 1])
    return head[np.argsort(key[head], kind="stable")]


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


class BoundedLoadSweep:
    """The fused bounded load step with ``u = K*p`` kept up to date (module docstring).

    ``ks`` is the kernel set of the solve (:func:`.cg.kernel_set`: the numba kernels of
    :mod:`.kernels` or an array set), whose ``update``, ``rescale_free``, ``free_mask``,
    ``changed_points`` and ``add_point_responses`` take the step; its rare numpy parts (a
    shortened step, a restart of the free set) run through ``ks.on_host``. ``base_op`` is
    the convolution (with ``real_space_kernel()`` when ``sparse_ok``), ``conv(x, out)`` the
    caller's counted ``out = K*x``, ``buf()`` a work array of the set; ``p_max`` (Pa) has one
    entry per point, ``target`` is the force over the pixel area (Σp, Pa). At most
    ``sparse_max`` changed points of the step, and as many of each rescale round, are
    applied as point responses; more, and ``u`` is convolved afresh.
    """

    def __init__(
        self, ks, base_op, shape, p_max, target, sparse_max, sparse_ok, conv, buf, finish_r=None
    ):
        n = p_max.size
        self.ks = ks
        self.base_op = base_op
        self.shape = shape
        self.p_max = p_max
        self.target = target
        self.sparse_max = sparse_max if sparse_ok else -1
        self.conv = conv
        self.buf = buf
        self.spare = buf()  # the next pressure; the old one becomes the spare
        self.spare_mask = ks.empty(n, np.uint8)
        self.v = None  # K*p_b (m), None while it is not known
        self._v_buf = self._bound_buf = None  # allocated on first use
        # r = K*t left in the spectrum (the caller's split convolution): finish_r(r) takes
        # its inverse, only for a step that follows u by its linear part; None: r is whole
        self.finish_r = finish_r
        self.green = None

    def forget_bound_displacement(self):
        """Drop ``v``: the caller recomputed ``u`` from scratch (a refresh) or changed the
        free set itself (violators added without a step: a point at the bound made free
        leaves the bound by a plain step, which ``update`` does not record)."""
        self.v = None

    def step(self, p, u, r, t, h, m, d, tau, found, idx_buf, val_buf, counts):
        """One CG step from ``p`` along ``t`` with length ``tau`` (``r = K*t``, ``u = K*p``,
        ``d`` the approach in m), the load imposed on the free points. ``found`` holds the
        violators ``kernels.direction`` counted and recorded (three arrays). ``idx_buf``,
        ``val_buf`` and ``counts`` are the caller's event records (``kernels.update``),
        reused by the rescale rounds once the step's events are applied.

        Returns ``(p, m, left, joined, pen, how, reset)``: the new pressure and free set
        (arrays of this object's or the caller's, to use from now on), the points that left
        and joined the free set, the largest ``|g|`` over the joining points (m), how ``u``
        was brought to ``K*p`` (a key of the solver's ``u_updates``; a convolution that takes
        ``v`` afresh is counted by ``conv`` but not there), and whether the step was
        shortened or restarted (the conjugation is then reset).
        """
        q = self.spare
        violators, vidx, vg = found
        ks = self.ks
        # with r in the spectrum, u is left as it was (K*p); it follows the step's linear
        # part below only where the step is followed without a convolution
        followed = self.finish_r is None
        total, pen, at_bound, complete = ks.update(
            p, q, u, r, t, h, m, self.p_max, True, 1.0, d, tau, violators,
            idx_buf, val_buf, counts, True, followed, vidx, vg, self.sparse_max,
        )  # fmt: skip
        rest = self.target - at_bound
        free_sum = total - at_bound
        if rest < 0.0 or (rest > 0.0 and not free_sum > 0.0):
            return self._numpy_step(p, u, r, t, h, m, d, tau, followed)
        changed = int(counts.sum())
        # records complete: no chunk was swept without them (kernels.update)
        sparse = changed <= self.sparse_max and complete
        if sparse:
            followed = followed or self._follow_linear_part(u, r, tau)
            idx, vals = ks.changed_points(counts, idx_buf, val_buf)
            self._add_responses(u, idx, vals)
            self._follow_bound(p, q, idx)
        else:
            self.v = None
        m_new = self.spare_mask
        reset = False
        for _ in range(MAX_LOAD_ROUNDS):
            s = rest / free_sum if free_sum > 0.0 else 1.0
            if sparse and not 0.0 <= s <= MAX_SPARSE_SCALE:
                # s·u - (s - 1)·v carries the round-off of u and v times |s|
                sparse = False
                self.v = None
            v = self.v if sparse else u  # v is not read without u
            total, at_bound, left, joined = ks.rescale_free(
                q, u, v, m, m_new, t, self.p_max, s, sparse, idx_buf, val_buf, counts
            )
            over = int(counts[:, 0].sum())
            if not over:
                break
            if sparse and over <= self.sparse_max:
                idx, vals = ks.changed_points(counts, idx_buf, val_buf)
                self._add_responses(u, idx, vals)
                self._add_responses(self.v, idx, self.p_max[idx])
            else:
                sparse = False
                self.v = None
            rest = self.target - at_bound
            free_sum = total - at_bound
            if rest < 0.0 or not free_sum > 0.0:
                # every free point clipped (the deficit goes to the next points to touch), or
                # the bound's round-off above the load (the excess comes off the bound); the
                # step's linear u orders the candidates
                followed = followed or self._follow_linear_part(u, r, tau)
                left, joined = self._restart_free_set(q, u, h, m, m_new, t)
                sparse = False
                self.v = None
                reset = True
                break
        if sparse:
            how = "point responses" if changed else "linear"
        else:
            self.conv(q, u)
            how = "full: changes"
        self.spare, self.spare_mask = p, m
        return q, m_new, left, joined, pen, how, reset

    def _follow_linear_part(self, u, r, tau):
        """``u -= τ K*t``, ``r = K*t`` first brought to real space (the inverse its split
        convolution skipped). Returns True: ``u`` has followed."""
        self.finish_r(r)
        self.ks.subtract_scaled(u, r, tau)
        return True

    def _numpy_step(self, p, u, r, t, h, m, d, tau, followed):
        """The step that must be shortened: :func:`bounded_load_step` from the old state
        (``update`` left ``p``, ``m`` and ``t`` as they were), then ``u = K*p``."""
        if followed:
            u += tau * r  # back to K*p to round-off (it gives the gap of the joining points)
        left, joined, pen, _ = self.ks.on_host(
            bounded_load_step, p, u, h, m, t, self.p_max, d, tau, self.target, writes=(0, 3, 4)
        )
        self.conv(p, u)
        self.v = None
        return p, m, left, joined, pen, "full: bounded load", True

    def _restart_free_set(self, q, u, h, m_old, m_new, t):
        """:func:`impose_bounded_load`'s restart on ``q``, then the free set rebuilt;
        returns ``(left, joined)`` against ``m_old``."""
        ks = self.ks
        ks.on_host(
            impose_bounded_load, q, m_new, t, self.p_max, self.target, u, h, writes=(0, 1, 2)
        )
        ks.free_mask(q, m_new, self.p_max, True)
        t *= m_new
        old = m_old != 0
        new = m_new != 0
        xp = ks.xp
        return int(xp.count_nonzero(old & ~new)), int(xp.count_nonzero(~old & new))

    def _follow_bound(self, p, q, idx):
        """Bring ``v`` from ``K*p_b`` to ``K*q_b``: only the changed points ``idx`` can have
        joined or left the bound; without a ``v`` it is taken afresh (one convolution)."""
        if self.v is None:
            if self._v_buf is None:
                self._v_buf, self._bound_buf = self.buf(), self.buf()
            self.ks.xp.multiply(q, q >= self.p_max, out=self._bound_buf)
            self.v = self.conv(self._bound_buf, self._v_buf)
            return
        xp = self.ks.xp
        idx = xp.unique(idx)  # a point clipped and rejoined is recorded twice
        ub = self.p_max[idx]
        before = xp.where(p[idx] >= ub, p[idx], 0.0)
        after = xp.where(q[idx] >= ub, q[idx], 0.0)
        moved = after != before
        self._add_responses(self.v, idx[moved], (after - before)[moved])

    def _add_responses(self, field, idx, values):
        """``field += K*c`` for pressures ``values`` (Pa) on the points ``idx``."""
        if not idx.size:
            return
        if self.green is None:
            self.green = self.base_op.real_space_kernel()
        self.ks.add_point_responses(field.reshape(self.shape), self.green, idx, values)
