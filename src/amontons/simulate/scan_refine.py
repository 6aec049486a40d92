"""A scan's grid refined where its answer is read (docs/study.md §1, "Refinement"): the
coarse grid finds the basin; more values are then solved at the estimate and at each end of
its interval, round after round, until a round's new solved values no longer move any of them
by more than ``fraction`` of the interval's width in ln v. The interval is then read off
solved values close about each target, not off an interpolation across a coarse step.

Each round judges the values solved so far
(:func:`amontons.simulate.scan_best.best_scan_value`) and solves each target that no solved
value lies within half the allowed movement of (rounded to its 4-digit folder label).
``max_values`` bounds the cost; a scan that reaches it says so, with how far each target
moved in its last round.
"""

from __future__ import annotations

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

__all__ = ["Refinement", "movement_ln", "refine_scan", "refinement_values"]


def refinement_values(best: ScanBest, solved: Sequence[float], near_ln: float) -> list[float]:
    """The targets of ``best`` (its estimate and closed ends) to solve next, rounded to their
    folder labels: those with no solved value within ``near_ln`` in ln v."""
    done = np.log(np.asarray(solved, dtype=float))
    proposals = []
    for target in best_targets(best).values():
        value = float(value_label(target))
        if np.min(np.abs(done - np.log(value))) > near_ln and value not in proposals:
            proposals.append(value)
    return sorted(proposals)


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
        return self.stopped != MAX_VALUES

    def to_record(self) -> dict:
        return {
            "refined_values": list(self.values),
            "rounds": self.rounds,
            "last_movement_ln": self.movement_ln,
            "allowed_movement_ln": self.allowed_ln,
            "resolution": self.resolution,
            "stopped": self.stopped,
            "resolved": self.resolved,
        }


CONVERGED = "converged: the last round moved no target by more than the allowed fraction"
AT_SOLVED = "every target lies at a solved value"
MAX_VALUES = "max_values reached before the targets stopped moving"


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
    rounds = 0
    while True:
        best = best_scan_value(points, criterion, confidence, grid)
        solved = [p.value for p in points]
        allowed = fraction * interval_width_ln(best, solved)
        if before is not None:
            moved = movement_ln(before, best)
            if all(m <= allowed for m in moved.values()):
                stopped = CONVERGED
                break
        proposals = refinement_values(best, solved, allowed / 2)
        if not proposals:
            stopped = AT_SOLVED
            break
        if len(added) + len(proposals) > max_values:
            stopped = MAX_VALUES
            break
        for value in proposals:
            points.append(solve(value))
            added.append(value)
        rounds += 1
        before = best
    return points, Refinement(
        tuple(added), rounds, moved, allowed, interval_resolution(solved, best), stopped
    )
