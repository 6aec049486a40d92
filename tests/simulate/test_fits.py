"""A scene's load-area fits and its rows in the scene and model tables, with loads left out
of the AFM scan (docs/simulate.md, "Fits and tables")."""

import numpy as np
import pytest

from amontons.simulate.fits import MIN_FIT_LOADS, scene_area_fits
from amontons.simulate.tables import left_out_note, model_table_rows, scene_table_rows

MEASURED = {"exponent": {"estimate": 0.8, "ci_low": 0.78, "ci_high": 0.82}}
OUTSIDE = [{"load_mn": 200.0, "window_um": 55.1}, {"load_mn": 300.0, "window_um": 63.3}]


def test_a_power_law_over_the_loads_simulated_recovers_its_exponent():
    """Exact A = 3 F^0.8 on the three loads a cut scan held: the exponent to 1e-12 (exact data,
    rounding only), the loads left out listed."""
    loads = [25.0, 50.0, 100.0]
    areas = [3 * f**0.8 for f in loads]
    fit = scene_area_fits(loads, areas, areas, 0.95, OUTSIDE)
    assert fit["solver_area"]["exponent"]["estimate"] == pytest.approx(0.8, abs=1e-12)
    assert fit["loads_mn"] == loads and fit["outside_scan"] == OUTSIDE
    assert fit["not_fitted"] is None
    assert left_out_note(fit) == "outside_scan: 200, 300 mN"


@pytest.mark.parametrize("n", range(MIN_FIT_LOADS))
def test_fewer_loads_than_a_fit_needs_give_no_fit_and_say_why(n):
    loads = [25.0, 50.0][:n]
    fit = scene_area_fits(loads, [1.0] * n, [1.0] * n, 0.95, OUTSIDE)
    assert fit["solver_area"] is None and fit["rendered_area"] is None
    assert f"{n} loads simulated (2 outside the AFM scan)" in fit["not_fitted"]
    (row,) = scene_table_rows("S", MEASURED, {"elastic": fit}, {"elastic": "elastic"})
    assert row["exponent"] is None and row["difference"] is None
    assert row["area"] == "not fitted"
    assert row["left_out"] == f"outside_scan: 200, 300 mN; not fitted: {fit['not_fitted']}"
    scene = {"fit": fit, "largest": None, "solve": {"loads": []}}
    (model,) = model_table_rows("S", MEASURED, {"elastic": scene}, {}, {"elastic": "elastic"})
    assert model["exponent"] is None and model["exponent_difference"] is None
    assert model["left_out"] == row["left_out"]


def test_a_scene_that_simulated_every_load_has_an_empty_note():
    loads = np.array([25.0, 50.0, 100.0, 200.0])
    fit = scene_area_fits(loads, 2 * loads**0.9, None, 0.95)
    (row,) = scene_table_rows("S", MEASURED, {"elastic": fit}, {"elastic": "elastic"})
    assert row["left_out"] == "" and row["area"] == "solver"
    assert row["difference"] == pytest.approx(0.9 - 0.8, abs=1e-12)
