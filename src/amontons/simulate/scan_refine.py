"""A scan's grid refined where its answer is read (docs/study.md §1, "Refinement"): the
coarse grid finds the basin; more values are then solved at the estimate and at each end of
its interval, round after round, until a round's new solved values no longer move any of them
by more than ``fraction`` of the interval's width in ln v. The interval is then read off
solved values close about each target, not off an interpolation across a coarse step.

Each round judges the values solved so far
(:func:`amontons.simulate.scan_best.best_scan_value`) and solves each target that no solved
value lies within half the allowed movement of (rounded to its 4-digit folder label; after
the first round, only the targets the last round still moved by more than allowed); and,
where an end of the interval lies next to a value whose contact left the window (no χ² to
interpolate), bisects between the two until they lie within the allowed movement.
``max_values`` bounds the cost; a scan that reaches it says so, with how far each target
moved in its last round.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from amontons.simulate.scan_best import (
    ScanBest,
    ScanPoint,
    best_scan_value,
    best_targets,
    interval_resolution,
    interval_width_ln,
)
from amontons.simulate.scan_criterion import Criterion
from amontons.simulate.scan_grid import value_label

__all__ = ["Refinement", "gap_values", "movement_ln", "refine_scan", "target_values"]


def target_values(
    best: ScanBest, solved: Sequence[float], near_ln: float, names: Sequence[str] | None = None
) -> list[float]:
    """Each target of ``best`` (its estimate and closed ends; only those ``names``, where
    given) with no solved value within ``near_ln`` in ln v, rounded to its folder label."""
    done = np.log(np.asarray(solved, dtype=float))
    targets = best_targets(best)
    values = [float(value_label(t)) for n, t in targets.items() if names is None or n in names]
    return [v for v in values if np.min(np.abs(done - np.log(v))) > near_ln]


def gap_values(
    best: ScanBest, solved: Sequence[float], near_ln: float, unsolvable: Sequence[float]
) -> list[float]:
    """Where an end of the interval lies at a value whose contact left the window
    (``unsolvable``: no χ², so the crossing lies somewhere between it and the solved value
    inside, and the interval keeps the whole step), the value halfway between the two in
    ln v, while they lie more than ``2 near_ln`` apart."""
    values = []
    for end, step in ((best.scatter_low, -1), (best.scatter_high, +1)):
        if end is None or not any(abs(math.log(v / end)) <= 1e-9 for v in unsolvable):
            continue
        inner = _outer_neighbour(solved, end, -step)
        if inner is not None and abs(math.log(end / inner)) > 2 * near_ln:
            values.append(float(value_label(math.sqrt(inner * end))))
    return values


def _outer_neighbour(solved: Sequence[float], end: float, step: int) -> float | None:
    """The solved value next beyond an interval's ``end`` on the side ``step`` (-1: below)."""
    # beyond by more than rounding: an end read off a solved value lies at it to ~1e-16
    beyond = [v for v in solved if math.log(v / end) * step > 1e-9]
    if not beyond:
        return None
    return min(beyond) if step > 0 else max(beyond)


def movement_ln(before: ScanBest, after: ScanBest) -> dict[str, float]:
    """How far each target moved between two judgements, in ln v (inf where an end opened or
    closed)."""
    old, new = best_targets(before), best_targets(after)
    return {
        name: float(abs(np.log(new[name] / old[name]))) if name in old else float("inf")
        for name in new
    } | {name: float("inf") for name in old if name not in new}


@dataclass(frozen=True)
class Refinement:
    """What refining a scan did: the values it solved, in order; the rounds; how far each
    target moved in the last round against what is allowed; why it stopped."""

    values: tuple[float, ...]
    rounds: int
    movement_ln: dict
    allowed_ln: float
    resolution: dict
    stopped: str

    @property
    def resolved(self) -> bool:
        return self.stopped in (CONVERGED, AT_SOLVED, NEAR_SOLVED)

    def to_record(self) -> dict:
        # an end that opened or closed moved without bound: null, not an infinite number
        moved = {k: (m if math.isfinite(m) else None) for k, m in self.movement_ln.items()}
        return {
            "refined_values": list(self.values),
            "rounds": self.rounds,
            "last_movement_ln": moved,
            "allowed_movement_ln": self.allowed_ln,
            "resolution": self.resolution,
            "stopped": self.stopped,
            "resolved": self.resolved,
        }


CONVERGED = (
    "converged: the last round moved no target by more than the allowed fraction, and no "
    "end lies next to an unsolvable value further than that"
)
AT_SOLVED = "every target lies at or near a solved value"
NEAR_SOLVED = (
    "the targets the last round still moved lie within half the allowed movement of a solved "
    "value: the interpolation about them cannot move them further than that"
)
MAX_VALUES = "max_values reached before the targets stopped moving"
OFF = "refinement off (max_values 0): the interval is read off the coarse grid"


def _settled(first_round: bool, moving: Sequence[str]) -> str:
    """Why refinement stops with nothing left to solve: every target at a solved value before
    any round; targets that still moved but lie near solved values; or converged."""
    if first_round:
        return AT_SOLVED
    return NEAR_SOLVED if moving else CONVERGED


def refine_scan(
    points: Sequence[ScanPoint],
    criterion: Criterion,
    confidence: float,
    solve: Callable[[float], ScanPoint],
    fraction: float,
    max_values: int,
) -> tuple[list[ScanPoint], Refinement]:
    """``points`` (the coarse grid, solved) with the values refinement adds, each solved by
    ``solve`` (value → its point), until a round moves no target by more than ``fraction``
    of the interval's width (ln v), or ``max_values`` are solved; and what it did."""
    points = list(points)
    grid = [p.value for p in points]
    added: list[float] = []
    before = None
    moved: dict[str, float] = {}
    moving: list[str] = []
    rounds = 0
    while True:
        best = best_scan_value(points, criterion, confidence, grid)
        solved = [p.value for p in points]
        allowed = fraction * interval_width_ln(best, solved)
        unsolvable = [p.value for p in points if not np.all(np.isfinite(p.residuals))]
        if before is not None:  # after the first round, only the targets the last round
            # still moved by more than allowed (an end that opened is a bound now)
            moved = movement_ln(before, best)
            moving = [n for n, m in moved.items() if m > allowed and n in best_targets(best)]
        proposals = gap_values(best, solved, allowed / 2, unsolvable) + target_values(
            best, solved, allowed / 2, None if before is None else moving
        )
        proposals = sorted(set(proposals) - {float(value_label(v)) for v in solved})
        if not proposals:
            stopped = _settled(before is None, moving)
            break
        if len(added) + len(proposals) > max_values:
            stopped = OFF if max_values == 0 else MAX_VALUES
            break
        for value in proposals:
            points.append(solve(value))
            added.append(value)
        rounds += 1
        before = best
    return points, Refinement(
        tuple(added), rounds, moved, allowed, interval_resolution(solved, best), stopped
    )
