"""The route table: which algorithm solves a step, chosen once from ``SolveOptions.route``.

=============  ==============================================================  ============
route          solves                                                          module
=============  ==============================================================  ============
``elastic``    no plasticity law: one Polonsky–Keer solve (coarse-to-fine)     :mod:`.elastic`
``winkler``    contact hardening, local increments: elastic + Winkler layer    :mod:`.winkler`
``bounded``    penetration hardness, local increments: one bounded CG          :mod:`.bounded`
``appendix``   either law, either increment: the appendix's scheme, root find  :mod:`.appendix`
=============  ==============================================================  ============

:func:`.options.resolve_route` picks the route from the law and ``method=``. Every route
takes ``(heights, spacing, e_star, opts, step)`` (m, m, Pa, :class:`~.options.SolveOptions`,
:class:`~.options.LoadStep`) and returns an :class:`~.result.Outcome`, converged or not; it
raises only for input it cannot solve (:class:`~.errors.ContactInputError`,
:class:`~.errors.FreeBoundaryError`).
"""

from __future__ import annotations

import numpy as np

from . import appendix, bounded, elastic, winkler
from .convolution import operator_for
from .elastic import start_pressure
from .errors import ContactInputError, FreeBoundaryError


def _plastic(route):
    """A plastic route (``route(operator, heights, spacing, law, opts, *, load,
    displacement, plastic_prev, p_init)``) under the table's signature: the load checked
    against the window's capacity, the operator taken from the cache and the starting
    pressure (Pa) made where the step has none."""

    def run(h, spacing, e_star, opts, step):
        check_capacity(opts.law, h, spacing**2, step.load, opts.periodic)
        op = operator_for(opts, h.shape, spacing, e_star)
        p_init = step.warm_start
        if p_init is None:
            p_init = start_pressure(
                h + step.plastic_prev, spacing, e_star, step.load, step.displacement
            )
        return route(
            op,
            h,
            spacing,
            opts.law,
            opts,
            load=step.load,
            displacement=step.displacement,
            plastic_prev=step.plastic_prev,
            p_init=p_init,
        )

    run.__doc__ = route.__doc__
    return run


ROUTES = {
    "elastic": elastic.solve,
    "winkler": _plastic(winkler.solve),
    "bounded": _plastic(bounded.solve),
    "appendix": _plastic(appendix.solve),
}


def run_route(h, spacing, e_star, opts, step):
    """Solve ``step`` by the route of ``opts`` (:data:`ROUTES`): an Outcome."""
    return ROUTES[opts.route](h, spacing, e_star, opts, step)


def check_capacity(law, heights, pixel_area, load, periodic) -> None:
    """Penetration hardness under load control: refuse a load (N) that the whole window at
    p_Y (Pa) could not carry (pixel area m²) - ContactInputError on a periodic grid (no
    state carries it), FreeBoundaryError on a half-space (the window is too small)."""
    p_y = None if (law is None or load is None) else law.capacity(heights.shape)
    if p_y is None:
        return
    capacity = float(p_y.sum()) * pixel_area
    if load < capacity:
        return
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
