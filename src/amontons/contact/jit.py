"""Compilation settings and thread control of the solver's numba kernels, and the guard that
makes every process run them from numba's disk cache.

numba optimises a ``parallel=True`` function that it compiles in the process slightly
differently from the same function loaded from its cache (numba issue #10617: the fast-math
reductions come out in a different order), so a solve in the one process that compiled the
kernels would differ from the same solve in every later process in the last bits (1e-14 to
2e-13 of the peak pressure at 256²–512²). So the first process to need the kernels on a
cold cache compiles them in a child process (:func:`ensure_cached`, which runs
``amontons.contact.kernel_cache.main``: tiny solves through every route, from the top of the
package) and then loads them from the cache like every later process does. Processes that
start together (the test workers, a Snakemake run's first jobs, a warm-up beside them) take
turns on a lock file in the cache folder (:func:`warm_up_lock`): one compiles, the others
wait and then load. The kernels (:mod:`.spectrum`, :mod:`.kernels`) enter through
:func:`kernel_threads`.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import tempfile
import warnings

import numba

from .locks import exclusive_lock

# fastmath "reassoc" only: it lets LLVM vectorise the reductions (several partial sums per
# chunk instead of one serial chain; benchmarks/README.md, "Why the kernels are written as
# they are"); the summation order is then fixed by
# the compiled code, the same on every call and thread count. No "contract" (FMA) or
# "nnan": results stay those of plain IEEE products and sums, and NaN propagates.
FASTMATH = {"reassoc", "nsz"}
# Options of a kernel called from Python (a parallel loop, cached on disk).
JIT = {"cache": True, "parallel": True, "nogil": True, "fastmath": FASTMATH}
# Options of an inner loop compiled into a kernel.
INNER = {"cache": True, "fastmath": FASTMATH, "inline": "always"}

# set in the child, whose own kernels must compile in process
CHILD_ENV = "AMONTONS_KERNEL_WARMUP"
# what the child runs: the warm-up at the top of the package (`python -m` would import the
# module twice)
COMMAND = "from amontons.contact.kernel_cache import main; main()"
# ids of the dispatcher tuples already checked in this process (the check costs a disk
# read; the tuples are module constants, so their ids stand for them)
_checked: set[int] = set()


@contextlib.contextmanager
def kernel_threads(threads: int, entry_points):
    """Run numba kernels on ``threads`` threads (clipped to numba's pool) within the block;
    the first call of a process for a set of ``entry_points`` (numba dispatchers) first
    makes sure they run from numba's disk cache (:func:`ensure_cached`)."""
    ensure_cached(entry_points)
    old = numba.get_num_threads()
    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(old)


def ensure_cached(dispatchers) -> None:
    """Once per process and tuple of ``dispatchers`` (a module constant): if the cache
    holds no compiled code for one of them, compile every kernel in a child process
    (:data:`COMMAND`) so that this process loads them from the cache."""
    if id(dispatchers) in _checked:
        return
    _checked.add(id(dispatchers))
    if os.environ.get(CHILD_ENV) or not is_cold(dispatchers):
        return
    with warm_up_lock(dispatchers):
        # another process may have filled the cache while this one waited
        if is_cold(dispatchers):
            compile_in_child()


def warm_up_lock(dispatchers):
    """An exclusive lock on a file in the cache folder of ``dispatchers`` (a context
    manager), so that one process at a time warms the cache; the others wait."""
    return exclusive_lock(os.path.join(_cache_folder(dispatchers), ".amontons-warm-up.lock"))


def _cache_folder(dispatchers) -> str:
    """The folder numba caches the first of ``dispatchers`` in; the temporary folder where
    numba does not say (another numba version, ``NUMBA_DISABLE_JIT``)."""
    try:
        folder = dispatchers[0]._cache._cache_path
    except (AttributeError, IndexError):
        return tempfile.gettempdir()
    os.makedirs(folder, exist_ok=True)
    return folder


def mark_checked(dispatchers) -> None:
    """Take ``dispatchers`` as checked: this process compiles them itself (the warm-up)."""
    _checked.add(id(dispatchers))


def is_cold(dispatchers) -> bool:
    """Whether numba's cache lacks compiled code for one of ``dispatchers`` on this
    machine and this source (numba drops an index whose source file changed). False when
    numba's internals do not say (another numba version, ``NUMBA_DISABLE_JIT``): the
    kernels then compile in the process, as numba does by itself."""
    try:
        return any(not d._cache._cache_file._load_index() for d in dispatchers)
    except AttributeError:
        return False


def compile_in_child() -> None:
    """Run :data:`COMMAND` in a child process; warn (RuntimeWarning) if it fails."""
    env = dict(os.environ)
    env[CHILD_ENV] = "1"
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
            stacklevel=4,
        )
