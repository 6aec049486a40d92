"""Scan-line offsets of an AFM height map (docs/models.md §1.8): found, and removed only when
they are there.

An AFM writes a map line by line; the map's rows are its scan lines (fast axis along x). A
feedback jump or a tip change shifts a line, or every line after it, by a constant. The
classic remedy (Gwyddion's "median of differences") aligns every row to the previous one by
the median of their differences. On a map without offsets that does harm: each row's median
carries noise, and their running sum is a random walk along y that bends the sphere (on a
25.6 µm scan of a 1.25 mm sphere, 65-130 nm of sag, it triples the scatter of the fitted
radius). So by default (``auto``) only the steps between rows that stand out of the map's own
step scatter are taken as offsets.

Heights in m; a map is indexed [row, column] = [y, x].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

LINE_LEVELLING_MODES = ("auto", "on", "off")

# A step between rows is an offset when it stands this many robust standard deviations of the
# column-to-column steps away from its neighbours' trend. For normal scatter 6 sd leaves a
# false offset in one map of ~10⁶ rows; the step medians of rough or flattened scans have
# heavier tails (5.4 sd seen on the virtual glass sphere's difference of scans), and a missed
# offset this small is within the scatter of the rows anyway.
STEP_THRESHOLD_SD = 6.0
# Running median that carries the smooth part of the steps (form the sphere fit left, long
# roughness waves): 9 rows ignore the two opposite steps of a single shifted line.
_TREND_ROWS = 9
# The rows are offset throughout (not at a few lines) when their steps' robust sd exceeds this
# many step-noise sd: without offsets the ratio is 1 (±7 % over 256 rows; a few shifted lines
# move it by ~10 %), with a 2 nm offset on every row of a 1 nm-noise map ~25.
THROUGHOUT_RATIO = 1.5
_MAD_TO_SD = 1.4826  # σ of a normal population per median absolute deviation
_MIN_LINES = 2 * _TREND_ROWS
# A block of at most this many shifted rows (half the trend window) is bounded by a step and
# its way back whatever their sum: over so few rows it is the local slope, not an offset.
_SHORT_BLOCK_ROWS = _TREND_ROWS // 2  # rows and columns needed to tell a step from the trend


class ScanLineError(ValueError):
    """A height map or setting with which scan lines cannot be levelled."""


@dataclass(frozen=True)
class LineLevelling:
    """What was done to a map's scan lines.

    ``offsets_m`` per row (m, removed from the map; zeros when nothing was applied),
    ``stepped_rows`` the number of row-to-row steps taken as offsets, ``every_row`` whether
    every row was aligned to the previous one (``on``, or ``auto`` on rows offset
    throughout), ``step_noise_m`` the robust sd of the column-to-column steps against which
    a step is judged (m).
    """

    mode: str
    applied: bool
    offsets_m: np.ndarray
    stepped_rows: int
    every_row: bool
    step_noise_m: float

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names."""
        return {
            "mode": self.mode,
            "applied": self.applied,
            "stepped_rows": self.stepped_rows,
            "every_row_aligned": self.every_row,
            "row_offset_rms_nm": float(np.sqrt(np.mean(self.offsets_m**2))) * 1e9,
            # None when the mode ('off') judged no step
            "step_threshold_nm": (
                STEP_THRESHOLD_SD * self.step_noise_m * 1e9
                if np.isfinite(self.step_noise_m)
                else None
            ),
        }


