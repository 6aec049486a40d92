"""The simulated flattening beside the measured one (docs/study.md, Fig. B.9): the solver
window cut out of the AFM scans, and the depth and place of a flattened region, by one
definition for both."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from amontons.physics.roughness import flattening_depth


def window_slices(
    shape: Sequence[int], pixel_m: float, centre_m: Sequence[float], window_m: float
) -> tuple[slice, slice]:
    """The pixels of a scan of ``shape`` (pixel ``pixel_m``) inside the solver window: side
    ``window_m`` about ``centre_m`` (row, col; m from the scan centre), clipped to the scan."""
    half = window_m / 2 / pixel_m
    out = []
    for n, c in zip(shape, centre_m, strict=True):
        mid = (n - 1) / 2 + c / pixel_m
        out.append(slice(max(0, int(round(mid - half))), min(n, int(round(mid + half)))))
    return out[0], out[1]


def flattened_region(
    drop_m: np.ndarray, smoothing_px: float, floor_m: float
) -> tuple[float | None, np.ndarray, tuple[float, float] | None]:
    """Depth (m; None if nothing passes ``floor_m``), the flattened pixels and their centre
    (row, col px) of a map of how far the surface went down (m): the depth definition of
    :func:`amontons.physics.roughness.flattening_depth`."""
    depth, core = flattening_depth(drop_m, smoothing_px=smoothing_px, floor_m=floor_m)
    if depth is None or not core.any():
        return None, core, None
    rows, cols = np.nonzero(core)
    return depth, core, (float(rows.mean()), float(cols.mean()))


def offset_from_centre_m(
    point_px: tuple[float, float] | None, shape: Sequence[int], pixel_m: float
) -> tuple[float, float] | None:
    """A pixel position as (row, col) m from the centre of a map of ``shape``."""
    if point_px is None:
        return None
    row, col = ((p - (n - 1) / 2) * pixel_m for p, n in zip(point_px, shape, strict=True))
    return row, col
