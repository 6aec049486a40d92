"""Power-law fits recover known exponents and report honest intervals."""

import numpy as np
import pytest

from amontons.power_law import fit_power_law


def test_exact_power_law_is_recovered_to_round_off():
    load = np.array([25.0, 50, 100, 200, 400])
    area = 400.0 * (load / 25) ** 0.8
    fit = fit_power_law(load, area, x_ref=25)
    assert fit.exponent.estimate == pytest.approx(0.8, abs=1e-12)
    assert fit.prefactor.estimate == pytest.approx(400.0, rel=1e-12)
    assert fit.n == 5


def test_interval_covers_the_truth_at_about_the_stated_rate():
    rng = np.random.default_rng(3)
    load = np.geomspace(25, 400, 6)
    hits = 0
    trials = 400
    for _ in range(trials):
        area = 400.0 * (load / 25) ** 0.7 * np.exp(rng.normal(0, 0.05, load.size))
        fit = fit_power_law(load, area, x_ref=25, confidence=0.95)
        hits += fit.exponent.ci_low <= 0.7 <= fit.exponent.ci_high
    # Binomial(400, 0.95) has sd 1.1 %; 4 sd either side.
    assert 0.906 <= hits / trials <= 0.994


@pytest.mark.parametrize(
    ("x", "y", "match"),
    [
        ([1.0, 2.0], [1.0, 2.0], "≥ 3 points"),
        ([1.0, 2.0, 3.0], [1.0, 0.0, 2.0], "positive"),
        ([1.0, 2.0, np.nan], [1.0, 2.0, 3.0], "positive"),
    ],
)
def test_bad_input_raises(x, y, match):
    with pytest.raises(ValueError, match=match):
        fit_power_law(np.array(x), np.array(y), x_ref=1.0)
