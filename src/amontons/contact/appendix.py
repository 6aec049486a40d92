"""Route ``"appendix"``: the appendix's iterative scheme (bounded CG, gap, plastic
increment, repeat) at a fixed approach, and under load control a root find on the approach
(:mod:`.root_find`), each trial starting from the previous step's plastic state.

Taken by volume-conserving increments (eq. B.3, where pile-up moves the heights of points
that did not yield; :mod:`.plastic_increments`) and on request (``method="appendix"``, the
test oracle of both exact routes). For contact hardening the bound is p_Y = k·|h_pl| and
the starting approach is the Winkler state's (:mod:`.winkler`). SI units: heights, gaps,
plastic displacement in m; pressures and p_Y in Pa; k in Pa/m.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .cg import polonsky_keer
from .constraints import BoundedWall
from .errors import ITERATION_CAP
from .plastic_increments import increment as plastic_increment
from .plastic_increments import penetration_at_bound
from .result import Outcome, Tally
from .root_find import SolvedTrials, find_approach
from .winkler import hardening_winkler


def solve(operator, heights, spacing, law, opts, *, load, displacement, plastic_prev, p_init):
    """One load step of ``law`` by the appendix's scheme from the plastic state
    ``plastic_prev`` (m), starting from ``p_init`` (Pa): at ``displacement`` (m), or at the
    approach that carries ``load`` (N). An :class:`~.result.Outcome`, converged or not."""
    pixel_area = spacing**2
    h_scale = float(np.std(heights)) or spacing
    cg_options, max_outer, periodic = opts.cg, opts.max_outer, opts.periodic
    bound = law.pressure_bound(heights.shape)

    def at(d, p_start):
        return plastic_iteration(
            operator,
            heights,
            pixel_area,
            h_scale,
            bound,
            plastic_prev,
            d,
            cg_options,
            increment=law.increment,
            alpha=law.alpha,
            periodic=periodic,
            p_init=p_start,
            max_outer=max_outer,
        )

    if displacement is not None:
        return at(float(displacement), p_init)
    last = {"p": p_init}
    solved = SolvedTrials()

    def evaluate(d):
        # start from the converged trial nearest in approach (the pressure is continuous in
        # d), else from the last one tried
        state = at(d, solved.nearest(d, last["p"]))
        last["p"] = state.pressure
        if state.converged:
            solved.add(d, state.pressure)
        return float(state.pressure.sum()) * pixel_area, state

    span = float(np.ptp(heights)) or spacing
    if law.appendix_start == "winkler":
        # the Winkler state is exact for local increments and close for volume-conserving ones
        guess = hardening_winkler(
            operator,
            heights,
            pixel_area,
            h_scale,
            law.k,
            plastic_prev,
            cg_options,
            load=load,
            displacement=None,
            p_init=p_init,
        )
        if not guess.converged:
            return replace(guess, message=f"starting approach (Winkler solve): {guess.message}")
        d_guess = guess.displacement
    else:
        elastic = polonsky_keer(
            operator,
            heights + plastic_prev,
            cg_options,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p_init,
            load=load,
        )
        if not elastic.converged or np.all(elastic.pressure <= bound(plastic_prev)):
            # the bound is never reached: the elastic solution is the answer
            return elastic_state(elastic, plastic_prev)
        last["p"] = np.minimum(elastic.pressure, bound(plastic_prev))
        # plasticity softens the contact, so the approach is at least the elastic one; when
        # fully plastic it is about the rigid overlap that carries the load at the hardness
        p_mean = float(np.mean(bound(plastic_prev)))
        target_pixels = min(heights.size, max(1, int(load / (pixel_area * p_mean))))
        d_bearing = -float(np.sort((heights + plastic_prev).ravel())[::-1][target_pixels - 1])
        d_guess = max(elastic.displacement, d_bearing)
    # a fully plastic contact's load is a near-staircase in d: one pixel's worth is allowed
    pixel_worth = float(np.max(bound(plastic_prev))) * pixel_area
    return find_approach(
        evaluate, load, d_guess, 1e-3 * span, load_tol=opts.tol, load_atol=pixel_worth
    )


def plastic_iteration(
    operator,
    heights,
    pixel_area,
    h_scale,
    bound,
    plastic_prev,
    displacement,
    cg_options,
    *,
    increment,
    alpha,
    periodic,
    p_init,
    max_outer,
):
    """Appendix scheme at a fixed approach: bounded CG on h + h_pl (run with ``cg_options``,
    :class:`~.options.CGOptions`), then h_pl += α·Δh_pl, until no yielding point penetrates
    by more than tol·h_scale. ``bound(h_pl)`` gives p_max per pixel (Pa)."""
    tol = cg_options.tol
    h_pl = plastic_prev.copy()
    p = p_init
    tally = Tally()
    for outer in range(1, max_outer + 1):
        p_max = bound(h_pl)
        out = polonsky_keer(
            operator,
            heights + h_pl,
            cg_options,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p,
            displacement=displacement,
            constraint=BoundedWall(p_max),
        )
        p = out.pressure
        tally.add(out)
        state = _appendix_state(out, h_pl, displacement, tally, outer)
        if not out.converged:
            return state
        yielding = penetration_at_bound(p, out.gap, p_max)
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
        h_pl = h_pl + alpha * plastic_increment(yielding, increment, periodic)
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


def elastic_state(out, plastic_prev):
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
