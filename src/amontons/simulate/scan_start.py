"""A scan value's solution as the next value's start (docs/study.md §1, "Warm-started values").

Neighbouring values of a scan give neighbouring contacts, so a value's load series starts
each load from its neighbour's pressure at the same load instead of from its own previous
load scaled up. One job solves a sphere's scan, its values in a fixed order
(its parameter's chain order, :mod:`amontons.models`), and hands each value's pressures to the
next in memory.

The chain's first value has no neighbour in the scan. Where the chain starts at the scan's
elastic end (p_Y from its largest value down: the bound hardly binds there), its neighbour
is the sphere's elastic scene, the limit the model tends to, which the run solves anyway; so
that value starts from the elastic scene's pressures (:meth:`ScanStart.from_scene_fields`).

A start is matched load by load on the scene's own loads (N, as the scene lists them) and on
the solver window (shape, pixel and centre in the scan): a load the neighbour did not solve
(outside its scan, a contact that outgrew the window) starts as it would without a
neighbour, and so does every load after a value that solved nothing, and every load of a
window other than the neighbour's.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from amontons.io.fields import read_load_series_field

log = logging.getLogger(__name__)

# How close two loads (relative), two pixels (relative) and two window centres (in pixels)
# must be to be the same: a file stores them through mN, nm and µm, which moves their last
# bits; any real difference between windows or loads is many orders larger.
SAME_LOAD = 1e-9
SAME_PIXEL = 1e-9
SAME_CENTRE_PX = 1e-3


@dataclass(frozen=True)
class ScanStart:
    """The pressures (Pa, float64) one value solved, one per load of ``loads_n`` (N), on a
    window of ``pixel_m`` (m) centred at ``centre_m`` (m, in the AFM scan's frame); empty
    where it solved nothing."""

    loads_n: tuple[float, ...] = ()
    pressures: tuple[np.ndarray, ...] = ()
    pixel_m: float | None = None
    centre_m: tuple[float, float] | None = None

    @classmethod
    def of(
        cls,
        loads_n: Sequence[float],
        pressures: Sequence[np.ndarray],
        pixel_m: float,
        centre_m: Sequence[float],
    ) -> ScanStart:
        """A value's solution: ``pressures`` (Pa) at ``loads_n`` (N) on a window of
        ``pixel_m`` (m) centred at ``centre_m`` (m)."""
        if len(loads_n) != len(pressures):
            raise ValueError(
                f"a scan start holds one pressure per load: {len(loads_n)} loads, "
                f"{len(pressures)} pressures"
            )
        return cls(
            tuple(float(f) for f in loads_n),
            tuple(np.asarray(p, dtype=np.float64) for p in pressures),
            float(pixel_m),
            (float(centre_m[0]), float(centre_m[1])),
        )

    @classmethod
    def from_scene_fields(cls, path: str) -> ScanStart:
        """The pressures of a scene's solve (its fields file, rule simulate_scene: pressure
        per load in Pa, the loads in mN, the window's pixel in nm and centre in µm); empty
        where it solved no load (its window outside the AFM scan)."""
        pressures, per_load, settings = read_load_series_field(path, "pressure")
        if not pressures:
            return cls()
        return cls.of(
            [row["load_mn"] * 1e-3 for row in per_load],
            pressures,
            settings["pixel_nm"] * 1e-9,
            [c * 1e-6 for c in settings["window_centre_in_scan_um"]],
        )

    def starts_for(
        self,
        loads_n: Sequence[float],
        shape: tuple[int, int],
        pixel_m: float,
        centre_m: Sequence[float],
    ) -> tuple[list[np.ndarray | None], int]:
        """The neighbour's pressure (Pa) for each of ``loads_n`` (N) on a window of
        ``shape``, ``pixel_m`` (m) and centre ``centre_m`` (m), None where it has none; and
        how many loads it starts."""
        if self.loads_n and not self._same_window(pixel_m, centre_m):
            log.info(
                "the neighbour's window differs (pixel %s m, centre %s m): no warm start",
                self.pixel_m,
                self.centre_m,
            )
            return [None] * len(loads_n), 0
        starts = [self._pressure_at(float(f), tuple(shape)) for f in loads_n]
        return starts, sum(s is not None for s in starts)

    def _same_window(self, pixel_m: float, centre_m: Sequence[float]) -> bool:
        if not np.isclose(self.pixel_m, pixel_m, rtol=SAME_PIXEL, atol=0.0):
            return False
        shift = np.subtract(self.centre_m, [float(c) for c in centre_m])
        return bool(np.all(np.abs(shift) <= SAME_CENTRE_PX * pixel_m))

    def _pressure_at(self, load_n: float, shape: tuple[int, int]) -> np.ndarray | None:
        for load, pressure in zip(self.loads_n, self.pressures, strict=True):
            if np.isclose(load, load_n, rtol=SAME_LOAD, atol=0.0) and pressure.shape == shape:
                return pressure
        return None
