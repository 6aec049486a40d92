"""The appendix's load control: a root find of load(d) = W on the rigid-body approach d.

The load is a continuous, non-decreasing function of the approach; :func:`find_approach`
brackets the root by doubling steps and refines it by Brent's method, and
:class:`SolvedTrials` keeps the converged trials to warm-start the next from the nearest.
Approach in m, loads in N, pressures in Pa.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import optimize

from .errors import ITERATION_CAP, STALLED


class SolvedTrials:
    """Pressures (Pa) of converged trial approaches (m) of a root find, the ``KEEP`` most
    recent, to warm-start each new trial from the nearest one in approach."""

    KEEP = 4  # the bracket's ends and their last refinements; each is one grid of floats

    def __init__(self):
        self.trials = []

    def add(self, d: float, pressure: np.ndarray) -> None:
        self.trials = [*self.trials[-(self.KEEP - 1) :], (d, pressure)]

    def nearest(self, d: float, default: np.ndarray) -> np.ndarray:
        if not self.trials:
            return default
        return min(self.trials, key=lambda trial: abs(trial[0] - d))[1]


class _Found(Exception):
    def __init__(self, state):
        self.state = state


class _Failed(Exception):
    """A trial approach's solve stopped without converging (carries its state)."""

    def __init__(self, state):
        self.state = state


# Doubling steps allowed while bracketing the approach: 60 doublings of the first step span
# 18 orders of magnitude, far beyond any contact.
MAX_BRACKET_STEPS = 60


def find_approach(evaluate, load, d_guess, d_step, load_tol, load_atol=0.0):
    """The state at the root of load(d) = ``load``, for a continuous non-decreasing load(d).

    ``evaluate(d)`` returns (load, state). Brackets by doubling steps from ``d_guess``, then
    Brent's method (scipy), stopping early once the load is within ``load_tol`` (relative).
    Where load(d) is nearly a staircase (a fully plastic contact: one more pixel, p_Y·Δx² more
    load), the closest state found is returned if its load is within ``load_atol`` (N, one
    pixel's worth). Otherwise, or when no bracket or root is found, or a trial approach does
    not converge, the closest state found (else the failed trial) is returned with status 1
    (a trial or Brent's method hit its iteration cap) or 2 (stalled) and a message.
    """
    best = {"err": np.inf, "state": None, "latest": None}

    def residual(d):
        f, state = evaluate(d)
        best["latest"] = state
        if not state.converged:
            raise _Failed(state)
        err = abs(f - load)
        if err < best["err"]:
            best.update(err=err, state=state)
        if err <= load_tol * load:
            raise _Found(state)
        return f - load

    def failed(why, status=STALLED, fallback=None):
        state = next(s for s in (best["state"], fallback, best["latest"]) if s is not None)
        return replace(
            state,
            status=status,
            message=f"load control of the plastic solve failed: {why}; closest load is "
            f"{best['err']:.3e} N from {load:.3e} N",
        )

    try:
        d_lo = d_hi = d_guess
        f0 = residual(d_guess)
        step = d_step
        for _ in range(MAX_BRACKET_STEPS):
            if f0 < 0:
                d_lo, d_hi = d_hi, d_hi + step
                if residual(d_hi) >= 0:
                    break
            else:
                d_hi, d_lo = d_lo, d_lo - step
                if residual(d_lo) < 0:
                    break
            step *= 2
        else:
            return failed(f"no approach brackets the load after {MAX_BRACKET_STEPS} doublings")
        optimize.brentq(residual, d_lo, d_hi, xtol=1e-13 * d_step, rtol=1e-15, maxiter=200)
    except _Found as found:
        return found.state
    except _Failed as trial:
        return failed(trial.state.message, trial.state.status, trial.state)
    except (ValueError, RuntimeError) as error:  # brentq: no sign change / no convergence
        return failed(str(error), ITERATION_CAP if isinstance(error, RuntimeError) else STALLED)
    if best["err"] > max(load_tol * load, load_atol):
        return failed("the load is not a continuous function of the approach here")
    return best["state"]
