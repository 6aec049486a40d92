"""The decision between the contact models (issues 65 and 76): elastic is the limit of both
plastic models, so it is named where no plastic model improves on it by more than the
quantile (the likelihood ratio of nested models), with each plastic parameter's one-sided
bound; where one does, elastic is excluded, and a plastic model is named only where every
other is excluded; otherwise 'not decided', with the models the data cannot tell apart and
why."""

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
        elastic_chi2={"hardening": 50.0, "penetration_hardness": 50.0},
    )
    assert decision.decided and decision.kept == ("hardening",)
    assert decision.delta_chi2 == {"hardening": 0.0, "penetration_hardness": 38.0, ELASTIC: 48.0}
    assert decision.flow == {"hardening": 48.0, "penetration_hardness": 10.0}
    assert "38 or more" in decision.why and "flow detected" in decision.why


def test_a_plastic_best_near_its_elastic_limit_names_elastic():
    """The issue's 150 MPa truth: the p_Y scan's best lies near its elastic limit (a plastic
    cap of 1 % of the area against a model error of 2 %): no plastic model improves on the
    elastic model by more than the quantile, so the simpler, nested model is the answer, with
    the plastic parameters bounded on one side only (where a rule that names a model only
    when it alone is kept could never name elastic: it at best ties)."""
    decision = decide(
        {"penetration_hardness": 3.0, "hardening": 30.0},
        {"penetration_hardness": 4.5, "hardening": 40.0},
        RISE_5,
        5,
        elastic_chi2={"penetration_hardness": 4.5, "hardening": 4.5},
    )
    assert decision.decided and decision.elastic
    assert decision.flow == {"penetration_hardness": 1.5, "hardening": -25.5}
    assert "no flow detected" in decision.why and "from above" in decision.why


def test_an_elastic_verdict_says_where_a_scan_bounds_its_parameter_from_above_all_the_same():
    """The validation's PMMA-4mm 60 MPa truth (docs/study.md §7): the p_Y scan, judged with
    the error measured at its best value, excludes its elastic end (χ² 30 against 5), while
    the elastic model judged with its own, larger error lies within the quantile. Elastic is
    named, and the verdict says that the scan bounds p_Y from above all the same, instead of
    that the data bound nothing from above."""
    decision = decide(
        {"penetration_hardness": 5.0, "hardening": 9.0},
        {"penetration_hardness": 30.0, "hardening": 12.0},
        RISE_5,
        5,
        elastic_chi2={"penetration_hardness": 8.0, "hardening": 8.0},
    )
    assert decision.elastic
    assert "scan of penetration_hardness bounds its parameter from above" in decision.why
    assert "the two errors disagree" in decision.why
    assert "bound no plastic parameter" not in decision.why


def test_elastic_is_excluded_by_its_own_chi2_not_by_a_plastic_models_error():
    """The scans' elastic ends judged with a plastic model's smaller error lie far above the
    best (60 and 50), but the elastic model judged with its own error lies within the quantile
    of the best: elastic is named. The same scans judged by their elastic ends would name
    hardening, the answer the issue found wrong (the elastic bias several times the
    hardening one)."""
    own = decide(
        {"hardening": 2.0, "penetration_hardness": 9.0},
        {"hardening": 50.0, "penetration_hardness": 60.0},
        RISE_5,
        5,
        elastic_chi2={"hardening": 9.0, "penetration_hardness": 9.0},
    )
    assert own.elastic
    by_ends = decide(
        {"hardening": 2.0, "penetration_hardness": 9.0},
        {"hardening": 50.0, "penetration_hardness": 60.0},
        RISE_5,
        5,
    )
    assert by_ends.kept == ("hardening", "penetration_hardness")
    assert "no elastic solve judged" in by_ends.why


def test_a_scan_whose_own_elastic_end_is_kept_reports_no_flow():
    """Flow needs a plastic model to beat elastic under both errors: the elastic model judged
    with its own (here far off, χ² 100) and its own scan's elastic end judged with the
    plastic model's (here within the quantile: the scan's interval is open above). Elastic is
    named, and the verdict cannot contradict the scan's own bound."""
    decision = decide({"hardening": 2.0}, {"hardening": 5.0}, RISE_5, 5, {"hardening": 100.0})
    assert decision.elastic and decision.flow == {"hardening": 3.0}


def test_plastic_models_not_told_apart_once_flow_is_detected():
    """Both plastic models improve on elastic by far more than the quantile, and lie within
    it of each other: elastic is excluded, and the verdict is 'not decided' between them."""
    decision = decide(
        {"penetration_hardness": 3.0, "hardening": 8.0},
        {"penetration_hardness": 90.0, "hardening": 80.0},
        RISE_5,
        5,
        elastic_chi2={"penetration_hardness": 70.0, "hardening": 70.0},
    )
    assert not decision.decided
    assert decision.kept == ("penetration_hardness", "hardening")
    assert "flow detected" in decision.why and "inside it" in decision.why


def test_a_misfit_of_every_model_scales_the_differences_by_the_best_ones():
    """The best model misses by χ² 40 over 4 degrees of freedom (Birge ratio² 10): the others'
    differences are judged under that scatter, so 60 more is 6, within the quantile."""
    decision = decide({"hardening": 40.0, "penetration_hardness": 100.0}, {"hardening": 400.0,
                      "penetration_hardness": 500.0}, RISE_5, 5, {"hardening": 400.0,
                      "penetration_hardness": 400.0})  # fmt: skip
    assert decision.delta_chi2["penetration_hardness"] == pytest.approx(6.0)
    assert decision.kept == ("hardening", "penetration_hardness")
    assert "Birge" in decision.why


def test_no_scan_judged_decides_nothing():
    assert decide({}, {}, RISE_5, 5).kept == ()
    assert decided_text({"decided": float("nan")}) == "no scan judged"
