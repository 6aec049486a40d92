"""The model's own error in rendered area, measured where it is used (docs/study.md §1, "The
model's error"): what a scan's criterion (:mod:`amontons.simulate.scan_criterion`) counts
beside the measured scatter.

**The solver pixel's bias.** The rendered Otsu area converges about linearly in the solver
pixel h (docs/accuracy.md §4: the elastic rough sphere's rendered area errs 18.8, 9.3 and
4.2 % at 411, 206 and 103 nm), A(h) ≈ A* + c·h. The scan job solves its grid's best value
once more at twice the pixel, and Richardson's extrapolation gives

    A* ≈ (2 A(h) − A(2h)),        b = ln A(h) − ln A*

per load. On the accuracy study's ladder this estimate, taken from 411 and 206 nm, gives the
206 nm error as 9.5 % against the 9.3 % measured (elastic) and 2.2 against 2.6 % (contact
hardening). A coarser step, not a finer one: it costs a quarter of a solve at h, not four to
eight.

**What stays uncertain of it, shared by every load.** The bias is fitted by a line in
x − x̄ (x = ln F): an offset and a slope, subtracted from the residuals. What remains is the
convergence order, which the ladder shows between about 0.6 and 1.6 (the factor 1/(2^p − 1)
between 1.9 and 0.5): a relative standard deviation ``order_sd`` of each coefficient, added
in quadrature to the coefficient's own standard error from the loads' scatter about the line.

**The PSF's uncertainty.** The best value's solution rendered again with the PSF's FWHM one
standard error wider and narrower: half the difference in ln area, fitted by the same line,
adds to the offset and the slope.

**What it leaves out.** Below the AFM map's own pixel nothing is known: the map is the
finest scale the model sees, and its own discretisation is not counted. Nor is the bias's
dependence on the scanned value: it is estimated at the grid's best and applied at every
value.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from amontons.simulate.scan_criterion import ModelError
from amontons.simulate.scan_grid import ScanError

__all__ = ["SharedLine", "model_error_of", "richardson_log_bias", "shared_line"]


def richardson_log_bias(
    fine_m2: Sequence[float], coarse_m2: Sequence[float], factor: float = 2.0, order: float = 1.0
) -> np.ndarray:
    """b_i = ln A(h) − ln A*: the bias in ln area of each load's area ``fine_m2`` at the
    solver pixel h, from the same load's ``coarse_m2`` at ``factor``·h, for an error of
    ``order`` in h (Richardson: A* = (f^p A(h) − A(fh)) / (f^p − 1))."""
    fine = np.asarray(fine_m2, dtype=float)
    coarse = np.asarray(coarse_m2, dtype=float)
    if fine.shape != coarse.shape or fine.size == 0:
        raise ScanError(f"{fine.size} areas at the solver pixel against {coarse.size} coarser")
    if np.any(fine <= 0) or np.any(coarse <= 0):
        raise ScanError(
            f"a load renders no contact at the solver pixel or {factor:g}x it (areas "
            f"{fine.tolist()} and {coarse.tolist()} m²): no bias to extrapolate"
        )
    gain = factor**order
    extrapolated = (gain * fine - coarse) / (gain - 1.0)
    if np.any(extrapolated <= 0):
        raise ScanError(
            f"areas {fine.tolist()} m² at the solver pixel and {coarse.tolist()} at "
            f"{factor:g}x it extrapolate to a non-positive area: the pixel is far from the "
            "linear range, expected a finer solver pixel"
        )
    return np.log(fine) - np.log(extrapolated)


@dataclass(frozen=True)
class SharedLine:
    """A per-load quantity in ln area fitted by c0 + c1 (x − x̄), x = ln F: its offset and
    slope with their standard errors (0 where the line passes through every load)."""

    offset: float
    slope: float
    offset_se: float
    slope_se: float

    def at(self, loads_mn: Sequence[float]) -> np.ndarray:
        """The line at ``loads_mn``."""
        x = np.log(np.asarray(loads_mn, dtype=float))
        return self.offset + self.slope * (x - x.mean())


def shared_line(loads_mn: Sequence[float], values: Sequence[float]) -> SharedLine:
    """The least-squares line of ``values`` against ln F about its mean (at least 2 loads;
    standard errors from the scatter about it with n − 2 degrees of freedom, 0 for 2)."""
    x = np.log(np.asarray(loads_mn, dtype=float))
    y = np.asarray(values, dtype=float)
    if x.size < 2 or y.shape != x.shape:
        raise ScanError(f"{y.size} values at {x.size} loads; a line needs at least 2")
    centred = x - x.mean()
    sxx = float(centred @ centred)
    slope = float(centred @ y / sxx) if sxx > 0 else 0.0
    offset = float(y.mean())
    if x.size == 2:
        return SharedLine(offset, slope, 0.0, 0.0)
    residuals = y - offset - slope * centred
    s2 = float(residuals @ residuals) / (x.size - 2)
    return SharedLine(offset, slope, float(np.sqrt(s2 / x.size)), float(np.sqrt(s2 / sxx)))


def _uncertain(line: SharedLine, order_sd: float) -> tuple[float, float]:
    """The offset's and the slope's standard deviations: ``order_sd`` of each, in quadrature
    with its standard error."""
    return (
        float(np.hypot(order_sd * line.offset, line.offset_se)),
        float(np.hypot(order_sd * line.slope, line.slope_se)),
    )


def model_error_of(
    loads_mn: Sequence[float],
    log_bias: Sequence[float],
    order_sd: float,
    psf_log_change: Sequence[float] | None = None,
) -> tuple[ModelError, dict]:
    """The criterion's model error at ``loads_mn``: the line fitted to the pixel's bias
    ``log_bias`` (subtracted), its uncertainty (``order_sd``, the coefficients' standard
    errors) and, where given, the PSF's (``psf_log_change``: the change of ln area per
    standard error of the FWHM), as shared offset and slope; and the record that says how."""
    bias = shared_line(loads_mn, log_bias)
    offset_sd, slope_sd = _uncertain(bias, order_sd)
    record = {
        "pixel_bias_per_load": [float(b) for b in log_bias],
        "pixel_bias_line": {"offset": bias.offset, "slope": bias.slope},
        "pixel_bias_sd": {"offset": offset_sd, "slope": slope_sd},
        "order_sd": order_sd,
    }
    if psf_log_change is not None:
        psf = shared_line(loads_mn, psf_log_change)
        record["psf_change_per_load"] = [float(c) for c in psf_log_change]
        record["psf_sd"] = {"offset": abs(psf.offset), "slope": abs(psf.slope)}
        offset_sd = float(np.hypot(offset_sd, psf.offset))
        slope_sd = float(np.hypot(slope_sd, psf.slope))
    error = ModelError(tuple(float(b) for b in bias.at(loads_mn)), offset_sd, slope_sd)
    return error, {**record, **error.to_record()}
