"""The solver holds every BLAS pool to one thread and every OpenMP pool to its ``threads`` for
the duration of a call, and gives the caller's limits back, also when the call raises (issue 21:
unbounded OpenBLAS threads spun against the solver's own and cost a plain process 1.7-3.5x; bounded
to 2 they made threads=2 11x slower, benchmarks/bench_thread_pools.py). OpenMP runs the kernels'
threads (and ran FFTW's threaded plans until 2026-11-27): held to one thread, as it was until
2026-11-26, it ran a two-thread FFTW plan on one core (issue 38; benchmarks/README.md, "A second
core"). The limits are observed from inside the call, through the CG loop and the GT iteration, not
by timing."""

import os

import numba
import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import amontons.contact.greenwood_tripp as gt_module
from amontons.contact import (
    ContactInputError,
    ConvergenceError,
    elastic,
    kernels,
    solve,
    solve_load_series,
)
from amontons.contact.greenwood_tripp import AsperityModel, greenwood_tripp
from amontons.contact.options import check_threads
from amontons.contact.surfaces import sphere

CALLER = 2  # the caller's own limit, different from the solve's


def _limits():
    """Threads of every native pool loaded in this process (OpenBLAS, OpenMP, ...)."""
    return [pool["num_threads"] for pool in threadpool_info()]


def _held(pools, threads):
    """Whether ``pools`` ((user_api, threads) of each) are as a solve on ``threads`` holds
    them: BLAS on one thread, OpenMP on ``threads``."""
    return all(n == (threads if api == "openmp" else 1) for api, n in pools)


@pytest.fixture
def seen_in_cg(monkeypatch):
    """Record the pools' limits each time the CG loop runs."""
    seen = []
    original = elastic.run_cg

    def recording(*args, **kwargs):
        seen.append([(pool["user_api"], pool["num_threads"]) for pool in threadpool_info()])
        return original(*args, **kwargs)

    monkeypatch.setattr(elastic, "run_cg", recording)
    return seen


def _sphere():
    return sphere((64, 64), 1e-6, 1e-3), 1e-6, 1e9


@pytest.fixture(scope="module", autouse=True)
def pools_loaded():
    """One solve first: the kernels' OpenMP runtime (numba) loads on its first parallel
    call, and a pool that appears during a call had no caller's limit to restore."""
    h, dx, e_star = _sphere()
    solve(h, dx, e_star, load=1e-3, threads=2)


def test_there_is_a_pool_to_bound():
    # Without a native pool the tests below could not fail.
    assert _limits(), "no native thread pool loaded (numpy without BLAS?)"


@pytest.mark.parametrize("threads", [1, 2])
def test_a_solve_holds_blas_to_one_thread_openmp_to_its_own_and_restores_the_callers(
    seen_in_cg, threads
):
    h, dx, e_star = _sphere()
    with threadpool_limits(limits=CALLER):
        before = _limits()
        solve(h, dx, e_star, load=1e-3, threads=threads)
        after = _limits()
    assert seen_in_cg and all(_held(pools, threads) for pools in seen_in_cg)
    # FFTW's and the kernels' OpenMP runtimes are loaded, so the bound on them is tested
    assert all(any(api == "openmp" for api, _ in pools) for pools in seen_in_cg)
    assert after == before == [CALLER] * len(before)


@pytest.mark.parametrize("threads", [1, 2])
def test_a_load_series_bounds_the_pools_for_every_step(seen_in_cg, threads):
    h, dx, e_star = _sphere()
    with threadpool_limits(limits=CALLER):
        solve_load_series(h, dx, e_star, [1e-3, 2e-3, 4e-3], threads=threads)
        after = _limits()
    assert len(seen_in_cg) >= 3
    assert all(_held(pools, threads) for pools in seen_in_cg)
    assert after == [CALLER] * len(after)


def test_the_callers_limits_come_back_when_the_solve_raises(seen_in_cg):
    h, dx, e_star = _sphere()
    with threadpool_limits(limits=CALLER):
        with pytest.raises(ConvergenceError):
            solve(h, dx, e_star, load=1e-3, threads=1, max_iter=1, tol=1e-14)
        after = _limits()
    assert seen_in_cg and all(_held(pools, 1) for pools in seen_in_cg)
    assert after == [CALLER] * len(after)


def test_greenwood_tripp_bounds_the_pools(monkeypatch):
    seen = []
    original = gt_module._solve_separation

    def recording(*args, **kwargs):
        seen.append(_limits())
        return original(*args, **kwargs)

    monkeypatch.setattr(gt_module, "_solve_separation", recording)
    model = AsperityModel.from_roughness(30e-9, 2e6)
    with threadpool_limits(limits=CALLER):
        greenwood_tripp(1e-3, 3e9, model, 0.05)
        after = _limits()
    assert seen and all(limits == [1] * len(limits) for limits in seen)
    assert after == [CALLER] * len(after)


def test_threads_none_means_the_cores_this_process_may_use():
    assert check_threads(None) == len(os.sched_getaffinity(0))


