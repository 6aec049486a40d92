"""The criterion a scan is judged by (docs/study.md §1, "The criterion"): χ² of the log-area
residuals under a covariance that counts the measured scatter as random per load and the
model's own error as shared by every load.

With x_i = ln F_i and r_i(v) = ln A_sim,i(v) − b_i − ln A_meas,i over the n loads where the
measured image shows a contact,

    C = σ² I + σ_off² 1 1ᵀ + σ_slope² (x − x̄)(x − x̄)ᵀ + Σ_k u_k u_kᵀ,   χ²(v) = rᵀ C⁻¹ r

* σ, the random part: the residual standard deviation of the measured ln areas about their
  own power-law line (n − 2 degrees of freedom), what even a perfect model would miss each
  load by. It averages down with n.
* b_i, the model's bias in ln area, known with its sign (the solver pixel's discretisation,
  :mod:`amontons.simulate.model_error`): subtracted, so that a biased model is corrected,
  not only widened.
* σ_off, σ_slope and the modes u_k, what remains uncertain of the model's error, shared by
  every load (an offset, a slope in ln F, and errors whose whole shape over the loads moves
  at once): they do not average down with n.

With σ_off = σ_slope = 0 and b = 0, χ² = n D² / σ², D the rms log-area distance of
:func:`amontons.simulate.scan.log_area_distance`: the criterion of the scans before the
model's error was counted.

The interval's quantile is that of F(1, ν): σ is estimated from n − 2 degrees of freedom
(7.71 at 95 % for n = 6, 10.1 for n = 5), and where the model's error, whose size is stated
rather than estimated, takes a share of the parameter's variance, ν grows by
Welch–Satterthwaite (:meth:`Criterion.effective_dof`) towards χ²(1)'s 3.84. A scan with
fewer than :data:`MIN_LOADS` measured loads has no σ to judge with: :class:`TooFewLoads`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy import optimize, stats

from amontons.simulate.scan_grid import MIN_LOADS, ScanError

__all__ = [
    "MIN_LOADS",
    "QUANTILES",
    "Criterion",
    "ModelError",
    "TooFewLoads",
    "log_area_scatter",
]

# The interval's quantile: "f", F(1, n - 2) for a scatter estimated from the data (the
# pipeline's); "chi2", χ²(1), for a scatter taken as known (the scans before issue 65).
QUANTILES = ("f", "chi2")
# The smallest random part (ln area): a perfect power law measured without scatter still
# leaves the criterion a finite scale.
SD_FLOOR = 1e-6


class TooFewLoads(ScanError):
    """A scan whose measured loads are too few to judge: an answer ("not decided"), not a
    failure. ``loads_mn``: the loads it holds."""

    def __init__(self, loads_mn: Sequence[float]):
        self.loads_mn = [float(f) for f in loads_mn]
        held = ", ".join(f"{f:g}" for f in self.loads_mn) or "none"
        super().__init__(
            f"{len(self.loads_mn)} measured loads ({held} mN); the scatter of the measured "
            f"areas about their power law, which the criterion weighs the model against, "
            f"needs at least {MIN_LOADS}"
        )


def log_area_scatter(loads: Sequence[float], areas: Sequence[float]) -> float:
    """s: residual standard deviation of ln A about the straight line fitted to ln A against
    ln F (n - 2 degrees of freedom; at least :data:`MIN_LOADS` loads, else
    :class:`TooFewLoads`)."""
    x = np.log(np.asarray(loads, dtype=float))
    y = np.log(np.asarray(areas, dtype=float))
    if x.size < MIN_LOADS:
        raise TooFewLoads(loads)
    residuals = y - np.polyval(np.polyfit(x, y, 1), x)
    return float(np.sqrt(np.sum(residuals**2) / (x.size - 2)))


@dataclass(frozen=True)
class ModelError:
    """The model's error in ln(rendered area), per load of the criterion: the bias ``bias``
    (known with its sign, subtracted from the residuals), and what remains uncertain of it,
    shared by every load: ``offset_sd`` (the same at every load), ``slope_sd`` (per unit of
    ln F about the loads' mean) and ``modes``, vectors over the loads each of whose whole
    shape is uncertain at one standard deviation (one error that moves every load at once,
    such as the convergence order's scaling of the bias: a rank-one term u uᵀ of C)."""

    bias: tuple[float, ...]
    offset_sd: float
    slope_sd: float
    modes: tuple[tuple[float, ...], ...] = ()

    @classmethod
    def none(cls, n: int) -> ModelError:
        """No model error: the criterion of the measured scatter alone."""
        return cls((0.0,) * n, 0.0, 0.0)

    @classmethod
    def from_record(cls, record: Mapping) -> ModelError:
        modes = tuple(tuple(mode) for mode in record.get("modes", []))
        return cls(tuple(record["bias"]), record["offset_sd"], record["slope_sd"], modes)

    def to_record(self) -> dict:
        return {
            "bias": list(self.bias),
            "offset_sd": self.offset_sd,
            "slope_sd": self.slope_sd,
            "modes": [list(mode) for mode in self.modes],
        }


@dataclass(frozen=True)
class Criterion:
    """χ² of a scan's values under one covariance: the measured loads ``loads_mn``, the
    measured scatter ``scatter_sd`` (ln area), the model's error and the quantile's kind
    (:data:`QUANTILES`)."""

    loads_mn: tuple[float, ...]
    scatter_sd: float
    model_error: ModelError
    quantile: str = "f"

    def __post_init__(self):
        if len(self.loads_mn) < MIN_LOADS:
            raise TooFewLoads(self.loads_mn)
        sizes = {len(self.model_error.bias), *(len(m) for m in self.model_error.modes)}
        if sizes != {len(self.loads_mn)}:
            raise ScanError(
                f"model error for {sorted(sizes)} loads; the criterion has {len(self.loads_mn)}"
            )
        if self.quantile not in QUANTILES:
            raise ScanError(f"quantile = {self.quantile!r}; expected one of {QUANTILES}")

    @classmethod
    def of_measured(
        cls,
        loads_mn: Sequence[float],
        measured_um2: Sequence[float],
        model_error: ModelError | None = None,
        quantile: str = "f",
    ) -> Criterion:
        """The criterion of the measured areas (µm²) at ``loads_mn``: their scatter about
        their power law, and the model's error (None: none counted)."""
        scatter = log_area_scatter(loads_mn, measured_um2)
        error = ModelError.none(len(loads_mn)) if model_error is None else model_error
        return cls(tuple(float(f) for f in loads_mn), scatter, error, quantile)

    @property
    def n(self) -> int:
        return len(self.loads_mn)

    @property
    def measured_sd(self) -> float:
        """The measured scatter, floored at :data:`SD_FLOOR` (ln area): the random part a
        value is judged with before any Birge inflation."""
        return max(self.scatter_sd, SD_FLOOR)

    def chi2_measured(self, residuals: Sequence[float]) -> float:
        """χ² of one value's residuals under the measured scatter (:attr:`measured_sd`): what
        the verdict compares the models by."""
        return self.chi2(residuals, self.measured_sd)

    @cached_property
    def shared_covariance(self) -> np.ndarray:
        """The model error's part of C, shared by every load: its offset, slope and modes
        (ln area²). The same at every random part, so built once."""
        x = np.log(np.asarray(self.loads_mn))
        centred = x - x.mean()
        error = self.model_error
        shared = error.offset_sd**2 * np.ones((self.n, self.n))
        shared += error.slope_sd**2 * np.outer(centred, centred)
        for mode in error.modes:
            shared += np.outer(mode, mode)
        return shared

    def covariance(self, random_sd: float) -> np.ndarray:
        """C: the random part ``random_sd``² on the diagonal and the model's shared offset,
        slope and modes (ln area²)."""
        return random_sd**2 * np.eye(self.n) + self.shared_covariance

    def corrected(self, residuals: Sequence[float]) -> np.ndarray:
        """The residuals ln A_sim − ln A_meas less the model's known bias."""
        r = np.asarray(residuals, dtype=float)
        if r.shape != (self.n,):
            raise ScanError(f"{r.size} residuals; the criterion has {self.n} loads")
        return r - np.asarray(self.model_error.bias)

    def chi2(self, residuals: Sequence[float], random_sd: float) -> float:
        """χ² of one value's residuals ln A_sim − ln A_meas (inf where one is inf)."""
        r = self.corrected(residuals)
        if not np.all(np.isfinite(r)):
            return float("inf")
        return float(r @ np.linalg.solve(self.covariance(random_sd), r))

    def random_sd_used(self, best_residuals: Sequence[float]) -> float:
        """The random part the scan is judged with: the measured scatter, or, where the best
        value misses by more than it and the model's error together allow (χ²_min above its
        n − 1 degrees of freedom), the scatter that brings χ²_min to n − 1 (the Birge ratio:
        the model's misfit, not the measurement, then sets the scatter, and a misfit does
        not shrink the interval). Floor :data:`SD_FLOOR`."""
        sd = self.measured_sd
        dof = self.n - 1
        if not self.chi2(best_residuals, sd) > dof:
            return sd
        # χ² falls monotonically as the random part grows, and C ≥ σ² I puts the root below
        # |r| / sqrt(n - 1)
        r = self.corrected(best_residuals)
        high = max(float(np.sqrt(r @ r / dof)), sd)
        excess = lambda s: self.chi2(best_residuals, s) - dof  # noqa: E731
        if excess(high) >= 0:  # no shared part: the root itself, up to rounding
            return high
        return float(optimize.brentq(excess, sd, high, xtol=1e-300))

    def effective_dof(self, direction: Sequence[float] | None, random_sd: float) -> float:
        """The degrees of freedom of the parameter's variance (Welch–Satterthwaite): n − 2
        where all of it comes from the estimated random part, more as the model's error,
        whose size is stated, not estimated, takes a larger share. ``direction``: how the
        residuals move per unit of ln v at the estimate (None: alike at every load). The
        variance of the estimate along it is V = 1 / (gᵀ C⁻¹ g), the random part's share
        f = σ² V gᵀ C⁻² g, and ν = (n − 2) / f²."""
        g = np.ones(self.n) if direction is None else np.asarray(direction, dtype=float)
        if not np.all(np.isfinite(g)) or not np.any(g):
            g = np.ones(self.n)
        inverse_g = np.linalg.solve(self.covariance(random_sd), g)
        variance = 1.0 / float(g @ inverse_g)
        share = random_sd**2 * variance * float(inverse_g @ inverse_g)
        return (self.n - 2) / min(share, 1.0) ** 2 if share > 0 else float("inf")

    def rise(
        self,
        confidence: float,
        direction: Sequence[float] | None = None,
        random_sd: float | None = None,
    ) -> float:
        """The rise of χ² above its minimum that bounds the interval at ``confidence``: the
        F(1, ν) quantile, ν the :meth:`effective_dof` along ``direction`` at ``random_sd``
        (the measured scatter where None): n − 2 without model error. χ²(1)'s under the
        ``"chi2"`` quantile."""
        if self.quantile == "chi2":
            return float(stats.chi2.ppf(confidence, 1))
        sd = self.measured_sd if random_sd is None else random_sd
        dof = self.effective_dof(direction, sd)
        if not np.isfinite(dof) or dof > 1e6:
            return float(stats.chi2.ppf(confidence, 1))
        return float(stats.f.ppf(confidence, 1, dof))
