"""Route ``"winkler"``: contact hardening with local increments, exact for any load history.

Under monotonic loading every contact point of the hardening law sits on its yield surface,
p = k·|h_pl|, so the converged state is an elastic half-space plus a Winkler layer of
stiffness k: (K + I/k) p = h + d on the contact set, one Polonsky–Keer solve with the
operator :class:`WinklerOperator`. The plastic displacement of earlier steps is a floor, so
each point either flows (Winkler, on the undeformed heights) or stays elastic on its earlier
deformation; an active-set loop picks which (the convex problem with dissipation potential
φ'(p) = max(|h_pl,prev|, p/k); docs/models.md §2.4). SI units: m, Pa, k in Pa/m.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .conjugate_gradient import conjugate_gradient
from .errors import ITERATION_CAP, ContactInputError
from .options import MAX_ACTIVE_SET_ROUNDS
from .result import Outcome, Tally


def solve(operator, heights, spacing, law, opts, *, load, displacement, plastic_prev, p_init):
    """One load step of ``law`` (ContactHardening, local increments) from the plastic state
    ``plastic_prev`` (m), starting from ``p_init`` (Pa); an :class:`~.result.Outcome`,
    converged or not. Raises ContactInputError when ``plastic_prev`` has pile-up."""
    if (plastic_prev > 0).any():
        # pile-up only comes from volume-conserving increments, which the Winkler
        # route does not model
        raise ContactInputError(
            "plastic_displacement has pile-up (h_pl > 0, max "
            f"{plastic_prev.max():.3e} m), which the exact Winkler route of local "
            "increments cannot carry; use increment='volume' for pile-up"
        )
    return hardening_winkler(
        operator,
        heights,
        spacing**2,
        float(np.std(heights)) or spacing,
        law.k,
        plastic_prev,
        opts.cg,
        load=load,
        displacement=displacement,
        p_init=p_init,
        max_rounds=opts.max_outer,
    )


class WinklerOperator:
    """K·x + x/k on the flowing set: the elastic half-space plus a Winkler layer."""

    def __init__(self, operator, compliance: np.ndarray):
        self.operator = operator
        self.compliance = compliance

    def __call__(self, x, out):
        self.operator(x, out=out)
        out += self.compliance * x
        return out


def hardening_winkler(
    operator,
    heights,
    pixel_area,
    h_scale,
    k,
    plastic_prev,
    cg_options,
    *,
    load,
    displacement,
    p_init,
    max_rounds=MAX_ACTIVE_SET_ROUNDS,
):
    """Contact hardening with local increments, exact for any load history (module doc);
    each active-set round one CG run with ``cg_options`` (:class:`~.options.CGOptions`)."""
    floor = np.maximum(-plastic_prev, 0.0)  # plastic depth already reached, m
    flowing = np.ones(heights.shape, dtype=bool)
    p = p_init
    tally = Tally()
    for rounds in range(1, max_rounds + 1):
        compliance = np.where(flowing, 1.0 / k, 0.0)
        effective = np.where(flowing, heights, heights - floor)
        out = conjugate_gradient(
            WinklerOperator(operator, compliance),
            effective,
            cg_options,
            pixel_area=pixel_area,
            h_scale=h_scale,
            p_init=p,
            load=load,
            displacement=displacement,
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
                f"tol {cg_options.tol:.1e}",
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