@pytest.mark.parametrize("bad", [0, -1, 1.5, "2"])
def test_bad_threads_are_refused(bad):
    with pytest.raises(ContactInputError, match="threads must be an integer >= 1 or None"):
        check_threads(bad)


def test_answers_do_not_depend_on_the_bound():
    """The bound changes who computes, not what: the same pressure to 1e-10 relative.

    Solved to tol 1e-10, so that 1e-10 is within what each solve promises where the two
    thread counts run other plans, whose round-off takes the iterates along a slightly
    different path: at the default tol 1e-8 two paths may stop ~1e-10 apart (measured
    1.0e-10 here with FFTW's threaded plans, each within 1e-8 of the tol 1e-13 solution).
    Since 2026-11-27 this 64² window (a 128² padded grid, under two slabs and one kernel
    chunk) runs the one-thread plans and kernels on two threads as well."""
    h, dx, e_star = _sphere()
    one = solve(h, dx, e_star, load=1e-3, threads=1, tol=1e-10)
    with threadpool_limits(limits=CALLER):
        two = solve(h, dx, e_star, load=1e-3, threads=2, tol=1e-10)
    scale = np.abs(one.pressure).max()
    assert np.abs(one.pressure - two.pressure).max() <= 1e-10 * scale


@pytest.mark.parametrize("periodic", [True, False])
def test_two_threads_give_the_one_thread_answer(periodic):
    """threads=2 runs the padded sphere's FFTs (a 256² grid) as two slabs of one-thread
    plans (FFTW_MEASURE, the default) and the periodic 128² ones on its whole-array plan
    (its spectrum is under two slabs: amontons.contact.fft.slab_count); the fused kernels
    run on one, as 128² is one kernel chunk (their sums do not depend on the thread count:
    tests/contact/test_fused_kernels.py), and the FFT plans differ only in round-off, so
    the solution is the one-thread one to 1e-10 in contact fraction and approach (over the
    rms height), far below the 1e-9 solve tolerance."""
    n = 128
    if periodic:
        from amontons.contact import self_affine

        h = self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=11)
        kw = {"load": 0.005 * n * n, "periodic": True}
    else:
        h = sphere((n, n), 1.0, 4.0 * n)
        kw = {"load": 4 * (n / 5) ** 3 / (3 * 4.0 * n)}
    one = solve(h, 1.0, 1.0, tol=1e-9, threads=1, **kw)
    two = solve(h, 1.0, 1.0, tol=1e-9, threads=2, **kw)
    assert (one.info.planner_effort, two.info.planner_effort) == ("FFTW_MEASURE", "FFTW_MEASURE")
    assert abs(one.contact_fraction - two.contact_fraction) <= 1e-10
    assert abs(one.displacement - two.displacement) <= 1e-10 * h.std()
    assert abs(one.iterations - two.iterations) <= 0.05 * one.iterations


def test_an_explicit_planner_effort_is_kept_on_two_threads():
    h = sphere((32, 32), 0.01, 1.0)
    res = solve(h, 0.01, 1.0, load=1e-4, threads=2, planner_effort="FFTW_ESTIMATE")
    assert res.info.planner_effort == "FFTW_ESTIMATE"


@pytest.mark.parametrize(("given", "expected"), [(None, "PASSIVE"), ("ACTIVE", "ACTIVE")])
def test_idle_openmp_workers_sleep_unless_the_user_says_otherwise(given, expected):
    """The kernels' threads are OpenMP (FFTW's threaded plans were, until 2026-11-27);
    spinning idle workers took the cores from the next parallel region (1024² pair on 2
    threads: 48-780 ms instead of 11 ms), so importing the solver sets
    OMP_WAIT_POLICY=PASSIVE before pyfftw loads its libgomp, and keeps a value the user has
    set. Checked in a fresh process."""
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    if given is not None:
        env["OMP_WAIT_POLICY"] = given
    code = "import os, sys, amontons.contact; print(os.environ['OMP_WAIT_POLICY'])"
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == expected


@pytest.mark.parametrize(("n", "expected"), [(64, 1), (128, 1), (256, 2)])
def test_the_kernels_take_no_more_threads_than_the_grid_has_chunks(monkeypatch, n, expected):
    """A thread without a chunk would only pay its wake-up in every kernel: 64² and 128² are
    one chunk (kernels.CHUNK = 16384 points), 256² four, so threads=2 runs the kernels on 1,
    1 and 2 threads. Observed from inside the kernels' caller, as numba's thread count."""
    if expected > numba.config.NUMBA_NUM_THREADS:
        pytest.skip("numba's pool has fewer threads than the grid has chunks")
    seen = []
    original = kernels.update

    def recording(*args):
        seen.append(numba.get_num_threads())
        return original(*args)

    monkeypatch.setattr(kernels, "update", recording)
    h = sphere((n, n), 1e-6, 1e-3)
    solve(h, 1e-6, 1e9, load=1e-3, threads=2)
    assert seen and set(seen) == {expected}
