"""Every process runs the fused kernels' machine code from numba's disk cache: the warm-up.

The top of the package: it compiles the kernels by solving (:func:`warm_up`, tiny solves
through every route of the solver, :func:`warm_up_cases`), so it stands above the public
calls it uses. :func:`.jit.ensure_cached` runs :func:`main` in a child process when a
process first needs the kernels on a cold cache (why: :mod:`.jit`); ``make reproduce`` runs
it before the first job:

    python -c "from amontons.contact.kernel_cache import main; main()"   # if cold
"""

from __future__ import annotations

import os

from . import jit, kernels
from .api import solve
from .laws import ContactHardening, PenetrationHardness
from .surfaces import sphere

is_cold = jit.is_cold
COMMAND = jit.COMMAND


def warm_up() -> None:
    """Compile every kernel with the argument types the solver gives it: the tiny solves
    of :func:`warm_up_cases`."""
    for case in warm_up_cases():
        solve(**case, max_iter=200, raise_on_failure=False)


def warm_up_cases():
    """Keyword arguments of :func:`amontons.contact.solve` for every route of the solver:
    a sphere on 32², periodic and not, under load and displacement control, elastic, with
    penetration hardness (bounded CG), contact hardening (Winkler) and the appendix's
    iteration (volume increments). The contact is ~8 pixels in radius with a Hertz peak of
    0.05 E*, plastic under both laws."""
    spacing, e_star, radius = 1e-7, 1e9, 1e-5
    h = sphere((32, 32), spacing, radius)
    load = 7e-3 * e_star * spacing**2 * h.size
    laws = [
        None,
        PenetrationHardness(0.02 * e_star),
        ContactHardening(0.2 * e_star / spacing),
        PenetrationHardness(0.02 * e_star, increment="volume", alpha=0.5),
    ]
    for periodic in (False, True):
        for law in laws:
            for control in ({"load": load}, {"displacement": 0.6 * spacing}):
                yield {
                    "heights": h.copy(),
                    "spacing": spacing,
                    "e_star": e_star,
                    "periodic": periodic,
                    "plasticity": law,
                    **control,
                }


def main() -> None:
    """Compile the kernels into the cache if it is cold (``make reproduce``, ``make test``,
    and the child of :func:`.jit.ensure_cached`, whose parent holds the lock)."""
    if os.environ.get(jit.CHILD_ENV):
        _compile_here()
        return
    with jit.warm_up_lock(kernels.ENTRY_POINTS):
        if is_cold(kernels.ENTRY_POINTS):
            _compile_here()


def _compile_here() -> None:
    """The warm-up in this process, which must not start another child."""
    jit.mark_checked(kernels.ENTRY_POINTS)
    jit.mark_checked(kernels.SPECTRUM_ENTRY_POINTS)
    warm_up()
