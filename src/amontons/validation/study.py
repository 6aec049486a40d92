"""A validation case judged as the study judges a sphere (docs/study.md §1 and §6): each
plastic model's scan over its grid about the prior, the model's error measured at the best
grid value (a solve at ``model_error_pixel_factor`` times the pixel, and the PSF's standard
error),
the refinement about the estimate and the interval's ends, the scan's estimate and interval
(amontons.simulate.scan_best), and the decision between the models
(amontons.study.decision). The same functions the scan and verdict jobs call, on the truth's
measured areas (amontons.validation.truth), here in memory.

The study renders with the PSF it measured: the true FWHM plus one draw of its stated
standard error, which the criterion counts as a mode of the model's error."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from amontons.contact import ContactError, FreeBoundaryError, solve_load_series
from amontons.measure.area import OtsuSettings
from amontons.model_laws import law_of
from amontons.models import ELASTIC, with_parameter
from amontons.simulate.compare import intersection_over_union
from amontons.simulate.model_error import (
    model_error_of,
    psf_log_change,
    richardson_log_bias,
    stated_model_error,
)
from amontons.simulate.render import render_load_series
from amontons.simulate.scan import log_area_distance
from amontons.simulate.scan_best import (
    ScanBest,
    ScanPoint,
    best_scan_value,
    floored_log_residuals,
    rms,
)
from amontons.simulate.scan_criterion import Criterion, TooFewLoads
from amontons.simulate.scan_grid import ScanError, scan_values
from amontons.simulate.scan_refine import refine_scan
from amontons.simulate.surface import area_average
from amontons.study.decision import Decision, decide
from amontons.validation.cases import PARAMETER_OF
from amontons.validation.truth import Measured, Sphere


@dataclass(frozen=True)
class StudySettings:
    """What the study solves and judges with: its solver pixel (m) and tolerance, each plastic
    model's prior (config units), the scans' grids (config ``scans``), the judgement (config
    ``scan_judgement`` with its confidence), the Otsu settings, and the second level the
    intervals are also read at (``inner_confidence``: calibration at two levels; None:
    none)."""

    pixel_m: float
    tol: float
    priors: Mapping[str, float]
    scans: Mapping[str, Mapping]
    judgement: Mapping
    otsu: OtsuSettings
    inner_confidence: float | None = None

    def grid(self, model: str) -> list[float]:
        """The scan's coarse grid of ``model`` about its prior (config units)."""
        scan = next(s for s in self.scans.values() if s["parameter"] == PARAMETER_OF[model])
        return scan_values(
            self.priors[PARAMETER_OF[model]], scan["range_factor"], scan["steps"], scan["spacing"]
        )


def sheet_priors(record: Mapping) -> dict[str, float]:
    """A sheet sphere's priors (config units, by parameter key): each plastic model's prior
    column of its row (config/materials.tsv), as the reproduction's scans take them."""
    return {m.parameter.key: float(record[m.parameter.sheet_column]) for m in with_parameter()}


@dataclass
class Solved:
    """One value solved: its point of the scan, its pressures (the neighbours' warm start;
    None where its contact left the window) and its fields."""

    point: ScanPoint
    pressures: list | None
    fields: list | None = None
    rendered_m2: list[float] = field(default_factory=list)


