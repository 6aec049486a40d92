"""Which contact models a sphere's data tell apart (docs/study.md §6, "The decision"): the
models compared by the scans' χ² of the rendered against the measured areas at every load,
under the measured scatter and each model's own measured error
(:mod:`amontons.simulate.scan_criterion`). Areas and exponent together: a model whose
areas follow another law, or sit at another level, misses at some loads.

The models are **nested**: elastic is the limit of both plastic models (p_Y → ∞, k → ∞), so
a plastic scan can always come as close to the elastic χ² as its elastic end allows, and a
rule that names a model only where it alone is kept could never name elastic. The decision
reads them as a likelihood ratio reads nested models:

- **The elastic limit** is the elastic model itself, solved on the scan's window and judged
  with the elastic model's own measured error (``elastic_chi2``; the scans' elastic ends,
  judged with a plastic model's error, only where no elastic solve was judged).
- **Flow is detected** where a plastic model's χ² at its best value lies below the elastic
  χ² by more than the quantile (one parameter more). Where none does, the answer is
  **elastic**, and each plastic parameter is stated as the one-sided bound its scan sets
  (p_Y ≥ X, k ≥ Y: the values the data exclude).
- Where flow is detected, elastic is excluded, and the plastic models are compared with
  each other (not nested): one is **excluded** where its χ² lies above the least by more
  than the quantile, and a model is **named** only where every other plastic model is
  excluded; otherwise the answer is "not decided", with the models the data cannot tell
  apart and the difference against the quantile.
- χ² is taken under the measured scatter, scaled by the best model's Birge ratio where that
  model misses by more than the errors allow (χ²_min over n − 1 degrees of freedom), so that
  every model is judged under the same scatter. The quantile is the larger of the scans'
  interval quantiles.

Pure Python: the verdict job imports no statistics.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from amontons.models import ELASTIC as ELASTIC_MODEL

__all__ = ["ELASTIC", "Decision", "decide"]

# The model every scan's elastic end approaches (the nested models' common limit).
ELASTIC = ELASTIC_MODEL.name


@dataclass(frozen=True)
class Decision:
    """The models the data keep (one: decided), every model's scaled Δχ² against the best,
    each plastic model's scaled χ² gain over the elastic limit (``flow``), the quantile and
    why."""

    kept: tuple[str, ...]
    delta_chi2: dict[str, float]
    rise: float
    why: str
    flow: dict[str, float]

    @property
    def decided(self) -> bool:
        return len(self.kept) == 1

    @property
    def elastic(self) -> bool:
        """Whether the answer is elastic: no plastic model improves on the elastic limit by
        more than the quantile."""
        return self.kept == (ELASTIC,)


def _elastic_reference(
    elastic_chi2: float | None, elastic_end_chi2: Mapping[str, float]
) -> tuple[float, str]:
    """The elastic limit's χ² and a note where it is not the elastic model's own: the least
    of the scans' elastic ends, judged with a plastic model's error, where no elastic solve
    was judged."""
    if elastic_chi2 is not None and math.isfinite(elastic_chi2):
        return elastic_chi2, ""
    return min(elastic_end_chi2.values()), (
        " (no elastic solve judged: the elastic limit is the scans' elastic end, judged with "
        "a plastic model's error)"
    )


def decide(
    best_chi2: Mapping[str, float],
    elastic_end_chi2: Mapping[str, float],
    rise: float,
    n: int,
    elastic_chi2: float | None = None,
) -> Decision:
    """The decision between the scanned plastic models (``best_chi2``: model → χ² at its best
    value under the measured scatter) and the elastic model (``elastic_chi2``: its own χ²,
    judged with its own error; where None, the least of ``elastic_end_chi2``, model → χ² at
    its scan's elastic end), at the quantile's ``rise`` over ``n`` loads."""
    if not best_chi2:
        return Decision((), {}, rise, "no scan judged", {})
    elastic, note = _elastic_reference(elastic_chi2, elastic_end_chi2)
    chi2 = {**best_chi2, ELASTIC: elastic}
    least = min(chi2.values())
    birge = max(1.0, least / max(n - 1, 1))
    delta = {model: (value - least) / birge for model, value in chi2.items()}
    flow = {model: (elastic - value) / birge for model, value in best_chi2.items()}
    if max(flow.values()) <= rise:
        kept = (ELASTIC,)
        gain = max(flow.values())
        why = (
            f"no flow detected: no plastic model improves on the elastic model by more than "
            f"the quantile's {rise:.3g} (the largest gain in χ² is {gain:.3g}); the plastic "
            "parameters are bounded on one side only"
        )
    else:
        kept = tuple(sorted((m for m in best_chi2 if delta[m] <= rise), key=lambda m: delta[m]))
        why = _plastic_why(kept, delta, flow, rise)
    if birge > 1:
        why += f" (χ² scaled by the best model's misfit, Birge ratio² {birge:.3g})"
    return Decision(kept, delta, rise, why + note, flow)


def _plastic_why(
    kept: tuple[str, ...], delta: Mapping[str, float], flow: Mapping[str, float], rise: float
) -> str:
    """Why, where flow is detected: elastic excluded by the largest gain, then the plastic
    models named or not told apart."""
    gain = max(flow.values())
    excluded = f"flow detected: the elastic model's χ² lies {gain:.3g} above the best"
    if len(kept) == 1:
        others = [d for m, d in delta.items() if m not in kept and m != ELASTIC]
        nearest = min(others, default=float("inf"))
        return (
            f"{excluded}, and every other plastic model's {nearest:.3g} or more, beyond the "
            f"quantile's {rise:.3g}"
        )
    spread = max(delta[m] for m in kept)
    return (
        f"{excluded}, beyond the quantile's {rise:.3g}; the plastic models' χ² lie within "
        f"{spread:.3g} of each other, inside it: the areas' difference between them is below "
        "the measured scatter and the models' error"
    )
