"""Route ``"elastic"``: one Polonsky–Keer solve of the hard-wall problem, optionally from a
coarse-to-fine start, and the starting pressures every route uses without a warm start.

Coarse-to-fine: the heights are block-averaged 2x2 (spacing doubles) down to
``COARSE_MIN_SIZE`` pixels, each level solved loosely (``COARSE_TOL``) from the one below,
its pressure prolonged by pixel replication (which keeps the total force). SI units: m, Pa,
N.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .conjugate_gradient import conjugate_gradient
from .convolution import operator_for
from .errors import STALLED
from .options import default_max_iter
from .result import CoarseLevel

# Coarse levels stop at this many pixels along the shorter side: below it a solve costs
# nothing and the coarse surface no longer resembles the fine one.
COARSE_MIN_SIZE = 32
# Coarse levels only provide a starting guess, so they are solved loosely.
COARSE_TOL = 1e-4


def solve(h, spacing, e_star, opts, step):
    """The elastic solve of ``step`` (:class:`~.options.LoadStep`) on heights ``h`` (m):
    an :class:`~.result.Outcome` (no plastic displacement yet), converged or not."""
    levels = ()
    p_init = step.warm_start
    if p_init is None and step.coarse_to_fine:
        p_init, levels = coarse_start(h, spacing, e_star, step.load, step.displacement, opts)
    if p_init is None:
        p_init = start_pressure(h, spacing, e_star, step.load, step.displacement)
    out = run_cg(
        h,
        spacing,
        e_star,
        opts,
        opts.cg,
        load=step.load,
        displacement=step.displacement,
        p_init=p_init,
    )
    out.plastic_displacement = np.zeros_like(out.pressure)
    out.coarse_levels = tuple(levels)
    return out


def run_cg(h, spacing, e_star, opts, cg_options, *, load, displacement, p_init):
    """One Polonsky–Keer solve of the hard-wall problem on the operator of ``opts``
    (:class:`~.options.SolveOptions`), run with ``cg_options``
    (:class:`~.options.CGOptions`; a route's never raise): its outcome."""
    h_scale = float(np.std(h))
    if not np.ptp(h) > 0:
        # a flat indenter: any length works, the gap is round-off. (np.std of a constant
        # array is round-off too, ~1e-16 of the height, not 0: that scale would turn the
        # round-off gap into a residual of order 1.)
        h_scale = spacing
    return conjugate_gradient(
        operator_for(opts, h.shape, spacing, e_star),
        h,
        cg_options,
        pixel_area=spacing**2,
        h_scale=h_scale,
        p_init=p_init,
        load=load,
        displacement=displacement,
    )


def finite(outcome) -> bool:
    return bool(np.isfinite(outcome.pressure).all() and np.isfinite(outcome.gap).all())


def start_pressure(h, spacing, e_star, load, displacement):
    """Starting pressure (Pa) without a warm start: uniform under load control (the solver
    rescales it to the load), the overlap guess under displacement control."""
    if load is not None:
        return np.ones_like(h)
    return initial_pressure(h, spacing, e_star, displacement)


def initial_pressure(h, spacing, e_star, displacement):
    """Starting pressure (Pa) for displacement control: a local-stiffness overlap guess."""
    overlap = np.maximum(h + displacement, 0.0)
    n = np.count_nonzero(overlap)
    if n == 0:
        return np.zeros_like(h)
    # a patch of size L has stiffness ~E*/L, so p ~ E* overlap / L
    return overlap * (e_star / (math.sqrt(n) * spacing))


def has_coarse_level(shape) -> bool:
    """Whether a grid can be coarsened 2x2 at least once (even sides, >= 2 COARSE_MIN_SIZE)."""
    n0, n1 = shape
    return not (n0 % 2 or n1 % 2 or min(n0, n1) < 2 * COARSE_MIN_SIZE)


def coarsen(h):
    n0, n1 = h.shape
    return h.reshape(n0 // 2, 2, n1 // 2, 2).mean(axis=(1, 3))


def coarse_start(h, spacing, e_star, load, displacement, opts, levels=()):
    """Pressure (Pa) on the grid of ``h`` from a solve on a 2x coarser grid, or None, and
    the coarse levels solved (coarsest first).

    Heights are block-averaged 2x2 (spacing doubles); the coarse pressure is prolonged by
    pixel replication, which keeps the total force. Recurses down to ``COARSE_MIN_SIZE``.
    A level that stalls or has no usable pressure gives no start.
    """
    if not has_coarse_level(h.shape):
        return None, levels
    hc = coarsen(h)
    start, levels = coarse_start(hc, 2 * spacing, e_star, load, displacement, opts, levels)
    if start is None:
        start = start_pressure(hc, 2 * spacing, e_star, load, displacement)
    # coarse levels are solved loosely, to their own grid's iteration cap
    coarse = replace(opts.cg, tol=COARSE_TOL, max_iter=default_max_iter(hc.shape))
    out = run_cg(
        hc, 2 * spacing, e_star, opts, coarse, load=load, displacement=displacement, p_init=start
    )
    if out.status == STALLED or not finite(out) or not out.pressure.any():
        return None, levels
    levels = (*levels, CoarseLevel(hc.shape, out.iterations, out.convolutions))
    return prolong(out.pressure), levels


def prolong(p):
    """Pixel replication 2x2: keeps the total force and the support of the pressure."""
    return np.repeat(np.repeat(p, 2, axis=0), 2, axis=1)
