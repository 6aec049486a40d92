"""The decision between the contact models (issue 65): a model is named only where every
other model, the elastic limit among them, is excluded under the same errors; otherwise 'not
decided', with the models the data cannot tell apart and why."""

import pytest

from amontons.study.decision import ELASTIC, decide
from amontons.study.summary import decided_text

RISE_5 = 10.128  # F(1, 3) at 95 %: five loads


def test_a_model_is_named_where_every_other_is_excluded():
    decision = decide(
        {"hardening": 2.0, "penetration_hardness": 40.0},
        {"hardening": 50.0, "penetration_hardness": 60.0},
        RISE_5,
        5,
    )
    assert decision.decided and decision.kept == ("hardening",)
    assert decision.delta_chi2 == {"hardening": 0.0, "penetration_hardness": 38.0, ELASTIC: 48.0}
    assert "38 or more" in decision.why


def test_an_elastic_end_within_the_quantile_keeps_the_elastic_model():
    """The issue's 150 MPa truth: the p_Y scan's best lies near its elastic end (a plastic cap
    of 1 % of the area against a model error of 2 %): penetration hardness and the elastic
    limit cannot be told apart, and the verdict says so instead of naming either."""
    decision = decide(
        {"penetration_hardness": 3.0, "hardening": 30.0},
        {"penetration_hardness": 4.5, "hardening": 40.0},
        RISE_5,
        5,
    )
    assert not decision.decided
    assert decision.kept == ("penetration_hardness", ELASTIC)
    assert "inside the quantile" in decision.why


def test_a_misfit_of_every_model_scales_the_differences_by_the_best_ones():
    """The best model misses by χ² 40 over 4 degrees of freedom (Birge ratio² 10): the others'
    differences are judged under that scatter, so 60 more is 6, within the quantile."""
    decision = decide({"hardening": 40.0, "penetration_hardness": 100.0}, {"hardening": 400.0,
                      "penetration_hardness": 500.0}, RISE_5, 5)  # fmt: skip
    assert decision.delta_chi2["penetration_hardness"] == pytest.approx(6.0)
    assert decision.kept == ("hardening", "penetration_hardness")
    assert "Birge" in decision.why


def test_no_scan_judged_decides_nothing():
    assert decide({}, {}, RISE_5, 5).kept == ()
    assert decided_text({"decided": float("nan")}) == "no scan judged"
