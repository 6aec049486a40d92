"""The Polonsky–Keer constrained conjugate gradient's iteration: its state and its steps.

The problem and the entry are :mod:`.cg`'s; this module holds the iteration.

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
set (``BOUNDED_RESET_FRACTION`` under a bound). The fixed point is Polonsky & Keer's.

:class:`CGIteration` owns the control flow: stall detection (:class:`.stall.StallMonitor`),
the full-contact singularity of periodic displacement control, restarts when no descent
direction is left, the refresh of ``u = K*p`` and convergence, each a named step. The
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
the larger of the two.

Cost: at most one convolution per iteration. ``u`` follows the step linearly
(``u ← s (u - τ K*t + K*c)``, ``c`` the pressures set by the projection and the violator
step): with no changed point no convolution at all, with at most ``SPARSE_MAX_PERIODIC`` /
``SPARSE_MAX_PADDED`` of them their point responses are added
(:func:`.kernels.add_point_responses`); otherwise, and at least every ``refresh``
iterations and before convergence is declared, ``u = K*p`` is taken afresh and the inverse
transform of ``K*t`` is skipped. The bounded load step (:class:`.bounded_load.BoundedLoadSweep`)
skips it alike: it asks for the inverse only for a step it follows without a convolution.

Load control rescales ``p`` (and so ``u``) to the target force every iteration at no cost:
the stored pressure ``P`` and displacement ``U`` carry one common scale ``sigma`` (true
``p = sigma·P``, ``u = sigma·U``); ``U = K*P`` stays true when only ``sigma`` changes.

The constraint is one of :mod:`.constraints` (host methods, numpy arrays); the operator's
convolution and Winkler compliance are split by :func:`_winkler_parts`.
"""

from __future__ import annotations

import numpy as np

from .bounded_load import (
    BoundedLoadSweep,
    bounded_load_step,
    fully_bound_approach,
    impose_bounded_load,
)
from .errors import STALLED, ConvergenceError
from .stall import StallMonitor

# Reset the conjugation to steepest descent only when the points added to the free set in
# one iteration exceed this fraction of it (module docstring; 0 = the original PK rule).
RESET_FRACTION = 0.01
# The same under a bound (penetration hardness): where the bound binds, a few hundred points
# join the free set every iteration (rising from 0 at the contact's edge, falling from the
# bound inside it) while as many leave, so the 1 % rule ran steepest descent in most
# iterations; 10 % keeps the conjugation through them (docs/models.md §2.2; measured by
# benchmarks/bench_scan_warm_start.py --bounded-reset-fractions).
BOUNDED_RESET_FRACTION = 0.1
# Most changed points (clipped + added) applied to u as point responses instead of a full
# convolution, periodic and padded: about where the points' responses cost a convolution
# less its inverse (benchmarks/bench_point_responses.py; benchmarks/README.md, "Fewer
# convolutions").
SPARSE_MAX_PERIODIC = 12
SPARSE_MAX_PADDED = 32
# Largest Σa²/G of the one-pass moments about the previous approach (see _centred_moments).
RECENTRE = 1e3


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


