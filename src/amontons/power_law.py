"""Power-law fits y = c·(x/x_ref)^α on log–log axes (ordinary least squares, statsmodels)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

# The two pieces used, not statsmodels.api: that imports all of statsmodels, 0.4 s more in
# every job that fits (docs/testing.md, "Where the time goes").
from statsmodels.regression.linear_model import OLS
from statsmodels.tools.tools import add_constant


@dataclass(frozen=True)
class Estimate:
    """A fitted value with its standard error and confidence interval."""

    estimate: float
    standard_error: float
    ci_low: float
    ci_high: float
    confidence: float


@dataclass(frozen=True)
class PowerLawFit:
    """y = prefactor·(x/x_ref)^exponent, fitted on n points."""

    exponent: Estimate
    prefactor: Estimate
    x_ref: float
    n: int

    def to_record(self) -> dict:
        """JSON-ready record: exponent and prefactor with their errors, x_ref and n."""
        return asdict(self)


def fit_power_law(
    x: np.ndarray, y: np.ndarray, *, x_ref: float, confidence: float = 0.95
) -> PowerLawFit:
    """Fit log y = log c + α·log(x/x_ref) by OLS.

    The prefactor c (units of y) and its interval are back-transformed from the intercept, so
    the interval is asymmetric and its 'standard_error' is the delta-method one. Needs at least
    three positive points, so that the standard errors are defined.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"x and y must be 1-D of equal length; got {x.shape} and {y.shape}")
    if x.size < 3:
        raise ValueError(f"a power-law fit with standard errors needs ≥ 3 points; got {x.size}")
    if np.any(x <= 0) or np.any(y <= 0) or not np.all(np.isfinite(x) & np.isfinite(y)):
        raise ValueError(f"power-law fit needs finite positive x and y; got x={x}, y={y}")
    design = add_constant(np.log(x / x_ref))
    result = OLS(np.log(y), design).fit()
    (ci_intercept, ci_slope) = result.conf_int(alpha=1 - confidence)
    intercept, slope = result.params
    se_intercept, se_slope = result.bse
    prefactor = float(np.exp(intercept))
    return PowerLawFit(
        exponent=Estimate(
            float(slope), float(se_slope), float(ci_slope[0]), float(ci_slope[1]), confidence
        ),
        prefactor=Estimate(
            prefactor,
            prefactor * float(se_intercept),
            float(np.exp(ci_intercept[0])),
            float(np.exp(ci_intercept[1])),
            confidence,
        ),
        x_ref=float(x_ref),
        n=int(x.size),
    )
