"""Which contact models a sphere's data tell apart (docs/study.md §6, "The decision"): the
models compared by the scans' χ² of the rendered against the measured areas at every load,
under the measured scatter and each model's own measured error
(:mod:`amontons.simulate.scan_criterion`). Areas and exponent together: a model whose
areas follow another law, or sit at another level, misses at some loads.

- Each scanned plastic model's χ² is its best value's. The **elastic limit**'s is the least
  of the scans' χ² at their elastic ends (their highest values, the most nearly elastic
  contacts they solved; a model truly elastic is further still, so this keeps the elastic
  model wherever any plastic model's own elastic end is kept).
- χ² is taken under the measured scatter, scaled by the best model's Birge ratio where that
  model misses by more than the errors allow (χ²_min over n − 1 degrees of freedom), so that
  every model is judged under the same errors.
- A model is **excluded** where its χ² lies above the least by more than the scans'
  quantile (the larger of the scans' interval quantiles). A model is **named** only where every
  other model is excluded; otherwise the answer is "not decided", with the models the data
  cannot tell apart and the difference against the quantile.

Pure Python: the verdict job imports no statistics.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from amontons.models import ELASTIC as ELASTIC_MODEL

__all__ = ["ELASTIC", "Decision", "decide"]

# The model every scan's elastic end approaches (the decision's reference).
ELASTIC = ELASTIC_MODEL.name


@dataclass(frozen=True)
class Decision:
    """The models the data keep (one: decided), every model's scaled Δχ² against the best,
    the quantile and why."""

    kept: tuple[str, ...]
    delta_chi2: dict[str, float]
    rise: float
    why: str

    @property
    def decided(self) -> bool:
        return len(self.kept) == 1


def decide(
    best_chi2: Mapping[str, float], elastic_end_chi2: Mapping[str, float], rise: float, n: int
) -> Decision:
    """The decision between the scanned plastic models (``best_chi2``: model → χ² at its best
    value under the measured scatter) and the elastic limit (``elastic_end_chi2``: model →
    χ² at its scan's elastic end), at the quantile's ``rise`` over ``n`` loads."""
    if not best_chi2:
        return Decision((), {}, rise, "no scan judged")
    chi2 = dict(best_chi2)
    chi2[ELASTIC] = min(elastic_end_chi2.values())
    least = min(chi2.values())
    birge = max(1.0, least / max(n - 1, 1))
    delta = {model: (value - least) / birge for model, value in chi2.items()}
    kept = tuple(sorted((m for m, d in delta.items() if d <= rise), key=lambda m: delta[m]))
    excluded = [m for m in chi2 if m not in kept]
    if len(kept) == 1:
        nearest = min((delta[m] for m in excluded), default=float("inf"))
        why = (
            f"every other model's χ² lies above it by {nearest:.3g} or more, beyond the "
            f"quantile's {rise:.3g}"
        )
    else:
        spread = max(delta[m] for m in kept)
        why = (
            f"their χ² lie within {spread:.3g} of each other, inside the quantile's {rise:.3g}: "
            "the areas' difference between them is below the measured scatter and the "
            "models' error"
        )
    if birge > 1:
        why += f" (χ² scaled by the best model's misfit, Birge ratio² {birge:.3g})"
    return Decision(kept, delta, rise, why)
