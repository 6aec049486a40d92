"""Convergence monitoring (issue 18 item 3): a solve whose residual stops falling ends early
with a ConvergenceError carrying its history, and convergent solves are never stopped."""

import numpy as np
import pytest

from amontons.contact import ConvergenceError, solve
from amontons.contact.options import default_max_iter
from amontons.contact.stall import STALL_FACTOR, STALL_WINDOW, StallMonitor
from amontons.contact.surfaces import self_affine

N = 64


def stalling_case():
    """A rough periodic surface solved to tol 1e-16: below the float64 floor of the
    residual (~2e-16 at best, ~1e-15 typically, reached in ~70 iterations), so the
    residual stops falling and, without the monitor, the solve ran all 1512 iterations."""
    h = self_affine((N, N), 1.0, 0.8, rms_slope=0.1, rng=7)
    return h, {"load": 0.005 * h.size, "periodic": True, "tol": 1e-16}


def longest_stretch(history, factor=STALL_FACTOR):
    """Longest run of iterations in which the best residual did not fall by ``factor``
    (what StallMonitor measures), from a residual history."""
    monitor = StallMonitor(window=len(history) + 1, factor=factor)
    longest = 0
    for r in history:
        monitor.update(r)
        longest = max(longest, monitor.stretch)
    return longest


def test_stalled_solve_ends_early_with_its_history():
    h, kw = stalling_case()
    with pytest.raises(ConvergenceError, match="residual stalled") as info:
        solve(h, 1.0, 1.0, **kw)
    err = info.value
    assert err.status == 2  # stalled, not the iteration cap
    # it stopped one window after the residual's floor, far before the cap
    assert err.iterations < default_max_iter(h.shape) / 4
    assert len(err.residual_history) == err.iterations
    # and the history shows why: the last STALL_WINDOW iterations did not halve the best
    hist = err.residual_history
    best_before = np.min(hist[:-STALL_WINDOW])
    assert np.min(hist) > best_before / STALL_FACTOR
    assert longest_stretch(hist) == STALL_WINDOW


def test_stalled_solve_without_raising_returns_its_last_iterate():
    """raise_on_failure=False: status 2, the message says why, the fields are finite and
    the iterate is as good as float64 allows (residual < 1e-14)."""
    h, kw = stalling_case()
    res = solve(h, 1.0, 1.0, raise_on_failure=False, **kw)
    assert res.status == 2 and not res.success and "stalled" in res.message
    assert np.isfinite(res.pressure).all() and res.residual < 1e-14


def test_convergent_solves_are_far_from_the_stall_criterion(rough_case, hertz_case):
    """The two shared cases (periodic rough 1e-10, free Hertz 1e-8) never go a quarter of
    the window without halving their best residual (measured: <= 26 iterations over every
    convergent solve of the suite, cg.py)."""
    for case in (rough_case, hertz_case):
        res = case["result"]
        assert res.converged
        assert longest_stretch(res.residual_history) < STALL_WINDOW / 4


def test_monitor_never_fires_on_a_slow_but_steady_fall():
    """A residual that halves every 24 iterations under up to 1.5x noise never stalls with
    a window of 50: from any best value 0.5^(t0/24)·u0 (u0 >= 1), every residual after
    24·(1 + log2 1.5) = 38 more iterations is below half of it, whatever its noise."""
    monitor = StallMonitor(window=50, factor=2.0)
    rng = np.random.default_rng(0)
    for i in range(2000):
        r = 0.5 ** (i / 24) * rng.uniform(1, 1.5)
        assert not monitor.update(r)


def test_monitor_fires_exactly_one_window_after_the_last_fall():
    monitor = StallMonitor(window=50, factor=2.0)
    for r in (1.0, 0.4, 0.1):
        assert not monitor.update(r)
    flags = [monitor.update(0.09) for _ in range(50)]  # a 10 % fall is no progress
    assert flags == [False] * 49 + [True]


@pytest.mark.parametrize("junk", [np.inf, np.nan])
def test_monitor_does_not_take_inf_or_nan_for_progress(junk):
    monitor = StallMonitor(window=5, factor=2.0)
    monitor.update(1.0)
    flags = [monitor.update(junk) for _ in range(5)]
    assert flags[-1]
