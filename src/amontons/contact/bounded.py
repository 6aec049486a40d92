"""Route ``"bounded"``: penetration hardness with local increments in one bounded CG.

The appendix scheme at a fixed approach stops once every point at p = p_Y has had its
penetration removed, which leaves the bounded solution unchanged, so the state is one
bounded CG (0 <= p <= p_Y) on h + h_pl,prev under the load itself (the approach is the
Lagrange multiplier of the force) followed by one update h_pl += g·θ(−g) where p = p_Y
(docs/models.md §2.3). SI units: m, Pa.
"""

from __future__ import annotations

import numpy as np

from .conjugate_gradient import conjugate_gradient
from .constraints import BoundedWall
from .plastic_increments import local_increment, penetration_at_bound
from .result import Outcome


def solve(operator, heights, spacing, law, opts, *, load, displacement, plastic_prev, p_init):
    """One load step of ``law`` (PenetrationHardness, local increments) from the plastic
    state ``plastic_prev`` (m), starting from ``p_init`` (Pa); an :class:`~.result.Outcome`,
    converged or not. ``opts.bounded_load_sweep`` picks the kernel set of load control
    (through :attr:`~.options.SolveOptions.cg`)."""
    return hardness_bounded(
        operator,
        heights,
        spacing**2,
        float(np.std(heights)) or spacing,
        np.broadcast_to(np.asarray(law.p_y, dtype=float), heights.shape),
        plastic_prev,
        opts.cg,
        load=load,
        displacement=displacement,
        p_init=p_init,
    )


def hardness_bounded(
    operator,
    heights,
    pixel_area,
    h_scale,
    p_y,
    plastic_prev,
    cg_options,
    *,
    load,
    displacement,
    p_init,
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
    heights, gaps, ``h_pl`` in m; ``p_y`` (per pixel) in Pa. The CG runs with
    ``cg_options`` (:class:`~.options.CGOptions`).
    """
    out = conjugate_gradient(
        operator,
        heights + plastic_prev,
        cg_options,
        pixel_area=pixel_area,
        h_scale=h_scale,
        p_init=p_init,
        load=load,
        displacement=displacement,
        constraint=BoundedWall(p_y),
    )
    flow = penetration_at_bound(out.pressure, out.gap, p_y)
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