def line_levelling_mode(value: str | bool) -> str:
    """The mode named by a config value: 'auto', 'on' or 'off'; True and False (YAML's reading
    of an unquoted on and off) mean 'on' and 'off'."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if value not in LINE_LEVELLING_MODES:
        raise ScanLineError(
            f"line levelling '{value}'; expected one of {', '.join(LINE_LEVELLING_MODES)}"
        )
    return value


def row_steps(residual: np.ndarray) -> np.ndarray:
    """Median of the differences between each row and the next (ny − 1 values), m."""
    return np.median(np.diff(residual, axis=0), axis=1)


def column_steps(residual: np.ndarray) -> np.ndarray:
    """Median of the differences between each column and the next (nx − 1 values), m."""
    return np.median(np.diff(residual, axis=1), axis=0)


def _detrended(steps: np.ndarray) -> np.ndarray:
    return steps - ndimage.median_filter(steps, size=_TREND_ROWS, mode="nearest")


def _robust_sd(values: np.ndarray) -> float:
    return float(_MAD_TO_SD * np.median(np.abs(values - np.median(values))))


def step_noise(residual: np.ndarray) -> float:
    """The scatter (m) a row-to-row step would have without offsets.

    Offsets shift rows, never columns, and roughness and noise look the same along both axes
    of an isotropic surface: so the column-to-column steps, detrended as the row steps are,
    show the scatter of an unshifted row step. Their robust sd is scaled from a median over
    ny values to one over nx values (√(ny/nx)).
    """
    ny, nx = residual.shape
    return _robust_sd(_detrended(column_steps(residual))) * np.sqrt(ny / nx)


@dataclass(frozen=True)
class _JudgedSteps:
    """Row-to-row steps (m), whether each stands out, and the step noise (m)."""

    steps: np.ndarray
    outstanding: np.ndarray
    noise: float

    @property
    def offset_throughout(self) -> bool:
        """Whether most rows are offset, not a few: the typical row step (robust sd, which a
        minority of outstanding steps does not move) then scatters more than an unshifted
        step would, i.e. than the column steps do."""
        return _robust_sd(_detrended(self.steps)) > THROUGHOUT_RATIO * self.noise


def judge_steps(residual: np.ndarray) -> _JudgedSteps:
    """The row-to-row steps of ``residual`` and which stand out: more than
    ``STEP_THRESHOLD_SD`` × :func:`step_noise` from the running median of their neighbours."""
    steps = row_steps(residual)
    noise = step_noise(residual)
    return _JudgedSteps(steps, np.abs(_detrended(steps)) > STEP_THRESHOLD_SD * noise, noise)


def outstanding_steps(residual: np.ndarray) -> tuple[np.ndarray, float]:
    """The row-to-row offset steps (m; zero where a step does not stand out,
    :func:`judge_steps`) and the step noise (m).

    A step's size is the step less the mean of the nearest ordinary steps on either side:
    the surface's own slope along y at that row, which correlates over a few rows (a running
    median of more rows leaves up to the roughness step scatter in it).
    """
    judged = judge_steps(residual)
    return _less_local_slope(judged.steps, judged.outstanding), judged.noise


def _less_local_slope(steps: np.ndarray, outstanding: np.ndarray) -> np.ndarray:
    ordinary = np.flatnonzero(~outstanding)
    sizes = np.zeros_like(steps)
    if ordinary.size == 0:
        return sizes
    for row in np.flatnonzero(outstanding):
        below = ordinary[ordinary < row]
        above = ordinary[ordinary > row]
        neighbours = [steps[side] for side in (below[-1:], above[:1]) if side.size]
        sizes[row] = steps[row] - np.mean(neighbours)
    return sizes


def _offsets_from_steps(steps: np.ndarray) -> np.ndarray:
    """Row offsets (m) whose steps between consecutive rows are ``steps``; the typical row
    keeps its height."""
    offsets = np.concatenate([[0.0], np.cumsum(steps)])
    return offsets - np.median(offsets)


def _takes_back(steps: np.ndarray, first: int, later: int, tolerance_m: float) -> bool:
    """Whether the step at row ``later`` undoes the one at ``first``: opposite signs, both
    isolated (no outstanding step just before the first or just after the later: in a run of
    outstanding steps every row is offset, and only their sum places them), and either a
    short block between them (their sum there is the local slope of the surface along y,
    not an offset) or a sum within ``tolerance_m``."""
    opposite = steps[first] * steps[later] < 0
    isolated = (first == 0 or steps[first - 1] == 0) and (
        later == steps.size - 1 or steps[later + 1] == 0
    )
    short = later - first <= _SHORT_BLOCK_ROWS
    return opposite and isolated and (short or abs(steps[first] + steps[later]) <= tolerance_m)


def _paired_offsets(steps: np.ndarray, tolerance_m: float) -> np.ndarray:
    """Row offsets (m) from the outstanding steps (zero elsewhere).

    A step followed by one that takes it back (:func:`_takes_back`) bounds a block of
    shifted rows, shifted by the mean of the two: summing the two noisy steps instead would
    leave their sum as a false step under every later row. Any other step shifts every later
    row (so a run of outstanding steps, every row offset, is summed as the median of
    differences does).
    """
    offsets = np.zeros(steps.size + 1)
    flagged = list(np.flatnonzero(steps))
    while flagged:
        first = flagged.pop(0)
        if flagged and _takes_back(steps, first, flagged[0], tolerance_m):
            last = flagged.pop(0)
            offsets[first + 1 : last + 1] += 0.5 * (steps[first] - steps[last])
        else:
            offsets[first + 1 :] += steps[first]
    return offsets - np.median(offsets)


def level_lines(residual: np.ndarray, mode: str = "auto") -> LineLevelling:
    """Scan-line offsets of ``residual`` (a height map with its form removed, m).

    ``auto``: offsets only at the steps that stand out (:func:`outstanding_steps`); none
    when no step does; every row aligned, as ``on``, when the rows are offset throughout
    (:attr:`_JudgedSteps.offset_throughout`: then the small offsets hide among the ordinary
    steps, and leaving them would be the larger error). ``on``: every row aligned to the
    previous one by the median of their differences (Gwyddion), which adds a random walk of
    the noise along y. ``off``: none.
    """
    if mode not in LINE_LEVELLING_MODES:
        raise ScanLineError(
            f"line levelling '{mode}'; expected one of {', '.join(LINE_LEVELLING_MODES)}"
        )
    if mode != "off" and min(residual.shape) < _MIN_LINES:
        raise ScanLineError(
            f"height map of {residual.shape} px; line levelling needs at least {_MIN_LINES} "
            "rows and columns to tell an offset from the surface"
        )
    if mode == "off":
        return LineLevelling(mode, False, np.zeros(residual.shape[0]), 0, False, float("nan"))
    judged = judge_steps(residual)
    if mode == "on" or (judged.outstanding.any() and judged.offset_throughout):
        offsets = _offsets_from_steps(judged.steps)
        return LineLevelling(mode, True, offsets, judged.steps.size, True, judged.noise)
    sizes = _less_local_slope(judged.steps, judged.outstanding)
    offsets = _paired_offsets(sizes, STEP_THRESHOLD_SD * judged.noise)
    stepped = int(np.count_nonzero(sizes))
    return LineLevelling(mode, stepped > 0, offsets, stepped, False, judged.noise)
