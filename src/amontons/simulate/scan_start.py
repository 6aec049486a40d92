"""A scan value's solution as the next value's start (docs/study.md §1, "Warm-started values").

Neighbouring values of a scan give neighbouring contacts, so a value's load series starts
each load from its neighbour's pressure at the same load instead of from its own previous
load scaled up. One job solves a sphere's scan, its values in a fixed order
(:data:`amontons.workflow.scenes.SCAN_CHAIN_ORDER`), and hands each value's pressures to the
next in memory.

A start is matched load by load on the scene's own loads (N, as the scene lists them) and on
the solver grid (shape and pixel): a load the neighbour did not solve (outside its scan, a
contact that outgrew the window) starts as it would without a neighbour, and so does every
load after a value that solved nothing.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ScanStart:
    """The pressures (Pa, float64) one value solved, one per load of ``loads_n`` (N), on a
    grid of ``pixel_m`` (m); empty where it solved nothing."""

    loads_n: tuple[float, ...] = ()
    pressures: tuple[np.ndarray, ...] = ()
    pixel_m: float | None = None

    @classmethod
    def of(
        cls, loads_n: Sequence[float], pressures: Sequence[np.ndarray], pixel_m: float
    ) -> ScanStart:
        """A value's solution: ``pressures`` (Pa) at ``loads_n`` (N) on ``pixel_m`` (m)."""
        if len(loads_n) != len(pressures):
            raise ValueError(
                f"a scan start holds one pressure per load: {len(loads_n)} loads, "
                f"{len(pressures)} pressures"
            )
        return cls(
            tuple(float(f) for f in loads_n),
            tuple(np.asarray(p, dtype=np.float64) for p in pressures),
            float(pixel_m),
        )

    def starts_for(
        self, loads_n: Sequence[float], shape: tuple[int, int], pixel_m: float
    ) -> tuple[list[np.ndarray | None], int]:
        """The neighbour's pressure (Pa) for each of ``loads_n`` (N) on a grid of ``shape``
        and ``pixel_m`` (m), None where it has none; and how many loads it starts."""
        if self.loads_n and self.pixel_m != pixel_m:
            log.info("the neighbour's grid differs (pixel %s m): no warm start", self.pixel_m)
            return [None] * len(loads_n), 0
        found = {
            load: pressure
            for load, pressure in zip(self.loads_n, self.pressures, strict=True)
            if pressure.shape == tuple(shape)
        }
        starts = [found.get(float(f)) for f in loads_n]
        return starts, sum(s is not None for s in starts)
