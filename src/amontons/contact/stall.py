"""Stall detection of the conjugate-gradient loop (cg.polonsky_keer): a solve whose
residual has stopped falling ends early, status
stalled, instead of running to max_iter (docs/models.md §2.2)."""

from __future__ import annotations

import numpy as np

# A solve has stalled when its best residual has not fallen by STALL_FACTOR in STALL_WINDOW
# iterations. Conservative by design: well above the longest such stretch seen in converging
# solves (benchmarks/README.md, "Stall window"), and a fifth of the smallest default max_iter.
STALL_WINDOW = 200
STALL_FACTOR = 2.0


class StallMonitor:
    """Watches the residual history of one solve and says when it has stopped falling.

    Keeps the best residual so far and the best at the start of the current stretch (the
    mark); a fall of the best to ``mark / factor`` starts a new stretch. Stalled: a stretch
    of ``window`` iterations. (This fires no earlier than the sliding-window test "best now
    > best ``window`` iterations ago / factor", which it implies.) Residuals are
    dimensionless; inf and NaN never count as a fall.
    """

    def __init__(self, window: int = STALL_WINDOW, factor: float = STALL_FACTOR):
        self.window = window
        self.factor = factor
        self.best = np.inf
        self.mark = np.inf
        self.stretch = 0

    def update(self, residual: float) -> bool:
        """Record one iteration's residual; True once the solve has stalled."""
        if residual < self.best:
            self.best = residual
        if self.best * self.factor < self.mark:  # also the first finite residual
            self.mark = self.best
            self.stretch = 0
        else:
            self.stretch += 1
        return self.stretch >= self.window

    def message(self) -> str:
        """Why the solve stopped, with the numbers of the criterion."""
        return (
            f"the residual stalled: its best value {self.best:.3e} has not fallen by "
            f"{self.factor:g}x in {self.window} iterations (below the floor that round-off or "
            "the problem allows; a larger tol converges)"
        )
