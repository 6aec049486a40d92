"""Which contact models a sphere's data tell apart (docs/study.md §6, "The decision"): the
models compared by the scans' χ² of the rendered against the measured areas at every load,
under the measured scatter and each model's own measured error
(:mod:`amontons.simulate.scan_criterion`). Areas and exponent together: a model whose
areas follow another law, or sit at another level, misses at some loads.

The models are **nested**: elastic is the limit of both plastic models (p_Y → ∞, k → ∞), so
a plastic scan can always come as close to the elastic χ² as its elastic end allows, and a
rule that names a model only where it alone is kept could never name elastic. The decision
reads them as a likelihood ratio reads nested models:

- **The elastic limit** is the elastic model itself, solved on each scan's window and judged
  with the elastic model's own measured error (``elastic_chi2``), and the scan's own elastic
  end, judged with the plastic model's error (``elastic_end_chi2``).
- **Flow is detected** where a plastic model's χ² at its best value lies below both by more
  than the quantile (one parameter more): the elastic model judged with its own error, and
  its own scan's profile, so that a scan whose interval is open above never reports flow.
  Where none does, the answer is **elastic**, and each plastic parameter is stated as the
  one-sided bound its scan sets (p_Y ≥ X, k ≥ Y: the values the data exclude).
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


def _finite(value) -> bool:
    return value is not None and math.isfinite(value)


def _elastic_references(
    best_chi2: Mapping[str, float],
    elastic_end_chi2: Mapping[str, float],
    elastic_chi2: Mapping[str, float] | None,
) -> tuple[dict[str, float], str]:
    """Each plastic model's elastic reference: the smaller of the elastic model's χ² on its
    scan's window (judged with the elastic model's own error) and its scan's elastic end's
    (judged with its own error), so that flow is detected only where the plastic model beats
    elastic under both errors; and a note where a scan has no elastic solve judged."""
    own = elastic_chi2 or {}
    references, missing = {}, []
    for model in best_chi2:
        pair = [v for v in (own.get(model), elastic_end_chi2.get(model)) if _finite(v)]
        if not _finite(own.get(model)):
            missing.append(model)
        if pair:
            references[model] = min(pair)
    note = (
        f" (no elastic solve judged on the window of {', '.join(missing)}: its elastic limit "
        "is its scan's elastic end, judged with its own error)"
        if missing
        else ""
    )
    return references, note


def decide(
    best_chi2: Mapping[str, float],
    elastic_end_chi2: Mapping[str, float],
    rise: float,
    n: int,
    elastic_chi2: Mapping[str, float] | None = None,
) -> Decision:
    """The decision between the scanned plastic models (``best_chi2``: model → χ² at its best
    value under the measured scatter) and the elastic model, at the quantile's ``rise`` over
    ``n`` loads. The elastic model is judged on each scan's window by ``elastic_chi2`` (model
    → the elastic model's own χ² there, with its own error) and ``elastic_end_chi2`` (model →
    χ² at its scan's elastic end): a plastic model detects flow only where its χ² lies below
    both by more than the quantile (:func:`_elastic_references`)."""
    if not best_chi2:
        return Decision((), {}, rise, "no scan judged", {})
    references, note = _elastic_references(best_chi2, elastic_end_chi2, elastic_chi2)
    if not references:
        raise ValueError("no elastic χ² to judge the elastic model by: neither an elastic solve "
                         "nor a scan's elastic end")  # fmt: skip
    elastic = min(references.values())
    chi2 = {**best_chi2, ELASTIC: elastic}
    least = min(chi2.values())
    birge = max(1.0, least / max(n - 1, 1))
    delta = {model: (value - least) / birge for model, value in chi2.items()}
    flow = {m: (references[m] - best_chi2[m]) / birge for m in references}
    if max(flow.values()) <= rise:
        kept = (ELASTIC,)
        why = (
            f"no flow detected: no plastic model improves on the elastic model by more than "
            f"the quantile's {rise:.3g} (the largest gain in χ² is {max(flow.values()):.3g}); "
            + _bounded_above_note(best_chi2, elastic_end_chi2, birge, rise)
        )
    else:
        kept = tuple(sorted((m for m in best_chi2 if delta[m] <= rise), key=lambda m: delta[m]))
        why = _plastic_why(kept, delta, flow, rise)
    if birge > 1:
        why += f" (χ² scaled by the best model's misfit, Birge ratio² {birge:.3g})"
    return Decision(kept, delta, rise, why + note, flow)


def _bounded_above_note(
    best_chi2: Mapping[str, float],
    elastic_end_chi2: Mapping[str, float],
    birge: float,
    rise: float,
) -> str:
    """Where elastic is named: that the data bound no plastic parameter from above, or which
    scans do so all the same, judged with the error measured at their best value, while the
    elastic model, judged with its own, is not excluded (the two errors disagree: the scan's
    bound is not the verdict's)."""
    bounded = [
        m
        for m, end in elastic_end_chi2.items()
        if _finite(end) and (end - best_chi2[m]) / birge > rise
    ]
    if not bounded:
        return "the data bound no plastic parameter from above"
    return (
        f"the scan of {', '.join(bounded)} bounds its parameter from above all the same, "
        "judged with the error measured at its best value; the elastic model, judged with "
        "its own, is not excluded: the two errors disagree"
    )


def _plastic_why(
    kept: tuple[str, ...], delta: Mapping[str, float], flow: Mapping[str, float], rise: float
) -> str:
    """Why, where flow is detected: elastic excluded by the largest gain, then the plastic
    models named or not told apart."""
    gain = max(flow.values())
    excluded = f"flow detected: a plastic model improves on the elastic model by {gain:.3g} in χ²"
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
