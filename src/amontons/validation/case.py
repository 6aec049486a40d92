"""One validation case, run and recorded (docs/study.md §7): its truth solved and imaged
(amontons.validation.truth), judged by the study (amontons.validation.study), and the record
that says whether each interval holds the truth and what the decision named, with the cost.

An interval *holds* the truth where the scan is the truth's model and the truth's value lies
inside it (an open end reaches to the scan's end and beyond); for an elastic truth, where the
interval is open at the scan's elastic end (the elastic limit, value → ∞, lies inside).
A scan of another model than the truth's holds nothing to check (None)."""

from __future__ import annotations

import time

from amontons import models
from amontons.contact.options import DEFAULT_ITERATION
from amontons.measure.area import OtsuSettings
from amontons.simulate.scan_best import ScanBest
from amontons.simulate.scan_criterion import TooFewLoads
from amontons.validation.cases import Case, Truth
from amontons.validation.study import CaseStudy, ScanAnswer, StudySettings, judge_case
from amontons.validation.truth import (
    Sphere,
    case_rng,
    grids_of,
    measure_truth,
    truth_solver_label,
)

# the verdict where the data keep more than one model
NOT_DECIDED = "not decided"
# the record's name for the study's own small sphere (the config's ``validation`` keys)
SMALL_SPHERE = "validation"


def holds_truth(answer: ScanAnswer, truth: Truth, best: ScanBest | None = None) -> bool | None:
    """Whether the scan's interval (``best``'s; None: the scan's own) holds the truth (module
    docstring); None where the scan is of another plastic model than the truth's."""
    best = answer.best if best is None else best
    low, high = best.scatter_low, best.scatter_high
    if truth.model == models.ELASTIC.name:
        return high is None
    if truth.model != answer.model:
        return None
    return (low is None or low <= truth.value) and (high is None or truth.value <= high)


def scan_record(answer: ScanAnswer, truth: Truth) -> dict:
    """What the case keeps of one scan: estimate, interval (null: open), grid best, the χ²
    the decision reads, whether it holds the truth, its model error and refinement."""
    best = answer.best
    inner = answer.inner
    return {
        "estimate": best.estimate,
        "interval": [best.scatter_low, best.scatter_high],
        "grid_best": best.value,
        "holds_truth": holds_truth(answer, truth),
        "inner_confidence": None if inner is None else inner.confidence,
        "inner_interval": None if inner is None else [inner.scatter_low, inner.scatter_high],
        "inner_holds_truth": None if inner is None else holds_truth(answer, truth, inner),
        "chi2_min_measured_sd": best.chi2_min_measured,
        "chi2_elastic_end_measured_sd": best.chi2_elastic_end_measured,
        "chi2_rise": best.rise,
        "measured_log_area_sd": best.scatter_sd,
        "log_area_sd_used": best.scatter_sd_used,
        "model_error_bias": answer.model_error["bias"],
        "refinement": answer.refinement,
        "values": list(answer.values),
    }


def verdict_of(kept: tuple[str, ...]) -> str:
    """The verdict a decision gives: the one model kept, else "not decided"."""
    return kept[0] if len(kept) == 1 else NOT_DECIDED


def run_case(
    case: Case,
    sphere: Sphere,
    settings: StudySettings,
    truth_tol: float,
    otsu: OtsuSettings,
    truth_iteration: str = DEFAULT_ITERATION,
) -> dict:
    """The case's truth (ours solved by our CG ``truth_iteration``), its study and the record
    of both (JSON-ready)."""
    grids = grids_of(sphere, settings.pixel_m, case.ratio)
    measured = measure_truth(sphere, grids, case, truth_tol, otsu, truth_iteration)
    # the PSF the study measured: the truth's, off by one draw of its stated standard error
    psf = sphere.psf_fwhm_m + sphere.psf_se_m * float(case_rng(case, "psf").standard_normal())
    study = CaseStudy(sphere, measured, settings, psf)
    start = time.perf_counter()
    record = {
        "case": case.name,
        "sphere": case.sphere or SMALL_SPHERE,
        "truth": case.truth.name,
        "model": case.truth.model,
        "value": case.truth.value,
        "parameter": case.truth.parameter,
        "signal": case.truth.signal,
        "seed": case.seed,
        "ratio": case.ratio,
        "comparison": case.comparison,
        "truth_solver": truth_solver_label(case),
        "truth_iteration": truth_iteration,
        "ratio_solved": grids.ratio,
        "truth_pixel_nm": grids.truth_pixel_m * 1e9,
        "study_pixel_nm": grids.study_pixel_m * 1e9,
        "study_grid_px": grids.study_px,
        "truth_grid_px": grids.truth_px,
        "loads_mn": [f * 1e3 for f in sphere.loads_n],
        "measured_area_um2": [a * 1e12 for a in measured.areas_m2],
        "true_area_um2": [a * 1e12 for a in measured.true_areas_m2],
        "psf_fwhm_study_nm": psf * 1e9,
    }
    try:
        answers, elastic, decision = judge_case(study)
    except TooFewLoads as error:
        return {
            **record,
            "scans": {},
            "verdict": NOT_DECIDED,
            "kept": [],
            "why": str(error),
            "truth_wall_s": measured.wall_time_s,
            "study_wall_s": time.perf_counter() - start,
            "study_solves": study.solves,
        }
    return {
        **record,
        "scans": {a.model: scan_record(a, case.truth) for a in answers},
        "elastic_limit": {
            "chi2_measured_sd": elastic.chi2,
            "log_area_distance": elastic.distance,
            "model_error": elastic.model_error,
        },
        "flow_gain": decision.flow,
        "verdict": verdict_of(decision.kept),
        "kept": list(decision.kept),
        "why": decision.why,
        "truth_wall_s": measured.wall_time_s,
        "study_wall_s": time.perf_counter() - start,
        "study_solves": study.solves,
    }
