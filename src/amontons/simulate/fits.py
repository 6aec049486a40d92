"""A scene's load-area power laws, from the solver's true area and the rendered Otsu area
(docs/simulate.md, "Fits and tables"); the tables that read them: :mod:`.tables`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from amontons.power_law import fit_power_law

# fit_power_law's standard errors need three points: a scene with fewer loads is not fitted.
MIN_FIT_LOADS = 3


def scene_area_fits(
    loads_mn: Sequence[float],
    solver_areas_um2: Sequence[float],
    rendered_areas_um2: Sequence[float] | None,
    confidence: float,
    outside_scan: Sequence[Mapping] = (),
) -> dict:
    """A = A_ref·(F/F_ref)^α fitted to the solver's true area and, for a scene with optics, to
    the rendered Otsu area (F_ref: the first load; areas in µm²), over the loads simulated.
    ``outside_scan`` lists the loads the AFM scan did not hold (solve.json); with fewer than
    MIN_FIT_LOADS loads simulated, neither fit is made and ``not_fitted`` says why."""
    loads = np.asarray(loads_mn, dtype=float)
    record = {
        "quantity": "real contact area versus normal load of a simulated scene, "
        "A = A_ref (F / F_ref)^exponent",
        "units": {"prefactor": "um2 (area at x_ref)", "x_ref": "mN"},
    }
    left_out = {"loads_mn": loads.tolist(), "outside_scan": [dict(row) for row in outside_scan]}
    if loads.size < MIN_FIT_LOADS:
        reason = (
            f"{loads.size} loads simulated ({len(outside_scan)} outside the AFM scan); a "
            f"load-area fit needs {MIN_FIT_LOADS} or more"
        )
        return {**record, "solver_area": None, "rendered_area": None, **left_out,
                "not_fitted": reason}  # fmt: skip

    def fit(areas):
        return fit_power_law(
            loads, np.asarray(areas, dtype=float), x_ref=loads[0], confidence=confidence
        ).to_record()

    return {
        **record,
        "solver_area": fit(solver_areas_um2),
        "rendered_area": None if rendered_areas_um2 is None else fit(rendered_areas_um2),
        **left_out,
        "not_fitted": None,
    }
