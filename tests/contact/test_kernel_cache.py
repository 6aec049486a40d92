"""The fused kernels run from numba's disk cache in every process
(:mod:`amontons.contact.kernel_cache`).

numba optimises a parallel function it compiles in the process differently from the same
function loaded from its cache, and the kernels' reductions then round differently: before
this module, the first process of a fresh install gave other bytes than every later one
(1e-14 to 2e-13 of the peak pressure at 256²-512²). A fresh clone (CI) starts this session
with a cold cache, so there the first two tests check the cold path itself: the child
compiled, this process loaded.
"""

import hashlib
import importlib.util
import subprocess
import sys

import numpy as np
import pytest

from amontons.contact import jit, kernel_cache, kernels, solve
from amontons.contact.laws import PenetrationHardness

# evaluated at collection, before any test has run a kernel
COLD_AT_START = kernel_cache.is_cold(kernels.ENTRY_POINTS)

SOLVES = """
import hashlib
from amontons.contact import self_affine, solve, sphere
from amontons.contact.laws import PenetrationHardness
rough = self_affine((96, 96), 1.0, 0.8, rms_slope=0.1, rng=11)
a = solve(rough, 1.0, 1.0, load=0.005 * 96**2, periodic=True)
h = sphere((96, 96), 0.01, 1.0)
b = solve(h, 0.01, 1.0, load=2e-3)
c = solve(h, 0.01, 1.0, load=2e-3, plasticity=PenetrationHardness(0.05))
digest = hashlib.sha256(b"".join(r.pressure.tobytes() for r in (a, b, c))).hexdigest()
"""


def _solve_here() -> str:
    scope = {}
    exec(SOLVES, scope)  # the same code as the fresh process below
    return scope["digest"]


def test_this_process_runs_every_kernel_from_the_cache():
    """After solves through the elastic and the bounded route, no kernel was compiled in
    this process: every one was loaded from the cache (on a cold start, after the child
    compiled them)."""
    _solve_here()
    compiled_here = {d.__name__: len(d.stats.cache_misses) for d in kernels.ENTRY_POINTS}
    loaded = sum(len(d.stats.cache_hits) for d in kernels.ENTRY_POINTS)
    assert not any(compiled_here.values()), (compiled_here, f"cold at start: {COLD_AT_START}")
    assert loaded > 0
    assert not kernel_cache.is_cold(kernels.ENTRY_POINTS)


def test_a_fresh_process_gives_the_bytes_of_this_one():
    """A periodic rough, a non-periodic Hertz and a penetration-hardness solve: the same
    pressure bytes in this process and in a fresh one (which shares the FFT wisdom)."""
    here = _solve_here()
    out = subprocess.run(
        [sys.executable, "-c", SOLVES + "print(digest)"],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    assert out.stdout.split()[-1] == here


def _tiny_cached_function(tmp_path):
    """A cache=True numba function whose cache lives in ``tmp_path`` (compiles in <1 s)."""
    src = tmp_path / "tiny_kernel.py"
    src.write_text("import numba\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1\n")
    spec = importlib.util.spec_from_file_location("tiny_kernel", src)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.f


def test_is_cold_until_the_cache_holds_compiled_code(tmp_path):
    f = _tiny_cached_function(tmp_path)
    assert kernel_cache.is_cold([f])
    assert f(1) == 2
    assert not kernel_cache.is_cold([f])


def test_is_cold_says_no_when_numba_cannot_tell():
    """A plain function (as under NUMBA_DISABLE_JIT) has no cache to warm."""
    assert not kernel_cache.is_cold([hashlib.sha256])


def test_a_failing_child_warns_and_the_process_goes_on(monkeypatch):
    monkeypatch.setattr(jit.sys, "executable", "/bin/false")
    with pytest.warns(RuntimeWarning, match="child process failed"):
        jit.compile_in_child()


def test_the_warm_up_solves_reach_their_routes():
    """The warm-up's tiny solves are in contact over a few pixels' radius, and the plastic
    ones carry pressures at the hardness bound: they run the code they are there to
    compile."""
    for case in kernel_cache.warm_up_cases():
        res = solve(**case, max_iter=200, raise_on_failure=False)
        law = case["plasticity"]
        area = np.count_nonzero(res.pressure)
        assert 20 < area < 600, (case, area)
        if isinstance(law, PenetrationHardness):
            assert res.pressure.max() > 0.9 * law.p_y, case


LOCK_PROBE = """
import fcntl, sys
with open(sys.argv[1], "a") as handle:
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        print("held")
    else:
        print("free")
"""


def _lock_state(path) -> str:
    """Whether another process finds the lock file ``path`` held or free."""
    out = subprocess.run(
        [sys.executable, "-c", LOCK_PROBE, str(path)],
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    )
    return out.stdout.strip()


def test_one_process_at_a_time_warms_the_cache(tmp_path):
    """The warm-up lock lives beside the cache and is held against other processes for
    the block only (the test workers and a Snakemake run's first jobs start together)."""
    f = _tiny_cached_function(tmp_path)
    lock = tmp_path / "__pycache__" / ".amontons-warm-up.lock"
    with jit.warm_up_lock([f]):
        assert lock.exists()
        assert _lock_state(lock) == "held"
    assert _lock_state(lock) == "free"


def test_a_process_that_waited_for_a_warm_cache_compiles_nothing(tmp_path, monkeypatch):
    """Cold when first asked, warm once the lock is had (another process compiled while
    this one waited): no child is started."""
    f = _tiny_cached_function(tmp_path)
    answers = iter([True, False])
    started = []
    monkeypatch.setattr(jit, "is_cold", lambda dispatchers: next(answers))
    monkeypatch.setattr(jit, "compile_in_child", lambda: started.append(1))
    monkeypatch.delenv(jit.CHILD_ENV, raising=False)
    jit.ensure_cached((f,))
    assert started == []