class CaseStudy:
    """The study of one case: the surface at the study's pixel, the measured areas at the
    loads whose image shows a contact, and the PSF the study measured."""

    def __init__(self, sphere: Sphere, measured: Measured, settings: StudySettings, psf_fwhm_m):
        self.sphere = sphere
        self.measured = measured
        self.settings = settings
        self.psf_fwhm_m = psf_fwhm_m
        self.used = [i for i, c in enumerate(measured.contacts) if c.contact_found]
        self.loads_mn = [sphere.loads_n[i] * 1e3 for i in self.used]
        self.measured_m2 = [measured.areas_m2[i] for i in self.used]
        self.solves = 0
        self._indenters: dict[int, tuple[np.ndarray, float]] = {}

    def indenter(self, factor: float = 1.0) -> tuple[np.ndarray, float]:
        """The surface averaged onto the study's pixel × ``factor`` (heights m, pixel m)."""
        if factor not in self._indenters:
            grids = self.measured.grids
            n = int(round(grids.study_px / factor))
            pixel = grids.window_m / n
            heights = area_average(self.measured.heights, grids.truth_pixel_m, (0.0, 0.0), n, pixel)
            self._indenters[factor] = (heights, pixel)
        return self._indenters[factor]

    def render(self, fields: Sequence[Mapping], pixel_m: float, fwhm_m: float) -> list:
        """Each measured load's rendered Otsu contact (ContactArea)."""
        rendered = render_load_series(
            [fields[i] for i in self.used],
            pixel_m,
            pixel_m=self.sphere.image_pixel_m,
            psf_fwhm_m=fwhm_m,
            rendering="emission",
            confinement_floor_pa=self.sphere.confinement_floor_pa,
            otsu=self.settings.otsu,
        )
        return [r.otsu for r in rendered]

    def solve_fields(self, model: str, value: float, warm, factor: float = 1.0) -> list[dict]:
        """The load series of ``model`` at ``value`` on the indenter of ``factor``."""
        heights, pixel = self.indenter(factor)
        self.solves += 1
        results = solve_load_series(
            heights,
            pixel,
            self.sphere.e_star_pa,
            list(self.sphere.loads_n),
            plasticity=law_of(model, value),
            tol=self.settings.tol,
            warm_starts=warm,
        )
        return [{"pressure": r.pressure, "contact": r.contact} for r in results]

    def solve(self, model: str, value: float, warm=None) -> Solved:
        """One value of the scan of ``model``, warm-started from ``warm`` (a neighbour's
        pressures, or None)."""
        n = len(self.used)
        try:
            fields = self.solve_fields(model, value, warm)
        except FreeBoundaryError:  # the contact outgrew the window: never best
            return Solved(ScanPoint.outside_window(value, n), None)
        contacts = self.render(fields, self.indenter()[1], self.psf_fwhm_m)
        rendered = [c.area_m2 for c in contacts]
        residuals = tuple(
            math.log(s / m) if s > 0 else math.inf
            for s, m in zip(rendered, self.measured_m2, strict=True)
        )
        point = ScanPoint(
            value,
            log_area_distance(rendered, self.measured_m2),
            intersection_over_union(contacts[-1].mask, self.measured.contacts[self.used[-1]].mask),
            rendered[-1] / self.measured_m2[-1],
            residuals,
        )
        return Solved(point, [f["pressure"] for f in fields], fields, rendered)


def nearest_warm(solved: Mapping[float, Solved], value: float):
    """The pressures of the solved value nearest ``value`` in ln v whose contact fit."""
    fitting = [v for v, s in solved.items() if s.pressures is not None]
    if not fitting:
        return None
    return solved[min(fitting, key=lambda v: abs(math.log(v / value)))].pressures


def model_error(study: CaseStudy, model: str, best: Solved, judgement: Mapping):
    """The model's error at a solved value ``best`` (a scan's best grid value, or the elastic
    limit), as the scan job measures it: the bias from a solve at
    ``model_error_pixel_factor`` times the pixel (Richardson) and the PSF's standard error as
    a mode (amontons.simulate.model_error); where the bias cannot be measured, the stated
    error. Returns (ModelError, record)."""
    factor = float(judgement["model_error_pixel_factor"])
    pixel = study.indenter()[1]
    psf = psf_log_change(
        lambda fwhm: [c.area_m2 for c in study.render(best.fields, pixel, fwhm)],
        study.psf_fwhm_m,
        study.sphere.psf_se_m,
    )
    try:
        other_fields = study.solve_fields(model, best.point.value, None, factor)
        other = [
            c.area_m2
            for c in study.render(other_fields, study.indenter(factor)[1], study.psf_fwhm_m)
        ]
        bias = richardson_log_bias(best.rendered_m2, other, factor, judgement["model_error_order"])
    except (ContactError, ScanError) as error:
        stated, record = stated_model_error(
            study.loads_mn, pixel, judgement["model_error_stated_per_um"], psf
        )
        return stated, {**record, "estimated": False, "why": str(error)}
    error, record = model_error_of(study.loads_mn, bias, judgement["model_error_order_sd"], psf)
    return error, {**record, "estimated": True}


@dataclass(frozen=True)
class ElasticLimit:
    """The elastic model solved on the study's grid (the nested models' common limit), its
    χ² under the measured scatter and its own model error, and that error's record."""

    chi2: float
    model_error: dict
    distance: float


