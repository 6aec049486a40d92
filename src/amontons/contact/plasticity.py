"""Plasticity laws of appendix B.2.3 on top of the Polonsky–Keer solver.

Two laws, each with local (eq. B.2) or volume-conserving (eq. B.3) plastic increments:

* :class:`PenetrationHardness`: the pressure is bounded by p_Y (scalar or per pixel). A bounded
  CG (0 ≤ p ≤ p_Y) gives the elastic field; where p = p_Y the gap is negative and the indenter
  is lowered by α·Δh_pl; repeat until the gap is non-negative everywhere.
* :class:`ContactHardening`: p_Y = k·|h_pl| per pixel, so an untouched point yields at once.

Routes (docs/models.md §2.4; ``method=`` of :func:`amontons.contact.solve`). Under monotonic
loading every contact point of the hardening law sits on its yield surface, p = k·|h_pl|, so
the converged state is an elastic half-space plus a Winkler layer of stiffness k:
(K + I/k) p = h + d on the contact set. That linear complementarity problem is solved
directly, with one extension that keeps it exact when a point unloads under a later load: the
plastic displacement of earlier steps is a floor, so each point either flows (Winkler, on the
undeformed heights) or stays elastic on its earlier deformation; an active-set loop picks
which (it is the convex problem with dissipation potential φ'(p) = max(|h_pl,prev|, p/k)).
This is the ``"winkler"`` route, the default for contact hardening with local increments.
Penetration hardness with local increments needs no outer loop either: the appendix scheme
at a fixed approach stops once every point at p = p_Y has had its penetration removed, which
leaves the bounded solution unchanged, so the state is one bounded CG on h + h_pl,prev under
the load (the approach is the Lagrange multiplier of the force) followed by one update
h_pl += g·θ(−g) where p = p_Y. This is the ``"bounded"`` route (docs/models.md §2.3), the
default there. The appendix's iterative scheme (bounded CG, gap, increment, repeat) is the
``"appendix"`` route: taken by volume-conserving increments (where pile-up moves the
heights of points that did not yield) and on request (``method="appendix"``, the test
oracle of both exact routes).

Failures do not raise here: every route returns a :class:`~.result.Outcome` whose ``status``
(0 converged, 1 iteration cap, 2 stalled) and ``message`` say how it stopped, holding the
last iterate; :func:`amontons.contact.solve` decides whether to raise.

Load control of the appendix scheme is a root find on the rigid-body approach (the load is a
continuous, non-decreasing function of it), each trial starting from the previous step's
plastic state.

SI units: heights, gaps, plastic displacement in m; pressures and p_Y in Pa; k in Pa/m.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np
from scipy import optimize

from .cg import BoundedWall, polonsky_keer
from .errors import ITERATION_CAP, STALLED, ContactInputError, FreeBoundaryError
from .laws import ContactHardening, Increment, PenetrationHardness
from .options import MAX_ACTIVE_SET_ROUNDS, default_max_outer
from .plastic_increments import local_increment, volume_conserving_increment
from .result import Outcome


@dataclass
class _Tally:
    """Work summed over the conjugate-gradient solves of one step."""

    iterations: int = 0
    convolutions: float = 0.0
    resets: int = 0
    history: list = field(default_factory=list)

    def add(self, out) -> None:
        self.iterations += out.iterations
        self.convolutions += out.convolutions
        self.resets += out.resets
        self.history.extend(out.history)


def _increment(gap, increment: Increment, periodic: bool):
    if increment == "local":
        return local_increment(gap)
    return volume_conserving_increment(gap, periodic)


def _penetration_at_bound(pressure, gap, p_max):
    """The negative gap (m) where the pressure is at its bound ``p_max`` (Pa), 0 elsewhere.

    Only points at the bound yield (appendix: "where p = p_Y the material deforms
    plastically"); a free point's gap is the elastic solver's residual, not flow. BoundedWall
    clips to the bound exactly, so ``>=`` is ``==`` there."""
    return np.where((pressure >= p_max) & (gap < 0.0), gap, 0.0)


def _plastic_iteration(
    operator,
    heights,
    pixel_area,
    h_scale,
    bound,
    plastic_prev,
    displacement,
    *,
    increment,
    alpha,
    periodic,
    p_init,
    tol,
    max_iter,
    max_outer,
):
    """Appendix scheme at a fixed approach: bounded CG on h + h_pl, then h_pl += α·Δh_pl,
    until no yielding point penetrates by more than tol·h_scale. ``bound(h_pl)`` gives
    p_max per pixel (Pa)."""
    h_pl = plastic_prev.copy()
    p = p_init
    tally = _Tally()
    for outer in range(1, max_outer + 1):
        p_max = bound(h_pl)
        out = polonsky_keer(
            operator,
            heights + h_pl,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p,
            displacement=displacement,
            tol=tol,
            max_iter=max_iter,
            constraint=BoundedWall(p_max),
            raise_on_failure=False,
        )
        p = out.pressure
        tally.add(out)
        state = _appendix_state(out, h_pl, displacement, tally, outer)
        if not out.converged:
            return state
        yielding = _penetration_at_bound(p, out.gap, p_max)
        worst = float(-yielding.min())
        if worst <= tol * h_scale:
            residual = max(out.residual, worst / h_scale)
            return replace(
                state,
                residual=residual,
                message=f"appendix scheme converged in {outer} round(s) of bounded solve and "
                f"plastic update, {tally.iterations} CG iterations: residual {residual:.3e} < "
                f"tol {tol:.1e}",
            )
        h_pl = h_pl + alpha * _increment(yielding, increment, periodic)
    return replace(
        state,
        residual=worst / h_scale,
        status=ITERATION_CAP,
        message=f"plastic iteration did not make the gap non-negative in {max_outer} updates: "
        f"worst penetration {worst:.3e} m > {tol * h_scale:.3e} m (alpha={alpha}, "
        f"{increment} increments, {tally.iterations} CG iterations, residual "
        f"{worst / h_scale:.3e}); lower alpha or raise max_outer",
    )


def _appendix_state(out, h_pl, displacement, tally, outer):
    """The state of the appendix scheme after a bounded solve ``out`` on h + ``h_pl``,
    with the status and message of that solve."""
    return Outcome(
        pressure=out.pressure,
        gap=out.gap,
        elastic_displacement=out.elastic_displacement,
        plastic_displacement=h_pl,
        displacement=displacement,
        iterations=tally.iterations,
        residual=out.residual,
        history=np.asarray(tally.history),
        convolutions=tally.convolutions,
        outer_iterations=outer,
        resets=tally.resets,
        status=out.status,
        message=out.message,
    )


class _SolvedTrials:
    """Pressures (Pa) of converged trial approaches (m) of a root find, the ``KEEP`` most
    recent, to warm-start each new trial from the nearest one in approach."""

    KEEP = 4  # the bracket's ends and their last refinements; each is one grid of floats

    def __init__(self):
        self.trials = []

    def add(self, d: float, pressure: np.ndarray) -> None:
        self.trials = [*self.trials[-(self.KEEP - 1) :], (d, pressure)]

    def nearest(self, d: float, default: np.ndarray) -> np.ndarray:
        if not self.trials:
            return default
        return min(self.trials, key=lambda trial: abs(trial[0] - d))[1]


class _Found(Exception):
    def __init__(self, state):
        self.state = state


class _Failed(Exception):
    """A trial approach's solve stopped without converging (carries its state)."""

    def __init__(self, state):
        self.state = state


# Doubling steps allowed while bracketing the approach: 60 doublings of the first step span
# 18 orders of magnitude, far beyond any contact.
MAX_BRACKET_STEPS = 60


def _find_approach(evaluate, load, d_guess, d_step, load_tol, load_atol=0.0):
    """The state at the root of load(d) = ``load``, for a continuous non-decreasing load(d).

    ``evaluate(d)`` returns (load, state). Brackets by doubling steps from ``d_guess``, then
    Brent's method (scipy), stopping early once the load is within ``load_tol`` (relative).
    Where load(d) is nearly a staircase (a fully plastic contact: one more pixel, p_Y·Δx² more
    load), the closest state found is returned if its load is within ``load_atol`` (N, one
    pixel's worth). Otherwise, or when no bracket or root is found, or a trial approach does
    not converge, the closest state found (else the failed trial) is returned with status 1
    (a trial or Brent's method hit its iteration cap) or 2 (stalled) and a message.
    """
    best = {"err": np.inf, "state": None, "latest": None}

    def residual(d):
        f, state = evaluate(d)
        best["latest"] = state
        if not state.converged:
            raise _Failed(state)
        err = abs(f - load)
        if err < best["err"]:
            best.update(err=err, state=state)
        if err <= load_tol * load:
            raise _Found(state)
        return f - load

    def failed(why, status=STALLED, fallback=None):
        state = next(s for s in (best["state"], fallback, best["latest"]) if s is not None)
        return replace(
            state,
            status=status,
            message=f"load control of the plastic solve failed: {why}; closest load is "
            f"{best['err']:.3e} N from {load:.3e} N",
        )

    try:
        d_lo = d_hi = d_guess
        f0 = residual(d_guess)
        step = d_step
        for _ in range(MAX_BRACKET_STEPS):
            if f0 < 0:
                d_lo, d_hi = d_hi, d_hi + step
                if residual(d_hi) >= 0:
                    break
            else:
                d_hi, d_lo = d_lo, d_lo - step
                if residual(d_lo) < 0:
                    break
            step *= 2
        else:
            return failed(f"no approach brackets the load after {MAX_BRACKET_STEPS} doublings")
        optimize.brentq(residual, d_lo, d_hi, xtol=1e-13 * d_step, rtol=1e-15, maxiter=200)
    except _Found as found:
        return found.state
    except _Failed as trial:
        return failed(trial.state.message, trial.state.status, trial.state)
    except (ValueError, RuntimeError) as error:  # brentq: no sign change / no convergence
        return failed(str(error), ITERATION_CAP if isinstance(error, RuntimeError) else STALLED)
    if best["err"] > max(load_tol * load, load_atol):
        return failed("the load is not a continuous function of the approach here")
    return best["state"]


class _WinklerOperator:
    """K·x + x/k on the flowing set: the elastic half-space plus a Winkler layer."""

    def __init__(self, operator, compliance: np.ndarray):
        self.operator = operator
        self.compliance = compliance

    def __call__(self, x, out):
        self.operator(x, out=out)
        out += self.compliance * x
        return out


def _hardening_winkler(
    operator,
    heights,
    pixel_area,
    h_scale,
    k,
    plastic_prev,
    *,
    load,
    displacement,
    p_init,
    tol,
    max_iter,
    max_rounds=MAX_ACTIVE_SET_ROUNDS,
):
    """Contact hardening with local increments, exact for any load history (module doc)."""
    floor = np.maximum(-plastic_prev, 0.0)  # plastic depth already reached, m
    flowing = np.ones(heights.shape, dtype=bool)
    p = p_init
    tally = _Tally()
    for rounds in range(1, max_rounds + 1):
        compliance = np.where(flowing, 1.0 / k, 0.0)
        effective = np.where(flowing, heights, heights - floor)
        out = polonsky_keer(
            _WinklerOperator(operator, compliance),
            effective,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p,
            load=load,
            displacement=displacement,
            tol=tol,
            max_iter=max_iter,
            raise_on_failure=False,
        )
        p = out.pressure
        tally.add(out)
        state = _winkler_state(out, heights, k, floor, flowing, compliance, tally, rounds)
        if not out.converged:
            return state
        now_flowing = (p > k * floor) | (floor == 0)
        if np.array_equal(now_flowing, flowing):
            return replace(
                state,
                message=f"elastic-plus-Winkler solve converged in {rounds} active-set "
                f"round(s), {tally.iterations} CG iterations: residual {out.residual:.3e} < "
                f"tol {tol:.1e}",
            )
        switching = int(np.count_nonzero(now_flowing != flowing))
        flowing = now_flowing
    return replace(
        state,
        status=ITERATION_CAP,
        message=f"hardening active set did not settle in {max_rounds} rounds ({switching} "
        f"pixels still switching; {tally.iterations} CG iterations, residual "
        f"{out.residual:.3e})",
    )


def _winkler_state(out, heights, k, floor, flowing, compliance, tally, rounds):
    """The hardening state of a Winkler solve ``out`` with the active set ``flowing``
    (status and message of that solve)."""
    p = out.pressure
    depth = np.where(flowing & (p > 0), np.maximum(p / k, floor), floor)
    plastic = -depth
    elastic = out.elastic_displacement - compliance * p
    gap = elastic - (heights + plastic) - out.displacement
    return Outcome(
        pressure=p,
        gap=gap,
        elastic_displacement=elastic,
        plastic_displacement=plastic,
        displacement=out.displacement,
        iterations=tally.iterations,
        residual=out.residual,
        history=np.asarray(tally.history),
        convolutions=tally.convolutions,
        outer_iterations=rounds,
        resets=tally.resets,
        status=out.status,
        message=out.message,
    )


def solve_plastic(
    operator,
    heights,
    spacing,
    law,
    *,
    load=None,
    displacement=None,
    plastic_prev,
    p_init,
    periodic,
    tol,
    max_iter,
    max_outer=None,
    route="winkler",
    bounded_load_sweep=True,
):
    """One load step of a plasticity law, starting from the plastic state ``plastic_prev``.

    ``route`` comes from :func:`resolve_route`: ``"winkler"`` (contact hardening with local
    increments, exact), ``"bounded"`` (penetration hardness with local increments, one
    bounded CG, exact) or ``"appendix"`` (the appendix's iterative scheme). ``max_outer``
    caps the active-set rounds or the plastic updates per approach (None:
    :func:`default_max_outer`; unused by ``"bounded"``); ``bounded_load_sweep`` picks the
    kernel set of the ``"bounded"`` route's load control (:func:`.cg.polonsky_keer`).
    Returns a :class:`~.result.Outcome`, converged or not.
    """
    pixel_area = spacing**2
    h_scale = float(np.std(heights)) or spacing
    max_outer = default_max_outer(route) if max_outer is None else max_outer
    if isinstance(law, ContactHardening):
        winkler = partial(
            _hardening_winkler,
            operator,
            heights,
            pixel_area,
            h_scale,
            law.k,
            plastic_prev,
            p_init=p_init,
            tol=tol,
            max_iter=max_iter,
        )
        if route == "winkler":
            if (plastic_prev > 0).any():
                # pile-up only comes from volume-conserving increments, which the Winkler
                # route does not model
                raise ContactInputError(
                    "plastic_displacement has pile-up (h_pl > 0, max "
                    f"{plastic_prev.max():.3e} m), which the exact Winkler route of local "
                    "increments cannot carry; use increment='volume' for pile-up"
                )
            return winkler(load=load, displacement=displacement, max_rounds=max_outer)
    if isinstance(law, PenetrationHardness):
        p_y = np.broadcast_to(np.asarray(law.p_y, dtype=float), heights.shape)
        capacity = float(p_y.sum()) * pixel_area
        if load is not None and load >= capacity:
            message = (
                f"load {load:.3e} N needs more than the whole window at the hardness "
                f"(Σ p_Y·Δx² = {capacity:.3e} N); lower the load or enlarge the window"
            )
            if periodic:
                # the whole periodic surface at p_Y carries less: no state carries the load
                raise ContactInputError(message)
            # on a half-space the contact would grow past the window: the window is too small,
            # as when a solution's pressure reaches the edge (every pixel would be at p_Y)
            ring = np.ones(heights.shape, dtype=bool)
            ring[1:-1, 1:-1] = False
            raise FreeBoundaryError(
                message,
                edge_pixels=int(ring.sum()),
                edge_force=float(p_y[ring].sum()) * pixel_area,  # the ring at p_Y
            )
        if route == "bounded":
            return _hardness_bounded(
                operator,
                heights,
                pixel_area,
                h_scale,
                p_y,
                plastic_prev,
                load=load,
                displacement=displacement,
                p_init=p_init,
                tol=tol,
                max_iter=max_iter,
                bounded_load_sweep=bounded_load_sweep,
            )

        def bound(h_pl):
            return p_y
    else:

        def bound(h_pl):
            # pile-up (h_pl > 0) has not yielded in compression: no hardness there
            return law.k * np.maximum(-h_pl, 0.0)

    def at(d, p_start):
        return _plastic_iteration(
            operator,
            heights,
            pixel_area,
            h_scale,
            bound,
            plastic_prev,
            d,
            increment=law.increment,
            alpha=law.alpha,
            periodic=periodic,
            p_init=p_start,
            tol=tol,
            max_iter=max_iter,
            max_outer=max_outer,
        )

    if displacement is not None:
        return at(float(displacement), p_init)
    last = {"p": p_init}
    solved = _SolvedTrials()

    def evaluate(d):
        # start from the converged trial nearest in approach (the pressure is continuous in
        # d), else from the last one tried
        state = at(d, solved.nearest(d, last["p"]))
        last["p"] = state.pressure
        if state.converged:
            solved.add(d, state.pressure)
        return float(state.pressure.sum()) * pixel_area, state

    span = float(np.ptp(heights)) or spacing
    if isinstance(law, ContactHardening):
        # the Winkler state is exact for local increments and close for volume-conserving ones
        guess = winkler(load=load, displacement=None)
        if not guess.converged:
            return replace(guess, message=f"starting approach (Winkler solve): {guess.message}")
        d_guess = guess.displacement
    else:
        elastic = polonsky_keer(
            operator,
            heights + plastic_prev,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p_init,
            load=load,
            tol=tol,
            max_iter=max_iter,
            raise_on_failure=False,
        )
        if not elastic.converged or np.all(elastic.pressure <= bound(plastic_prev)):
            # the bound is never reached: the elastic solution is the answer
            return _elastic_state(elastic, plastic_prev)
        last["p"] = np.minimum(elastic.pressure, bound(plastic_prev))
        # plasticity softens the contact, so the approach is at least the elastic one; when
        # fully plastic it is about the rigid overlap that carries the load at the hardness
        p_mean = float(np.mean(bound(plastic_prev)))
        target_pixels = min(heights.size, max(1, int(load / (pixel_area * p_mean))))
        d_bearing = -float(np.sort((heights + plastic_prev).ravel())[::-1][target_pixels - 1])
        d_guess = max(elastic.displacement, d_bearing)
    # a fully plastic contact's load is a near-staircase in d: one pixel's worth is allowed
    pixel_worth = float(np.max(bound(plastic_prev))) * pixel_area
    return _find_approach(evaluate, load, d_guess, 1e-3 * span, load_tol=tol, load_atol=pixel_worth)


def _hardness_bounded(
    operator,
    heights,
    pixel_area,
    h_scale,
    p_y,
    plastic_prev,
    *,
    load,
    displacement,
    p_init,
    tol,
    max_iter,
    bounded_load_sweep=True,
):
    """Penetration hardness with local increments (eq. B.2) in one bounded CG.

    The appendix scheme at a fixed approach ends where every point at ``p = p_Y`` has had
    its penetration removed: with local increments that is one bounded solve on
    ``h + h_pl,prev`` and one update, since lowering a point at the bound to zero gap leaves
    the bounded solution unchanged (p = p_Y with g = 0 is admissible). So the bounded solve
    (0 <= p <= p_Y, Pa) is run under the load itself, with the approach as the Lagrange
    multiplier of the force (bounded_load.impose_bounded_load), instead of a root find on the
    approach; then ``h_pl = h_pl,prev + g·θ(−g)`` where ``p = p_Y`` (m) and the gap there
    closes to ``max(g, 0)``. The plastic history enters only through the heights. Units:
    heights, gaps, ``h_pl`` in m; ``p_y`` (per pixel) in Pa.
    """
    out = polonsky_keer(
        operator,
        heights + plastic_prev,
        pixel_area=pixel_area,
        h_scale=h_scale,
        p_init=p_init,
        load=load,
        displacement=displacement,
        tol=tol,
        max_iter=max_iter,
        constraint=BoundedWall(p_y),
        raise_on_failure=False,
        bounded_load_sweep=bounded_load_sweep,
    )
    flow = _penetration_at_bound(out.pressure, out.gap, p_y)
    plastic = plastic_prev + local_increment(flow)
    message = out.message
    if out.converged:
        message = (
            f"bounded solve under the force constraint: {message}; "
            f"{int(np.count_nonzero(flow))} pixel(s) flowed"
        )
    return Outcome(
        pressure=out.pressure,
        gap=out.gap - flow,
        elastic_displacement=out.elastic_displacement,
        plastic_displacement=plastic,
        displacement=out.displacement,
        iterations=out.iterations,
        residual=out.residual,
        history=out.history,
        convolutions=out.convolutions,
        outer_iterations=1,
        resets=out.resets,
        status=out.status,
        message=message,
    )


def _elastic_state(out, plastic_prev):
    """A PK outcome that never reached the bound, as the state of a plastic step (or the
    failed elastic starting solve, with its status)."""
    message = out.message
    if out.converged:
        message = f"the hardness is never reached, the elastic solution holds: {message}"
    return Outcome(
        pressure=out.pressure,
        gap=out.gap,
        elastic_displacement=out.elastic_displacement,
        plastic_displacement=plastic_prev.copy(),
        displacement=out.displacement,
        iterations=out.iterations,
        residual=out.residual,
        history=out.history,
        convolutions=out.convolutions,
        outer_iterations=0,
        resets=out.resets,
        status=out.status,
        message=message,
    )