class CGIteration:
    """The state of one constrained CG solve and its steps (module docstring).

    The fields live in the kernel set's memory as flat float64 arrays: pressure ``p`` (Pa,
    stored at the scale ``sigma``), displacement ``u = K*p`` (m, same scale), heights ``h``
    (m), the conjugate direction ``t`` and ``r = K*t``, the free set ``m`` (uint8). One
    iteration of :meth:`run` is: :meth:`_stops_before_step`, :meth:`_restart_free_set`
    (an empty free set), :meth:`_gap_moments`, :meth:`_next_direction`, then either
    :meth:`_without_descent` or :meth:`_take_step`, :meth:`_choose_conjugation`,
    :meth:`_follow_u` and :meth:`_judge`. The outcome is built from :meth:`host_fields` and
    :meth:`counters` (:func:`.cg.run_to_outcome`).
    """

    def __init__(
        self,
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
        self.ks, self.xp = ks, ks.xp
        self.tol, self.max_iter = options.tol, options.max_iter
        self.refresh, self.raise_on_failure = options.refresh, options.raise_on_failure
        # read per solve (bench_convergence.py sets it)
        self.reset_fraction = BOUNDED_RESET_FRACTION if constraint.bounded else RESET_FRACTION
        self.constraint, self.pixel_area, self.h_scale = constraint, pixel_area, h_scale
        self.load, self.load_control = load, load is not None
        self.shape, self.n = heights.shape, heights.size
        self.calls = 0  # convolutions taken
        self.forward_only = 0  # forward transforms whose inverse was skipped
        self._set_operator(operator)
        self._set_fields(heights, p_init, options)
        self._set_buffers()
        self._set_bookkeeping(operator, displacement)

    def buf(self):
        """A flat float64 array of the grid's size in the kernel set's memory (the numba
        set's are SIMD-aligned: the FFT plans run on them without copies)."""
        return self.ks.empty(self.n, np.float64)

    def conv(self, x, out):
        """``out = K*x`` (m), the Winkler term included; counts the convolution."""
        self.calls += 1
        self.base_op(x.reshape(self.shape), out=out.reshape(self.shape))
        if self.winkler:
            # the elastic-plus-Winkler operator's K*x + x/k (winkler.WinklerOperator), with
            # the compliance in the kernel set's memory
            out += self.compliance * x
        return out

    def _set_operator(self, operator):
        """The convolution, its Winkler compliance and what the operator offers: point
        responses (``sparse_ok``), a split ``K*t`` (``split``), the singular full contact
        of periodic displacement control."""
        base_op, compliance = _winkler_parts(operator)
        self.base_op, self.winkler = base_op, compliance is not None
        self.compliance = self.ks.asarray(compliance) if self.winkler else None
        self.comp_arg = self.compliance if self.winkler else self.xp.zeros(1)
        self.singular_full = getattr(operator, "periodic", False) and not self.load_control
        # every operator of .convolution offers its real-space kernel; a custom one may not
        self.sparse_ok = hasattr(base_op, "real_space_kernel")
        periodic = getattr(base_op, "periodic", False)
        self.sparse_max = SPARSE_MAX_PERIODIC if periodic else SPARSE_MAX_PADDED
        self.green = None  # the real-space kernel, fetched at the first point responses

    def _set_fields(self, heights, p_init, options):
        """``h``, the start ``p`` (rescaled to the load, within the bound), ``t``, ``m``,
        the bounded load's target and step, ``u = K*p`` and the free set's size."""
        ks, xp, n = self.ks, self.xp, self.n
        p_max, self.bounded = _bound_array(self.constraint, n)
        self.p_max = ks.asarray(p_max)
        self.h = self.buf()
        self.h[:] = ks.asarray(np.ravel(heights))
        p = self.p = self.buf()
        p[:] = ks.asarray(np.ravel(p_init))
        if p.min() < 0:
            raise ValueError("p_init must be >= 0")
        if self.load_control:
            total = p.sum()
            if not total > 0:
                p[:] = 1.0
                total = p.size
            p *= self.load / (self.pixel_area * total)
        if self.bounded:
            # after the load's rescale, which may push a start's points through the bound
            xp.minimum(p, self.p_max, out=p)
        # bounded load control: the force is imposed on the free points only (module
        # docstring)
        self.bounded_load = self.bounded and self.load_control
        self.target = self.load / self.pixel_area if self.load_control else 0.0  # Σp, Pa
        self.t = self.buf()
        self.t[:] = 0.0
        self.m = ks.empty(n, np.uint8)
        if self.bounded_load:
            ks.free_mask(p, self.m, self.p_max, self.bounded)
            ks.on_host(
                impose_bounded_load, p, self.m, self.t, self.p_max, self.target, np.zeros(n),
                self.h, writes=(0, 1, 2),
            )  # fmt: skip
        self.u, self.r = self.buf(), self.buf()
        # the convolution r = K*t taken in halves (operator.forward, .multiply_energy,
        # .inverse): an iteration that takes u = K*p afresh then skips the inverse, half an
        # FFT pair. A Winkler term needs r in real space (step_dots); the numpy bounded load
        # step updates u itself, the fused one (the sweep) asks for the inverse when it
        # follows u by the step's linear part
        with_sweep = self.bounded_load and options.bounded_load_sweep and not self.winkler
        self.split = (
            getattr(self.base_op, "splits", False)
            and not self.winkler
            and (with_sweep or not self.bounded_load)
        )
        self.sweep = None
        if with_sweep:
            self.sweep = BoundedLoadSweep(
                ks, self.base_op, self.shape, self.p_max, self.target, self.sparse_max,
                self.sparse_ok, self.conv, self.buf,
                self._finish_r if self.split else None,
            )  # fmt: skip

    def _set_buffers(self):
        """The kernels' per-chunk records: changed points and values, event counts, the
        violators found by ``direction``."""
        xp, nch, slots = self.xp, self.ks.n_chunks(self.n), self.ks.SLOTS
        self.p_old = None  # a copy of p, taken only when the step may converge
        self.idx_buf = xp.zeros((nch, slots), dtype=np.int64)
        self.val_buf = xp.zeros((nch, slots))
        self.counts = xp.zeros((nch, 2), dtype=np.int64)
        self.violators = xp.zeros(nch, dtype=np.int64)
        # the violators of chunks with few, recorded by direction for update
        # (kernels.direction)
        self.vidx = xp.zeros((nch, slots), dtype=np.int64)
        self.vg = xp.zeros((nch, slots))
        self.found = (self.violators, self.vidx, self.vg)

    def _set_bookkeeping(self, operator, displacement):
        """``u = K*p``, the free set's size, the scale, the conjugation and the counters."""
        self.conv(self.p, self.u)
        self.sigma = 1.0  # true p = sigma·p, u = sigma·u (module docstring)
        self.nc = int(self.ks.free_mask(self.p, self.m, self.p_max, self.bounded))
        self.delta, self.g_old = 0.0, 1.0
        self.since_fresh = 0  # iterations since u = K*p was taken afresh
        self.resets = 0
        self.recentres = 0  # second moment passes (see _centred_moments)
        # how u was updated after each step (for benchmarks/bench_iteration.py)
        self.updates = dict.fromkeys(
            ("linear", "point responses", "full: changes", "full: refresh", "full: bounded load"),
            0,
        )
        self.history = []
        self.d = 0.0 if self.load_control else float(displacement)
        self.residual = np.inf
        self.converged = False
        self.stalled = None
        self.it = 0
        self.monitor = StallMonitor()

    def run(self):
        """Iterate until converged, stalled or ``max_iter``."""
        while self.it < self.max_iter:
            if self.history and self.monitor.update(self.history[-1]):
                self.stalled = self.monitor.message()
                break
            self.it += 1
            if self._stops_before_step():
                break
            if self.nc == 0 and self._restart_free_set():
                break
            big_g, gt_old, t_old_sum = self._gap_moments()
            g_dot_t, rt = self._next_direction(big_g, gt_old, t_old_sum)
            if not (rt > 0 and np.isfinite(rt)):
                if self._without_descent(big_g):
                    break
                continue
            tau = g_dot_t / rt
            rms_ok = np.sqrt(big_g / max(self.nc, 1)) / self.h_scale < self.tol
            if rms_ok:
                # the convergence test needs the pressure change: keep the old field (this
                # pass is paid only in the last iterations; otherwise p is updated in place)
                self.p_old = (
                    self.xp.copy(self.p)
                    if self.p_old is None
                    else _copy(self.xp, self.p, self.p_old)
                )
            n_clip, n_add, pen, how, backtracked, psum, complete = self._take_step(tau)
            self._choose_conjugation(backtracked, n_add)
            nc_start = self.nc
            self.nc += n_add - n_clip
            sigma_old = self.sigma
            if self.load_control and not self.bounded_load:
                self.sigma = self.load / (self.pixel_area * psum)
            self._follow_u(how, n_clip + n_add, complete, tau, sigma_old)
            self._judge(big_g, nc_start, pen, rms_ok, sigma_old)
            self.history.append(self.residual)
            if self.converged:
                break

    def _stops_before_step(self) -> bool:
        """Periodic displacement control at full contact: the mean pressure is undetermined;
        stop (raise, when the options say so), the iteration not counted."""
        if not (self.singular_full and self.nc == self.n):
            return False
        self.stalled = (
            "periodic displacement-controlled solve reached full contact: the mean "
            "pressure is then undetermined (the q = 0 mode is the rigid mode); use load "
            f"control or a smaller displacement (d = {self.d:.3e} m)"
        )
        if self.raise_on_failure:
            raise ConvergenceError(
                self.stalled,
                iterations=self.it,
                residual=float(self.residual),
                tol=self.tol,
                residual_history=np.asarray(self.history),
                status=STALLED,
            )
        self.it -= 1
        return True

    def _restart_free_set(self) -> bool:
        """An empty free set (displacement control, or bounded load control with every
        loaded point at the bound): start it from the points the constraint says should be
        free. True when there are none: the solve has converged."""
        ks, sigma = self.ks, self.sigma
        if self.load_control:
            self.d = ks.on_host(fully_bound_approach, sigma * self.u, self.h, self.p, self.d)
        g = sigma * self.u - self.h - self.d
        mf = self.xp.zeros(self.n)
        # a restart of the free set, rare: the constraint's numpy test on the host
        start = ks.asarray(ks.on_host(self.constraint.violators, sigma * self.p, g, mf))
        self.nc = int(start.size)
        if self.nc == 0:
            self.residual = 0.0
            self.history.append(0.0)
            self.converged = True
            self.since_fresh = 1
            return True
        self.m[:] = 0
        self.m[start] = 1
        self.t[:] = 0.0
        if self.sweep is not None:
            self.sweep.forget_bound_displacement()
        return False

    def _gap_moments(self):
        """``G = Σ_Ic g²`` (m²), ``Σ_Ic g·t_old`` and ``Σ_Ic t_old``; load control also
        moves the approach ``d`` to the mean gap on the free set."""
        if self.load_control:
            self.d, big_g, gt_old, t_old_sum, recentred = _centred_moments(
                self.ks, self.u, self.sigma, self.h, self.m, self.t, self.d, self.nc
            )
            self.recentres += recentred
            return big_g, gt_old, t_old_sum
        _, big_g, gt_old, _ = self.ks.gap_moments(
            self.u, self.sigma, self.h, self.m, self.t, self.d
        )
        return big_g, gt_old, 0.0

    def _next_direction(self, big_g, gt_old, t_old_sum):
        """The conjugate direction ``t`` and ``r = K*t``; returns ``(Σ g·t, Σ r·t)``."""
        beta = self.delta * big_g / self.g_old if self.g_old > 0 else 0.0
        g_dot_t = big_g + beta * gt_old if beta else big_g
        # load control: Σ_Ic t = 0 (t_old loses its sum where points were clipped); the
        # mean of r over Ic then drops out of Σ r t
        shift = beta * t_old_sum / self.nc
        self.ks.direction(
            self.u, self.sigma, self.h, self.m, self.t, self.d, beta, shift, self.p,
            self.p_max, self.bounded, *self.found,
        )  # fmt: skip
        self.g_old = big_g
        if self.split:
            # r = K*t in halves: Σ r t from the spectrum now, the inverse only if u follows
            # the step incrementally (_follow_u)
            self.base_op.forward(self.t.reshape(self.shape))
            rt = self.base_op.multiply_energy()
            self.forward_only += 1
        else:
            conv_t(self.base_op, self.t, self.r, self.shape)
            self.calls += 1
            rt, _ = self.ks.step_dots(self.r, self.t, self.m, self.comp_arg, self.winkler)
        if self.load_control and self.nc == 1:
            # a one-point free set has no direction that keeps its force (its t is
            # round-off): no descent direction
            rt = 0.0
        return g_dot_t, rt

    def _without_descent(self, big_g) -> bool:
        """No descent direction (the gap on the free set is nil or round-off, or conjugacy
        was lost to round-off). The solution if the gap on the free set is below tol and
        nothing penetrates off it, judged on a freshly convolved u (True: converged);
        otherwise penetrating points join the free set at p = 0 and the next,
        steepest-descent, iteration moves them."""
        ks, sigma, nc = self.ks, self.sigma, self.nc
        g = sigma * self.u - self.h - self.d
        ol = ks.asarray(
            ks.on_host(self.constraint.violators, sigma * self.p, g, self.m.astype(np.float64))
        )
        pen = float(abs(g[ol]).max()) if ol.size else 0.0
        self.residual = max(np.sqrt(big_g / nc), pen) / self.h_scale
        self.history.append(self.residual)
        if self.residual < self.tol and self.since_fresh:
            self.conv(self.p, self.u)
            self.since_fresh = 0
            return False
        if self.residual < self.tol:
            self.converged = True
            return True
        self.m[ol] = 1
        self.nc += int(ol.size)
        if self.sweep is not None:
            self.sweep.forget_bound_displacement()
        self.delta = 0.0
        self.g_old = 0.0
        return False

    def _take_step(self, tau):
        """``p ← p - τ t``, projected, violators added: by the bounded load's fused sweep,
        its numpy step (then ``u`` afresh), or ``kernels.update``. Returns ``(points clipped,
        points added, worst penetration (m), how u followed (None: left to _follow_u),
        backtracked, Σp stored, whether update's records hold every changed point)``."""
        ks = self.ks
        if self.sweep is not None:
            self.p, self.m, n_clip, n_add, pen, how, backtracked = self.sweep.step(
                self.p, self.u, self.r, self.t, self.h, self.m, self.d, tau, self.found,
                self.idx_buf, self.val_buf, self.counts,
            )  # fmt: skip
            return n_clip, n_add, pen, how, backtracked, None, True
        if self.bounded_load:
            n_clip, n_add, pen, backtracked = ks.on_host(
                bounded_load_step, self.p, self.u, self.h, self.m, self.t, self.p_max, self.d,
                tau, self.target, writes=(0, 3, 4),
            )  # fmt: skip
            # the step rescaled the free points only: u is taken afresh
            self.conv(self.p, self.u)
            return n_clip, n_add, pen, "full: bounded load", backtracked, None, True
        psum, pen, _, complete = ks.update(
            self.p, self.p, self.u, self.r, self.t, self.h, self.m, self.p_max, self.bounded,
            self.sigma, self.d, tau, self.violators, self.idx_buf, self.val_buf, self.counts,
            False, not self.split, self.vidx, self.vg,
            self.sparse_max if self.sparse_ok else -1,
        )  # fmt: skip
        n_clip, n_add = ks.event_counts(self.counts)
        return n_clip, n_add, pen, None, False, psum, complete

    def _choose_conjugation(self, backtracked, n_add):
        """Keep the conjugation (``delta = 1``) unless the step backtracked or added more
        than ``RESET_FRACTION`` of the free set; then steepest descent (a reset)."""
        if backtracked or (n_add and n_add > self.reset_fraction * self.nc):
            self.delta = 0.0
            self.resets += 1
        else:
            self.delta = 1.0

    def _follow_u(self, how, changes, complete, tau, sigma_old):
        """Bring ``u`` to ``K*p`` after the step: afresh (a refresh is due, or too many
        changed points), or by the step's linear part (the inverse of ``K*t`` the split
        convolution skipped) and the changed points' responses."""
        # a chunk with more events than its records hold: u cannot follow by point
        # responses either
        too_many = changes > self.sparse_max or not complete
        if how is not None:
            # the bounded load step brought u to K*p itself (sigma stays 1)
            if how.startswith("full"):
                self.since_fresh = 0
            elif self.since_fresh >= self.refresh:
                self.conv(self.p, self.u)
                self.since_fresh = 0
                self.sweep.forget_bound_displacement()
                how = "full: refresh"
            else:
                self.since_fresh += 1
            self.updates[how] += 1
        elif self.since_fresh >= self.refresh or (changes and (too_many or not self.sparse_ok)):
            self.conv(self.p, self.u)
            self.since_fresh = 0
            self.updates["full: changes" if too_many else "full: refresh"] += 1
        else:
            self.updates["point responses" if changes else "linear"] += 1
            self._follow_u_incrementally(changes, tau, sigma_old)
            self.since_fresh += 1

    def _finish_r(self, r):
        """``r = K*t`` brought to real space from the spectrum the split convolution left
        (its inverse, counted: the forward is then no longer a forward only)."""
        self.base_op.inverse(r.reshape(self.shape))
        self.forward_only -= 1
        self.calls += 1

    def _follow_u_incrementally(self, changes, tau, sigma_old):
        """``u -= τ/σ K*t`` (the inverse the split step skipped), then ``u += K*c / σ`` for
        the pressures ``c`` the projection and the violators set (point responses)."""
        ks, u = self.ks, self.u
        if self.split:
            self.base_op.inverse(self.r.reshape(self.shape))
            self.forward_only -= 1
            self.calls += 1
            ks.subtract_scaled(u, self.r, tau / sigma_old)
        if changes:
            # u (stored, scale sigma_old) += K*c / sigma_old; u = K*p holds for the stored
            # pair whatever their common scale, so the new scale needs no pass
            idx, vals = ks.changed_points(self.counts, self.idx_buf, self.val_buf)
            if self.green is None:
                self.green = self.base_op.real_space_kernel()
            ks.add_point_responses(u.reshape(self.shape), self.green, idx, vals / sigma_old)
            if self.winkler:
                # a point clipped and re-added appears twice: add.at sums both
                ks.add_at(u, idx, self.compliance[idx] * vals / sigma_old)

    def _judge(self, big_g, nc_start, pen, rms_ok, sigma_old):
        """The residual of this iteration, and convergence: the complementarity below tol,
        then the pressure change, then the complementarity again on a fresh ``u`` with the
        scale settled into the fields and a fresh free set."""
        comp = max(np.sqrt(big_g / max(nc_start, 1)), pen) / self.h_scale
        self.residual = comp
        if not (comp < self.tol and rms_ok):
            return
        change, psum_true = self.ks.relative_change(self.p, self.sigma, self.p_old, sigma_old)
        change = float(change / psum_true) if psum_true > 0 else 0.0
        self.residual = max(change, comp)
        if not change < self.tol:
            return
        self._settle_scale()
        comp_now, d_now, self.nc = _final_complementarity(
            self.ks, self.u, self.h, self.p, self.d, self.load_control, self.m, self.t,
            self.p_max, self.bounded,
        )  # fmt: skip
        comp_now /= self.h_scale
        self.residual = max(change, comp_now)
        if comp_now < self.tol:
            self.d = d_now
            self.converged = True
        self.t *= self.m  # the fresh mask replaces the sparsely maintained one

    def _settle_scale(self):
        """Settle the scale into the fields (two passes, only where convergence is judged)."""
        self.p *= self.sigma
        if self.since_fresh:
            self.conv(self.p, self.u)
            self.since_fresh = 0
        else:
            self.u *= self.sigma
        self.sigma = 1.0

    def host_fields(self):
        """``(p, u, h)`` on the host (numpy arrays; the numba set's already are), with ``p``
        (Pa) at its true scale and ``u = K*p`` (m) fresh: the fields of the outcome."""
        if self.sigma != 1.0:
            self.p *= self.sigma
            self.u *= self.sigma
        if self.since_fresh:
            self.conv(self.p, self.u)
        ks = self.ks
        return ks.to_host(self.p), ks.to_host(self.u), ks.to_host(self.h)

    def counters(self) -> dict:
        """What the iteration did besides its count: moment recentres, how ``u`` followed
        each step, forward transforms whose inverse was skipped."""
        return {
            "moment_recentres": self.recentres,
            "u_updates": self.updates,
            "forward_only_transforms": self.forward_only,
        }


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
