"""The Gaussian's full width at half maximum per standard deviation (docs/models.md §1.3)."""

from __future__ import annotations

import math

FWHM_PER_SIGMA = 2 * math.sqrt(2 * math.log(2))  # 2.3548
