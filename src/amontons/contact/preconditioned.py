"""The preconditioned, bound-constrained conjugate gradient (docs/models.md §2.2, "The
preconditioned iteration"): the solver's second iteration, beside Polonsky–Keer's.

Same problem and arguments as :func:`.cg.polonsky_keer` (SI units: pressures Pa, lengths
m). Per iteration, on the free set ``F`` (points strictly between their bounds, and those at
a bound whose gap pulls them off it):

1. ``g = u - h - d`` on ``F``; load control: ``d`` the mean of ``u - h`` over the interior,
   then ``g`` made zero-sum on ``F`` (a step must not change the force);
2. ``w = K⁻¹ g`` by the kernel's inverse symbol in Fourier space (``|q| E*/2``, plus a
   uniform Winkler compliance; on a padded window the periodic one of the window itself),
   kept on ``F`` and made zero-sum there: a Fourier-diagonal preconditioner restricted to
   the contact set (Vollebregt, J. Comput. Phys. 257 (2014) 333);
3. ``t = w + β t`` with ``β = Σ g·w / (Σ g·w)_old`` (Fletcher–Reeves), never restarted when
   ``F`` changes (Vollebregt's BCCG, J. Optim. Theory Appl. 162 (2014) 931); only a
   direction that is no descent falls back to ``w``;
4. ``τ = Σ g·t / Σ t·K t`` (the denominator by Parseval from the forward transform of
   ``t``); ``p ← clip(p - τ t, 0, p_max)``: the points that cross a bound stop there, a
   pressure below round-off of the peak goes to 0;
5. load control: the interior points scaled to carry the load again
   (``_Iteration._impose_load`` says what happens where they cannot);
6. ``u`` follows the step by its linear part and the responses of a few clipped points, or
   is taken afresh (under a bound, after many clipped points, every ``refresh`` steps).

Convergence is the Polonsky–Keer loop's: the complementarity and the relative change of
``p`` both below ``tol`` and the load carried, judged on a fresh ``u``. One iteration costs
2–2.5 FFT pairs (the preconditioner's pair, the direction's forward transform, the inverse
``u`` follows by or a fresh ``u``), against Polonsky–Keer's 1.3–1.5; it takes 0.2–0.5 of
Polonsky–Keer's iterations on rough periodic surfaces (benchmarks/README.md, benchmark 3b).
"""

from __future__ import annotations

import numpy as np

from . import fft as _fft
from . import kernels as _kernels
from . import preconditioned_kernels as _pk
from .bounded_load import fully_bound_approach
from .cg import finish_outcome
from .cg_iteration import SPARSE_MAX_PADDED, SPARSE_MAX_PERIODIC
from .constraints import HardWall
from .options import CGOptions
from .stall import StallMonitor

METHOD = "preconditioned BCCG"
# A pressure below this fraction of the field's peak is round-off: the step sets it to 0
# (a point left there by round-off would stay in the free set, carry nothing and, where
# every loaded point sits at its bound, set the approach by itself).
ROUND_OFF = 1e-13
# Halvings of a bounded load-controlled step that leaves no point off its bound to carry a
# deficit of the load.
MAX_HALVINGS = 40
# Rounds of the interior rescale that imposes the load: each round clips the points it
# lifts past their bound and takes the rest up again (one round without a bound).
MAX_RESCALES = 40


def preconditioned_cg(
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
):
    """Solve the contact problem by the preconditioned bound-constrained CG (module doc).

    Arguments and outcome as :func:`.cg.polonsky_keer`; ``operator`` is a convolution of
    :mod:`.convolution` (its ``precondition``), or a Winkler wrapper of one (``operator``
    and ``compliance`` attributes: contact hardening), whose compliance the
    preconditioner takes as its largest value. Of ``options`` it reads ``tol``,
    ``max_iter``, ``refresh`` and ``raise_on_failure``."""
    if (load is None) == (displacement is None):
        raise ValueError("exactly one of load and displacement must be given")
    state = _Iteration(
        operator,
        heights,
        options,
        pixel_area=pixel_area,
        h_scale=h_scale,
        p_init=p_init,
        load=load,
        displacement=displacement,
        constraint=HardWall() if constraint is None else constraint,
    )
    state.run()
    return finish_outcome(
        state.constraint,
        options.tol,
        options.raise_on_failure,
        pixel_area,
        p=state.p,
        u=state.u,
        h=state.h,
        d=state.d,
        load_control=state.load_control,
        converged=state.converged,
        stalled=state.stalled,
        it=state.it,
        residual=state.residual,
        history=state.history,
        calls=state.calls,
        resets=state.resets,
        shape=state.shape,
        method=METHOD,
    )