def judge_elastic_limit(study: CaseStudy) -> ElasticLimit:
    """The elastic model solved at the study's pixel and judged with its own model error, as
    the scan job judges it (amontons.simulate.scan_job.solve_elastic_limit)."""
    limit = study.solve(ELASTIC.name, None)
    if limit.fields is None:
        raise ValueError("the elastic contact outgrew the study's window: no elastic limit")
    error, record = model_error(study, ELASTIC.name, limit, study.settings.judgement)
    criterion = Criterion.of_measured(study.loads_mn, [a * 1e12 for a in study.measured_m2], error)
    residuals = floored_log_residuals(
        limit.rendered_m2, study.measured_m2, study.sphere.image_pixel_m**2
    )
    chi2 = criterion.chi2_measured(residuals)
    return ElasticLimit(chi2, record, rms(residuals))


@dataclass(frozen=True)
class ScanAnswer:
    """One plastic model's scan: its estimate and interval (amontons.simulate.scan_best), its
    model error's record, the refinement's stop and the values it solved; and its interval
    at the settings' ``inner_confidence`` (``inner``), read off the same solved values (the
    refinement solved about the outer interval's ends: the inner ends lie between solved
    values and are read off the parabola about the estimate or interpolated)."""

    model: str
    best: ScanBest
    model_error: dict
    refinement: str
    values: tuple[float, ...]
    inner: ScanBest | None = None


def run_scan(study: CaseStudy, model: str) -> ScanAnswer:
    """The scan of ``model``: its grid solved in a chain, the criterion with the model's
    error at the grid's best value (least D), refined, judged."""
    settings = study.settings
    judgement = settings.judgement
    grid = settings.grid(model)
    solved: dict[float, Solved] = {}
    warm, best = None, None
    for value in grid:
        result = study.solve(model, value, warm)
        solved[value] = result
        warm = result.pressures
        if result.fields is None:
            continue
        if best is None or result.point.distance < best.point.distance:
            if best is not None:
                best.fields = None  # only the best value's fields are kept
            best = result
        else:
            result.fields = None
    if best is None:
        raise ValueError(f"{model}: no value of {grid} gives a contact that fits the window")
    error, record = model_error(study, model, best, judgement)
    criterion = Criterion.of_measured(study.loads_mn, [a * 1e12 for a in study.measured_m2], error)

    def solve(value: float) -> ScanPoint:
        result = study.solve(model, value, nearest_warm(solved, value))
        result.fields = None
        solved[value] = result
        return result.point

    points, refinement = refine_scan(
        [s.point for s in solved.values()],
        criterion,
        judgement["confidence"],
        solve,
        judgement["refine_fraction"],
        judgement["refine_max_values"],
    )
    answer = best_scan_value(points, criterion, judgement["confidence"], grid)
    inner = settings.inner_confidence
    return ScanAnswer(
        model,
        answer,
        record,
        refinement.stopped,
        tuple(sorted(p.value for p in points)),
        None if inner is None else best_scan_value(points, criterion, inner, grid),
    )


def decision_of(answers: Sequence[ScanAnswer], elastic: ElasticLimit) -> Decision:
    """The decision between the scanned models and the elastic model, as the verdict takes
    it (amontons.study.summary.model_decision): χ² under the measured scatter, each model
    with its own error, the larger of the scans' quantiles, the fewest loads."""
    return decide(
        {a.model: a.best.chi2_min_measured for a in answers},
        {a.model: a.best.chi2_elastic_end_measured for a in answers},
        max(a.best.rise for a in answers),
        min(a.best.n_loads for a in answers),
        {a.model: elastic.chi2 for a in answers},  # both scans solve on the study's grid
    )


def judge_case(study: CaseStudy) -> tuple[list[ScanAnswer], ElasticLimit, Decision]:
    """Both plastic models' scans, the elastic limit and the decision (TooFewLoads where the
    measured images show a contact at fewer loads than the criterion needs)."""
    if len(study.used) < 3:
        raise TooFewLoads(study.loads_mn)
    answers = [run_scan(study, model.name) for model in with_parameter()]
    elastic = judge_elastic_limit(study)
    return answers, elastic, decision_of(answers, elastic)
