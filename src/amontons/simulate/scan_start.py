"""A scan value's solution as the next value's start (docs/study.md §1, "Warm-started values").

Neighbouring values of a scan give neighbouring contacts, so a value's load series starts
each load from its neighbour's pressure at the same load instead of from its own previous
load scaled up. The values of one sphere's scan run as a chain in a fixed order
(:data:`amontons.workflow.scenes.SCAN_CHAIN_ORDER`); each writes its pressures (Pa, one
group per load, in HDF5 through :func:`amontons.io.fields.write_load_series`) for the next.

A start is matched load by load on the scene's own loads (N, as the scene lists them) and on
the solver grid (shape and pixel): a load the neighbour did not solve (outside its scan, a
contact that outgrew the window) starts as it would without a neighbour. A neighbour that
solved nothing leaves a file with no load, so that the chain's files always exist.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from amontons.io.fields import read_load_series, write_load_series

log = logging.getLogger(__name__)


def write_scan_start(
    path: str | Path,
    loads_n: Sequence[float],
    pressures: Sequence[np.ndarray],
    pixel_m: float | None,
    value: float,
) -> None:
    """The pressures (Pa, float64) a value solved, one per load of ``loads_n`` (N), on a grid
    of ``pixel_m`` (m); empty sequences where it solved nothing."""
    write_load_series(
        path,
        [{"pressure": np.asarray(p, dtype=np.float64)} for p in pressures],
        [{"load_n": float(f)} for f in loads_n],
        {"value": float(value), "pixel_m": pixel_m},
    )


def read_scan_start(
    path: str | Path, loads_n: Sequence[float], shape: tuple[int, int], pixel_m: float
) -> tuple[list[np.ndarray | None], int]:
    """The neighbour's pressure (Pa) for each of ``loads_n`` (N) on a grid of ``shape`` and
    ``pixel_m`` (m), None where it has none; and how many loads it starts."""
    fields, per_load, attrs = read_load_series(path)
    if fields and attrs.get("pixel_m") != pixel_m:
        log.info("%s: the neighbour's grid differs (pixel %s m): no warm start", path, pixel_m)
        return [None] * len(loads_n), 0
    found = {
        info["load_n"]: f["pressure"]
        for f, info in zip(fields, per_load, strict=True)
        if f["pressure"].shape == tuple(shape)
    }
    starts = [found.get(float(f)) for f in loads_n]
    return starts, sum(s is not None for s in starts)
