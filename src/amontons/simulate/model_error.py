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
x − x̄ (x = ln F), subtracted from the residuals. What remains is, first, the convergence
order: the ladder's errors fall 2.0–2.2× per halving of the pixel for the elastic contact
(p ≈ 1.0–1.1) and 1.9–5× for contact hardening (p ≈ 0.9–2.3), so the factor 1/(2^p − 1) that
p = 1 takes as 1 lies between about 1.15 and 0.25. It scales the whole bias at once: one mode
of the covariance, ``order_sd`` times the bias line. Second, the line's own standard errors
from the loads' scatter about it, as an offset and a slope.

**The PSF's uncertainty.** The best value's solution rendered again with the PSF's FWHM one
standard error wider and narrower: half the difference in ln area, fitted by the same line,
is a second mode (one parameter moves every load at once).

**Where it cannot be measured** (the finer solve does not converge or does not fit the
window, or its area extrapolates to nothing), the error is not taken as none: it is bounded
by a stated figure, ``model_error_stated_per_um`` times the solver pixel in µm, counted as an
offset of unknown sign shared by every load (:func:`stated_model_error`). The default, 0.46
per µm, is the accuracy study's largest rendered-area error per pixel, the elastic rough
sphere's (docs/accuracy.md §4: 18.8, 9.3 and 4.2 % at 411, 206 and 103 nm; contact
hardening's is 2–4 times less).

**What it leaves out.** Below the AFM map's own pixel nothing is known: the map is the
finest scale the model sees, and its own discretisation is not counted. Nor is the bias's
dependence on the scanned value: it is estimated at the grid's best and applied at every
value.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from amontons.simulate.scan_criterion import ModelError
from amontons.simulate.scan_grid import ScanError

__all__ = [
    "SharedLine",
    "model_error_of",
    "psf_log_change",
    "richardson_log_bias",
    "shared_line",
    "stated_model_error",
]


def richardson_log_bias(
    solved_m2: Sequence[float], check_m2: Sequence[float], factor: float, order: float = 1.0
) -> np.ndarray:
    """b_i = ln A(h) − ln A*: the bias in ln area of each load's area ``solved_m2`` at the
    solver pixel h, from the same load's ``check_m2`` solved at ``factor``·h (0.5: one step
    finer), for an error of ``order`` p in h (Richardson: A(h) − A* = (A(h) − A(fh)) /
    (1 − f^p))."""
    solved = np.asarray(solved_m2, dtype=float)
    check = np.asarray(check_m2, dtype=float)
    if solved.shape != check.shape or solved.size == 0:
        raise ScanError(
            f"{solved.size} areas at the solver pixel against {check.size} at the check"
        )
    if factor <= 0 or factor == 1:
        raise ScanError(f"model_error_pixel_factor = {factor:g}; expected a positive factor ≠ 1")
    if np.any(solved <= 0) or np.any(check <= 0):
        raise ScanError(
            f"a load renders no contact at the solver pixel or {factor:g}x it (areas "
            f"{solved.tolist()} and {check.tolist()} m²): no bias to extrapolate"
        )
    extrapolated = solved - (solved - check) / (1.0 - factor**order)
    if np.any(extrapolated <= 0):
        raise ScanError(
            f"areas {solved.tolist()} m² at the solver pixel and {check.tolist()} at "
            f"{factor:g}x it extrapolate to a non-positive area: the pixel is far from the "
            "range where the error falls as a power of it; expected a finer solver pixel"
        )
    return np.log(solved) - np.log(extrapolated)


def psf_log_change(
    rendered_m2: Callable[[float], Sequence[float]], fwhm_m: float, se_m: float
) -> list[float] | None:
    """Half the change of ln(rendered area) per load between renders with the PSF's FWHM
    ``fwhm_m`` one standard error ``se_m`` wider and one narrower (no narrower than half the
    FWHM), ``rendered_m2`` giving each load's area (m²) at a FWHM (m); None where a render
    loses its contact (its share cannot be measured)."""
    wide, narrow = (rendered_m2(f) for f in (fwhm_m + se_m, max(fwhm_m - se_m, 0.5 * fwhm_m)))
    if min([*wide, *narrow]) <= 0:
        return None
    return [0.5 * math.log(w / n) for w, n in zip(wide, narrow, strict=True)]


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


def model_error_of(
    loads_mn: Sequence[float],
    log_bias: Sequence[float],
    order_sd: float,
    psf_log_change: Sequence[float] | None = None,
) -> tuple[ModelError, dict]:
    """The criterion's model error at ``loads_mn``: the line fitted to the pixel's bias
    ``log_bias`` (subtracted); its uncertainty as one mode, ``order_sd`` times the line
    (the convergence order scales the whole bias at once), and the line's own standard errors
    as offset and slope; and, where given, the PSF's as a second mode (``psf_log_change``:
    the change of ln area per standard error of the FWHM, fitted by a line). With the record
    that says how."""
    bias = shared_line(loads_mn, log_bias)
    line = bias.at(loads_mn)
    modes = [tuple(float(order_sd * b) for b in line)]
    record = {
        "pixel_bias_per_load": [float(b) for b in log_bias],
        "pixel_bias_line": {"offset": bias.offset, "slope": bias.slope},
        "pixel_bias_se": {"offset": bias.offset_se, "slope": bias.slope_se},
        "order_sd": order_sd,
    }
    if psf_log_change is not None:
        psf = shared_line(loads_mn, psf_log_change)
        record["psf_change_per_load"] = [float(c) for c in psf_log_change]
        record["psf_line"] = {"offset": psf.offset, "slope": psf.slope}
        modes.append(tuple(float(c) for c in psf.at(loads_mn)))
    error = ModelError(tuple(float(b) for b in line), bias.offset_se, bias.slope_se, tuple(modes))
    return error, {**record, **error.to_record()}


def stated_model_error(
    loads_mn: Sequence[float],
    pixel_m: float,
    per_um: float,
    psf_log_change: Sequence[float] | None = None,
) -> tuple[ModelError, dict]:
    """The criterion's model error where the pixel's bias cannot be measured: no bias
    subtracted, and an offset of unknown sign, shared by every load, of ``per_um`` (ln area
    per µm of solver pixel) times the solver pixel ``pixel_m`` (m); the PSF's mode where
    given, as :func:`model_error_of` counts it. With the record that says how."""
    if not per_um > 0:
        raise ScanError(
            f"model_error_stated_per_um = {per_um!r}; expected a positive error per µm of pixel"
        )
    n = len(loads_mn)
    offset_sd = per_um * pixel_m * 1e6
    modes = []
    record = {"stated_per_um": per_um, "stated_offset_sd": offset_sd}
    if psf_log_change is not None:
        psf = shared_line(loads_mn, psf_log_change)
        record["psf_change_per_load"] = [float(c) for c in psf_log_change]
        modes.append(tuple(float(c) for c in psf.at(loads_mn)))
    error = ModelError((0.0,) * n, offset_sd, 0.0, tuple(modes))
    return error, {**record, **error.to_record()}
