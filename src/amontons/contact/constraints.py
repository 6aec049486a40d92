"""The inequality constraints of the contact problem: the hard wall ``p >= 0`` and the bounded
wall ``0 <= p <= p_max`` (penetration hardness, docs/models.md §2.3).

A constraint is an object with three methods, which the conjugate-gradient loop of
:mod:`.cg` calls on the host (numpy arrays, pressures in Pa, gaps in m); :class:`HardWall`
documents the protocol.
"""

from __future__ import annotations

import numpy as np

_EMPTY = np.empty(0, dtype=np.intp)


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
