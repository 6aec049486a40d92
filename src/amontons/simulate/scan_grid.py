"""The values a parameter scan visits (docs/study.md), in pure Python: the workflow builds its
jobs from them, and building the DAG imports no numerical stack."""

from __future__ import annotations

import math
from collections.abc import Sequence

SPACINGS = ("log", "linear")
# The fewest measured loads a scan is judged on: the scatter of the measured areas about their
# power law, which the criterion weighs the model against, needs a degree of freedom beyond
# the line's two (amontons.simulate.scan_criterion).
MIN_LOADS = 3


class ScanError(ValueError):
    """A scan that cannot be set up or judged; the message names the scan and the value."""


def scan_values(
    sheet_value: float, range_factor: Sequence[float], steps: int, spacing: str = "log"
) -> list[float]:
    """``steps`` values from ``range_factor[0]`` to ``range_factor[1]`` times the sheet's value,
    log- or linearly spaced, rounded to 4 significant digits (they name the jobs' folders)."""
    low, high = (float(f) * float(sheet_value) for f in range_factor)
    if not 0 < low < high:
        raise ScanError(
            f"range {low:g}..{high:g} from range_factor {list(range_factor)} x sheet value "
            f"{sheet_value:g}; expected 0 < low < high"
        )
    if spacing not in SPACINGS:
        raise ScanError(f"spacing = {spacing!r}; expected one of {SPACINGS}")
    if steps < 3:
        raise ScanError(f"steps = {steps}; expected at least 3 (a minimum needs neighbours)")
    fractions = [i / (steps - 1) for i in range(steps)]
    if spacing == "log":
        grid = [math.exp(math.log(low) + f * math.log(high / low)) for f in fractions]
    else:
        grid = [low + f * (high - low) for f in fractions]
    return [float(value_label(v)) for v in grid]


def value_label(value: float) -> str:
    """A scan value as its folder name: 4 significant digits."""
    return f"{value:.4g}"