class _Iteration:
    """The state of one preconditioned solve and its steps (module doc)."""

    def __init__(self, operator, heights, options, *, pixel_area, h_scale, p_init, load,
                 displacement, constraint):  # fmt: skip
        self.convolution = getattr(operator, "operator", operator)
        compliance = getattr(operator, "compliance", None)
        self.compliance = np.empty(0) if compliance is None else np.ravel(compliance)
        self.winkler = float(np.max(compliance)) if compliance is not None else 0.0
        self.operator = operator
        self.constraint = constraint
        self.tol, self.max_iter, self.refresh = options.tol, options.max_iter, options.refresh
        self.h_scale = h_scale
        self.shape = np.shape(heights)
        n = int(np.size(heights))
        self.h = self._buffer(n, np.ravel(heights))
        self.p_max = _pk.bounds_array(constraint, n)
        self.p = self._buffer(n, np.ravel(p_init))
        self.load_control = load is not None
        self.target = None if load is None else float(load) / pixel_area
        self.d = 0.0 if displacement is None else float(displacement)
        self.u, self.gf, self.w, self.t = (self._buffer(n) for _ in range(4))
        self.t[:] = 0.0
        self.free = np.zeros(n, dtype=np.uint8)
        periodic = getattr(self.convolution, "periodic", False)
        self.singular_full = periodic and load is None
        # u follows a step by its linear part where the clip moved few points (their
        # responses added), on the hard wall; a bound's load rescale moves only the
        # interior, which the linear part does not follow (u is then taken afresh)
        self.linear = self.convolution.splits and not constraint.bounded
        cap = SPARSE_MAX_PERIODIC if periodic else SPARSE_MAX_PADDED
        self.clip_idx = np.empty(cap, dtype=np.int64)
        self.clip_added = np.empty(cap)
        self.r = self._buffer(n) if self.linear else None
        # the pressures before a bounded load-controlled step, which may have to be halved
        self.saved = self._buffer(n) if (constraint.bounded and load is not None) else None
        self.green = None  # the real-space kernel, fetched at the first point responses
        self.calls = 0.0
        self.it = 0
        self.resets = 0
        self.since_fresh = 0
        self.history = []
        self.residual = np.inf
        self.change = np.inf
        self.converged = False
        self.stalled = None
        self.gw_old = 0.0
        if self.load_control:
            self._start_at_load()
        else:
            np.minimum(self.p, self.p_max, out=self.p)
        self.peak = float(self.p.max())
        self._fresh_displacement()

    @staticmethod
    def _buffer(n, values=None):
        out = _fft.empty(n, np.float64, "pyfftw" if _fft.HAVE_PYFFTW else "numpy")
        if values is not None:
            out[:] = values
        return out

    def _start_at_load(self):
        """Scale the start to the load (a uniform start if it carries none), then clip it
        to the bound: the other order would lift points past it (docs/models.md §2.3)."""
        total = float(self.p.sum())
        if not total > 0:
            self.p[:] = 1.0
            total = float(self.p.size)
        self.p *= self.target / total
        np.minimum(self.p, self.p_max, out=self.p)
        if not self._impose_load(*_pk.interior_sum(self.p, self.p_max)):
            # a start whose loaded points all sit at their bound short of the load (a
            # neighbouring law's pressures clipped to this one's): the uniform start
            self.p[:] = self.target / self.p.size
            np.minimum(self.p, self.p_max, out=self.p)
            self._impose_load(*_pk.interior_sum(self.p, self.p_max))

    def _impose_load(self, total, inner) -> bool:
        """Make the field (its sum ``total``, of which ``inner`` strictly between the
        bounds, Pa) carry the load: the interior points scaled, or, where the points at
        their bound alone carry more, the whole field scaled down (every point then lies
        below its bound). False where no interior point is left to carry a deficit: the
        deficit stays until the gap draws more points in (they join the free set)."""
        for _ in range(MAX_RESCALES):
            if abs(total - self.target) <= 1e-14 * self.target:
                return True
            bound = total - inner
            if bound > self.target * (1 + 1e-12):
                # the whole field scaled down: every point then lies off its bound
                self.p *= self.target / total
                return True
            if bound >= self.target * (1 - 1e-12):
                # the points at their bound carry the load to round-off (their sum's, of
                # order n·eps): the others carry nothing
                _pk.scale_interior(self.p, self.p_max, 0.0)
                return True
            if inner <= 0.0:
                return False
            total, inner = _pk.scale_interior(self.p, self.p_max, (self.target - bound) / inner)
        return True

    def _fresh_displacement(self):
        self.operator(self.p.reshape(self.shape), out=self.u.reshape(self.shape))
        self.calls += 1
        self.since_fresh = 0

    def run(self):
        monitor = StallMonitor()
        while True:
            self._gradient()
            if self._finished(monitor):
                return
            self.it += 1
            tau = self._direction_step()
            if tau is None:
                self._judge_without_descent()
                return
            self._take_step(tau)

    def _gradient(self):
        """The approach (load control), the free set, its zero-sum gradient and the
        residual (appended to the history)."""
        if self.load_control:
            total, count = _pk.interior_approach(self.u, self.h, self.p, self.p_max)
            self.d = (
                total / count if count else fully_bound_approach(self.u, self.h, self.p, self.d)
            )
        total, self.n_free, squares, n_interior, worst = _pk.free_gradient(
            self.u, self.h, self.p, self.p_max, self.d, self.free, self.gf
        )
        if self.load_control and self.n_free:
            _pk.shift_free(self.gf, self.free, total / self.n_free)
        rms = np.sqrt(squares / n_interior) if n_interior else 0.0
        self.residual = max(rms, worst) / self.h_scale
        self.n_interior = n_interior
        self.history.append(self.residual)

    def _finished(self, monitor) -> bool:
        """Whether the solve ends here: converged (judged on a fresh ``u``), stalled, or at
        its iteration cap."""
        if (
            self.residual < self.tol
            and (self.change < self.tol or self.n_free == 0)
            and self._at_load()
        ):
            if self.since_fresh == 0:
                self.converged = True
                return True
            self._judge_on_fresh_displacement()
            return self._finished(monitor)
        if self.n_free == 0:
            self.stalled = "no free point is left and the gaps do not close"
            return True
        if self.singular_full and self.n_interior == self.p.size:
            self.stalled = (
                "periodic displacement-controlled solve reached full contact: the mean "
                "pressure is then undetermined (the q = 0 mode is the rigid mode); use load "
                f"control or a smaller displacement (d = {self.d:.3e} m)"
            )
            return True
        if self.it >= self.max_iter:
            return True
        if monitor.update(self.residual):
            self.stalled = monitor.message()
            return True
        return False

    def _judge_on_fresh_displacement(self):
        """``u`` taken afresh and the gradient and residual taken again on it, in place of
        the last ones: convergence is never judged on a followed ``u``."""
        self._fresh_displacement()
        self.history.pop()
        self._gradient()

    def _at_load(self) -> bool:
        """Whether the field carries the load (to round-off; always under displacement
        control)."""
        if not self.load_control:
            return True
        return abs(float(self.p.sum()) - self.target) <= 1e-12 * self.target

    def _direction_step(self):
        """The preconditioned direction ``t`` and its step length ``τ`` (None: none)."""
        self.convolution.precondition(
            self.gf.reshape(self.shape), self.w.reshape(self.shape), self.winkler
        )
        self.calls += self.convolution.precondition_pairs
        total_w, gw, total_t = _pk.preconditioned_sums(self.w, self.gf, self.t, self.free)
        beta = gw / self.gw_old if self.gw_old > 0 else 0.0
        shift = (total_w + beta * total_t) / self.n_free if self.load_control else 0.0
        gt = _pk.next_direction(self.w, self.gf, self.free, shift, beta, self.t)
        if not gt > 0 and beta:
            # not a descent direction after a change of the free set: start afresh
            self.resets += 1
            shift = total_w / self.n_free if self.load_control else 0.0
            gt = _pk.next_direction(self.w, self.gf, self.free, shift, 0.0, self.t)
        self.gw_old = gw
        curvature = self._curvature()
        if not (gt > 0 and curvature > 0 and np.isfinite(curvature)):
            return None
        return gt / curvature

    def _judge_without_descent(self):
        """No descent direction is left: the gap on the free set is round-off (uniform
        full contact, a one-point free set under load control). Converged where the
        residual, on a fresh ``u``, is below ``tol``; else stalled."""
        self.it -= 1  # this iteration took no step
        if self.since_fresh:
            self._judge_on_fresh_displacement()
        if self.residual < self.tol:
            self.converged = True
        else:
            self.stalled = "no descent direction is left while the gaps do not close"

    def _curvature(self) -> float:
        """``Σ t·(K t)`` (m·Pa), by Parseval where the convolution splits (its spectrum
        then holds ``K t``'s, which a step that ``u`` follows brings to real space)."""
        if self.convolution.splits:
            self.convolution.forward(self.t.reshape(self.shape))
            energy = self.convolution.multiply_energy()
            self.calls += 0.5
        else:
            self.convolution(self.t.reshape(self.shape), out=self.w.reshape(self.shape))
            energy = float(np.dot(self.t, self.w))
            self.calls += 1
        if self.compliance.size:
            energy += float(np.dot(self.compliance * self.t, self.t))
        return energy

    def _take_step(self, tau):
        """``p ← clip(p - τ t)``, the load imposed again, ``u`` brought to ``K p``; the
        relative change of ``p``."""
        if self.saved is not None:
            np.copyto(self.saved, self.p)
        for _ in range(MAX_HALVINGS):
            total, inner, change, clipped, peak = _pk.step(
                self.p, self.t, tau, self.p_max, ROUND_OFF * self.peak, self.clip_idx,
                self.clip_added,
            )  # fmt: skip
            factor = self.target / total if (self.load_control and total > 0) else 1.0
            if not self.load_control or self._impose_load(total, inner) or self.saved is None:
                break
            # every loaded point went to a bound short of the load, none left to carry the
            # deficit: a shorter step (as Polonsky-Keer's bounded load step does)
            np.copyto(self.p, self.saved)
            tau *= 0.5
            self.resets += 1
        self.peak = peak
        self.change = change / total if total > 0 else 0.0
        follows = self.linear and clipped <= self.clip_idx.size
        if follows and self.since_fresh + 1 < self.refresh:
            self._follow(tau, clipped, factor)
        else:
            self._fresh_displacement()

    def _follow(self, tau, clipped, factor):
        """``u`` after the step from its linear part (``K t``: the inverse the curvature's
        split transform left) and the responses of the points the clip moved."""
        self.convolution.inverse(self.r.reshape(self.shape))
        self.calls += 0.5
        _pk.follow_step(self.u, self.r, self.t, tau, self.compliance, factor)
        if clipped:
            idx = self.clip_idx[:clipped]
            added = self.clip_added[:clipped] * factor
            if self.green is None:
                self.green = self.convolution.real_space_kernel()
            _kernels.add_point_responses(self.u.reshape(self.shape), self.green, idx, added)
            if self.compliance.size:
                self.u[idx] += self.compliance[idx] * added
        self.since_fresh += 1
