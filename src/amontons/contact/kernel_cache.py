"""Every process runs the fused kernels' machine code from numba's disk cache.

numba optimises a ``parallel=True`` function that it compiles in the process slightly
differently from the same function loaded from its cache (numba issue #10617; here the
fast-math reductions of :mod:`.kernels` come out in a different order). A solve in the one
process that compiled the kernels therefore differed from the same solve in every later
process in the last bits (1e-14 to 2e-13 of the peak pressure at 256²–512²). So the first
process to need the kernels on a cold cache compiles them in a child process
(:func:`warm_up`, tiny solves through every route of the solver) and then loads them from
the cache like every later process does: the first run of a fresh install gives the same
bytes as the second. The compile costs what it did (docs/models.md §2.1); ``make
reproduce`` pays it before the first job.

    python -c "from amontons.contact.kernel_cache import main; main()"   # if cold
"""

from __future__ import annotations

import os
import subprocess
import sys
import warnings

# set in the child, whose own kernels must compile in process
_CHILD = "AMONTONS_KERNEL_WARMUP"
# what the child runs (`python -m` would import this module twice: the package imports it)
COMMAND = "from amontons.contact.kernel_cache import main; main()"
_checked = False


def ensure_cached(dispatchers) -> None:
    """Once per process, before the first kernel call: if the cache holds no compiled code
    for one of ``dispatchers`` (numba dispatchers of :mod:`.kernels`), compile them all in
    a child process (:func:`warm_up`) so that this process loads them from the cache."""
    global _checked
    if _checked:
        return
    _checked = True
    if os.environ.get(_CHILD) or not is_cold(dispatchers):
        return
    _compile_in_child()


def is_cold(dispatchers) -> bool:
    """Whether numba's cache lacks compiled code for one of ``dispatchers`` on this
    machine and this source (numba drops an index whose source file changed). False when
    numba's internals do not say (another numba version, ``NUMBA_DISABLE_JIT``): the
    kernels then compile in the process, as numba does by itself."""
    try:
        return any(not d._cache._cache_file._load_index() for d in dispatchers)
    except AttributeError:
        return False


def _compile_in_child() -> None:
    env = dict(os.environ)
    env[_CHILD] = "1"
    # the child imports amontons the way this process does, installed or not
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    proc = subprocess.run(
        [sys.executable, "-c", COMMAND],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if proc.returncode:
        tail = "\n".join(proc.stderr.strip().splitlines()[-5:])
        warnings.warn(
            "compiling the fused kernels into numba's cache in a child process failed "
            f"(exit {proc.returncode}); they compile in this process, whose results may then "
            f"differ in the last bits from a process that loads them from the cache:\n{tail}",
            RuntimeWarning,
            stacklevel=3,
        )


def warm_up() -> None:
    """Compile every kernel with the argument types the solver gives it: the tiny solves
    of :func:`warm_up_cases`."""
    from .api import solve

    for case in warm_up_cases():
        solve(**case, max_iter=200, raise_on_failure=False)


def warm_up_cases():
    """Keyword arguments of :func:`amontons.contact.solve` for every route of the solver:
    a sphere on 32², periodic and not, under load and displacement control, elastic, with
    penetration hardness (bounded CG), contact hardening (Winkler) and the appendix's
    iteration (volume increments). The contact is ~8 pixels in radius with a Hertz peak of
    0.05 E*, plastic under both laws."""
    from .plasticity import ContactHardening, PenetrationHardness
    from .surfaces import sphere

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
    """Compile the kernels into the cache if it is cold (``make reproduce``, and the child
    of :func:`ensure_cached`)."""
    global _checked
    from . import kernels

    if os.environ.get(_CHILD) or is_cold(kernels.ENTRY_POINTS):
        _checked = True  # this process compiles: its warm-up must not start another child
        warm_up()
