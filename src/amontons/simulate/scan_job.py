"""One sphere's parameter scan, the job of rule scan_scene (docs/study.md): its values solved
in a chain in one job. At each value the base scene with its parameter set to the value is
solved over the measured loads, each load starting from the previous value's pressure at
that load (amontons.simulate.scan_start; the p_Y chain's first value from the sphere's
elastic scene's) or else from the previous load, rendered like the microscope sees it, and
compared with the measured contact under the base scene's registration. The levelled map,
the PSF, the registration and the measured contacts are read once for the whole scan; each
value writes its result and its rendered fields into its own folder. After the chain, the
criterion of the measured areas, the model's error at the best value and the refinement
about the estimate (:func:`judge_and_refine`)."""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path

from amontons.contact import ContactError, ConvergenceError, FreeBoundaryError
from amontons.io.fields import write_load_series
from amontons.io.files import read_json, write_json
from amontons.io.rawdata import fluorescence_planes, read_fluorescence_series
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, image_contact_area, image_pixel_m
from amontons.models import ELASTIC
from amontons.simulate.compare import compare_loads, sheet_load_index
from amontons.simulate.model_error import (
    model_error_of,
    psf_log_change,
    richardson_log_bias,
    stated_model_error,
)
from amontons.simulate.register import Registration
from amontons.simulate.render import render_load_series
from amontons.simulate.scan import log_area_distance, scene_config_at
from amontons.simulate.scan_best import (
    criterion_of_record,
    floored_log_residuals,
    point_from_record,
    rms,
)
from amontons.simulate.scan_criterion import TooFewLoads
from amontons.simulate.scan_grid import ScanError, value_label
from amontons.simulate.scan_refine import refine_scan
from amontons.simulate.scan_start import ScanStart
from amontons.simulate.scene import SceneError
from amontons.simulate.solve import solve_scene
from amontons.simulate.surface import Indenter, afm_indenter, afm_scene, load_levelled_map

log = logging.getLogger(__name__)


class MeasuredContacts:
    """The sphere's measured contacts, each load's image read and thresholded the first time
    a value compares at that load, then kept for the scan's other values."""

    def __init__(self, fluorescence, sheet_mn: list[float], pixel_nm, images: dict, settings):
        self.files, self.choices = fluorescence_planes(fluorescence, sheet_mn, images)
        self.fallback_pixel_m = optional_nm_to_m(pixel_nm)
        self.settings = settings
        self.found = {}

    def at(self, indices: list[int]) -> list:
        """The measured contact at each of the sheet's loads ``indices``."""
        missing = [i for i in indices if i not in self.found]
        images = read_fluorescence_series(
            [self.files[i] for i in missing],
            self.fallback_pixel_m,
            [self.choices[i] for i in missing],
        )
        for i, image in zip(missing, images, strict=True):
            self.found[i] = image_contact_area(image, self.settings)
        return [self.found[i] for i in indices]


class ScanContext:
    """What every value of one sphere's scan shares: the levelled map, the sphere, the
    rendering's optics and the measured contacts with their registration."""

    def __init__(
        self,
        levelled_path: str,
        psf_path: str,
        registration_path: str,
        fluorescence,
        scan: dict,
        base_config: dict,
        sphere: str,
        sphere_record: dict,
        pixel_nm: float | None,
        pixel_table: list[str],
        images: dict,
        otsu: dict,
        threads: int,
        solver_backend: str,
    ):
        self.levelled_path = levelled_path
        self.levelled = load_levelled_map(levelled_path)
        self.scan = scan
        self.base_config = base_config
        self.sphere = sphere
        self.sphere_record = sphere_record
        self.settings = OtsuSettings.from_config(otsu)
        self.psf_path = psf_path
        self.registration_path = registration_path
        self.pixel_nm = pixel_nm
        self.pixel_table = pixel_table
        self.sheet_mn = [float(f) for f in sphere_record["loads"]]  # the files are named by these
        self.measured = MeasuredContacts(
            fluorescence, self.sheet_mn, pixel_nm, images, self.settings
        )
        self.threads = threads
        self.solver_backend = solver_backend
        self._indenters: dict[tuple[int, float], Indenter] = {}

    # Read when the first value renders: a scan whose values solve nothing (its windows
    # outside the AFM scan) has no registration to read, and needs no pixel or PSF.
    @cached_property
    def pixel_m(self) -> float:
        """The fluorescence image's pixel (m)."""
        return image_pixel_m(self.pixel_nm, self.pixel_table)

    @cached_property
    def psf_fwhm_nm(self) -> dict:
        """The sphere's measured PSF width (psf.json's ``fwhm_nm``: estimate, nm, and its
        standard error where the PSF was measured)."""
        return read_json(self.psf_path)["fwhm_nm"]

    @property
    def psf_fwhm_m(self) -> float:
        """The sphere's measured PSF width (m)."""
        return self.psf_fwhm_nm["estimate"] * 1e-9

    @cached_property
    def registration(self) -> Registration:
        """The base scene's registration, every value is compared under."""
        return Registration.from_record(read_json(self.registration_path))

    def indenter(self, scene) -> Indenter:
        """The scene's indenter, cut from the levelled map once per window: the window does
        not depend on the scanned parameter, so every value of the scan solves on the same
        one (its cut, its area average and its statistics: 4 of PTFE's 64 s for seven)."""
        key = (scene.side_px, scene.pixel_m)
        if key not in self._indenters:
            indenter = afm_indenter(self.levelled, scene, self.levelled_path)
            indenter.heights.setflags(write=False)  # shared by the values: none may change it
            self._indenters[key] = indenter
        return self._indenters[key]


@dataclass
class Solved:
    """One value solved: its result (scan_point.json), the next value's start, and where its
    contact fit the window, its scene, solution and rendered areas (what the model's error is
    measured on)."""

    record: dict
    start: ScanStart
    scene: object = None
    solution: object = None
    rendered_m2: tuple[float, ...] = ()  # each load's rendered Otsu area (m²), in its order

    @property
    def distance(self) -> float:
        d = self.record.get("log_area_distance")
        return float("inf") if d is None else d


def _value_record(context: ScanContext, value: float, covered: dict) -> dict:
    """The fields every value's scan_point.json starts with: where it was solved and what
    the AFM scan left out."""
    scan = context.scan
    record = {
        "sphere": context.sphere,
        "scene": scan["scene"],
        "parameter": scan["parameter"],
        "value": value,
        "outside_scan": covered["outside_scan"],
    }
    if "window_clipped" in covered:  # the scan clipped the window: say by how much
        record["window_clipped"] = covered["window_clipped"]
    return record


def _held_no_window(
    context: ScanContext, value: float, record: dict, covered: dict, paths: tuple[str, str]
) -> Solved:
    """A value whose AFM scan holds no load's window: recorded, nothing solved. The window
    does not depend on the scanned parameter: no value has a load to solve, and
    best_scan_value says so from the scan's size and the largest window in it."""
    point_path, fields_path = paths
    log.warning("%s = %g: the AFM scan holds no load's window", context.scan["parameter"], value)
    write_load_series(fields_path, [], [], record)
    record = {**record, **covered, "log_area_distance": None, "outside_window": None, "loads": []}
    write_json(point_path, record)
    return Solved(record, ScanStart())


def _outgrew_window(
    error: FreeBoundaryError, scene, value: float, record: dict, paths: tuple[str, str], name
) -> Solved:
    """A value so soft that the contact outgrows the base scene's window (which holds the
    measured contact with room to spare): it matches the measurement worse than any value
    whose contact fits, so it is recorded, never best, and the scan goes on."""
    point_path, fields_path = paths
    log.warning("%s = %g: %s", name, value, error)
    write_load_series(fields_path, [], [], {**scene.to_record(), **record})
    record = {**record, "log_area_distance": None, "outside_window": str(error)}
    write_json(point_path, record)
    return Solved(record, ScanStart())


def _solve_from(context: ScanContext, scene, indenter, start: ScanStart, value: float):
    """The scene's load series, each load from ``start``'s pressure where it has one."""
    starts, started = start.starts_for(
        scene.loads_n, indenter.heights.shape, indenter.spacing_m, indenter.centre_in_scan_m
    )
    if start.loads_n:
        log.info("%s = %g: %d of %d loads start from the neighbour's pressures (the value "
                 "before, or the elastic scene for the first)", context.scan["parameter"],
                 value, started, len(scene.loads_n))  # fmt: skip
    return _solve(context, scene, starts if start.loads_n else None)


def _solve(context: ScanContext, scene, warm_starts=None):
    """The scene's load series on its window of the levelled map, with the scan's threads
    and solver engine; ``warm_starts``: a starting pressure (Pa) or None per load."""
    return solve_scene(
        scene,
        context.indenter(scene),
        threads=context.threads,
        backend=context.solver_backend,
        warm_starts=warm_starts,
    )


@dataclass(frozen=True)
class Compared:
    """A solved value rendered and compared with the measured contacts: the rendered
    loads, the sheet's loads they are at (mN), each load's comparison, those whose measured
    image shows a contact, and D over them."""

    rendered: list
    loads_mn: list[float]
    rows: list
    used: list
    distance: float


def _render_and_compare(context: ScanContext, scene, config: dict, solution) -> Compared:
    """The value's loads rendered like the microscope sees them and compared with the
    measured contacts under the base scene's registration."""
    rendered = render_load_series(
        solution.fields,
        scene.pixel_m,
        pixel_m=context.pixel_m,
        psf_fwhm_m=context.psf_fwhm_m,
        rendering=config["rendering"],
        confinement_floor_pa=config["confinement_floor_mpa"] * 1e6,
        otsu=context.settings,
    )
    simulated = [sheet_load_index(context.sheet_mn, f * 1e3) for f in scene.loads_n]
    loads_mn = [context.sheet_mn[i] for i in simulated]
    rows = compare_loads(
        [f * 1e-3 for f in loads_mn],
        rendered,
        context.measured.at(simulated),
        [row["area_um2"] * 1e-12 for row in solution.per_load],
        context.registration,
        context.pixel_m,
    )
    used = [row for row in rows if row.measured_found]
    distance = log_area_distance(
        [row.simulated_area_m2 for row in used], [row.measured_area_m2 for row in used]
    )
    return Compared(rendered, loads_mn, rows, used, distance)


def _write_rendered(
    fields_path: str, context: ScanContext, scene, indenter, solution, compared: Compared, value
) -> None:
    """The value's rendered.h5: each load's image, and the last load's plastic displacement
    and deformed heights (float32, m) for Fig. B.9."""
    last = solution.fields[-1]
    fields = [{"image": r.image} for r in compared.rendered]
    fields[-1] |= {
        "plastic_displacement": last["plastic_displacement"].astype("float32"),
        "deformed_heights": last["deformed_heights"].astype("float32"),
    }
    write_load_series(
        fields_path,
        fields,
        [
            {"load_mn": f, "otsu_threshold": r.otsu.threshold}
            for f, r in zip(compared.loads_mn, compared.rendered, strict=True)
        ],
        {
            **scene.to_record(),
            "parameter": context.scan["parameter"],
            "value": value,
            "image_pixel_nm": context.pixel_m * 1e9,
            "window_centre_in_scan_um": [c * 1e6 for c in indenter.centre_in_scan_m],
        },
    )


def _solved_record(record: dict, compared: Compared, solution) -> dict:
    """A solved value's scan_point.json: D, the loads it counts, the largest load's IoU and
    area ratio, the wall time and each load's comparison with its solver counts."""
    rows = compared.rows
    return {
        **record,
        "log_area_distance": compared.distance,
        "outside_window": None,
        "loads_used": len(compared.used),
        "iou_largest": rows[-1].iou,
        "area_ratio_largest": rows[-1].area_ratio,
        "wall_time_s": solution.wall_time_s,
        "loads": [
            {
                **row.to_record(),
                **{k: info[k] for k in ("iterations", "outer_iterations", "convolutions")},
            }
            for row, info in zip(rows, solution.per_load, strict=True)
        ],
    }


def solve_value(
    context: ScanContext, value: float, point_path: str, fields_path: str, start: ScanStart
) -> Solved:
    """One value of the scan, solved from ``start`` (the previous value's pressures), its
    result written to ``point_path`` and its rendered fields to ``fields_path``; returns it
    with its own pressures, the next value's start."""
    scan = context.scan
    config = scene_config_at(context.base_config, scan["parameter"], value)
    scene, coverage = afm_scene(
        scan["scene"], config, context.sphere, context.sphere_record, context.levelled
    )
    covered = coverage.to_record()
    record = _value_record(context, value, covered)
    paths = (point_path, fields_path)
    if scene is None:
        return _held_no_window(context, value, record, covered, paths)
    indenter = context.indenter(scene)
    try:
        solution = _solve_from(context, scene, indenter, start, value)
    except FreeBoundaryError as error:
        return _outgrew_window(error, scene, value, record, paths, scan["parameter"])
    compared = _render_and_compare(context, scene, config, solution)
    log.info(
        "%s = %g: D = %.4f over %d loads",
        scan["parameter"],
        value,
        compared.distance,
        len(compared.used),
    )
    _write_rendered(fields_path, context, scene, indenter, solution, compared, value)
    record = _solved_record(record, compared, solution)
    write_json(point_path, record)
    start = ScanStart.of(
        scene.loads_n,
        [f["pressure"] for f in solution.fields],
        indenter.spacing_m,
        indenter.centre_in_scan_m,
    )
    areas = tuple(r.simulated_area_m2 for r in compared.rows)
    return Solved(record, start, scene, solution, areas)


def rendered_areas_m2(context: ScanContext, scene, solution, psf_fwhm_m: float) -> list[float]:
    """The Otsu area (m²) of each load of ``solution`` rendered as the scan renders it, with
    the PSF's FWHM ``psf_fwhm_m`` (m)."""
    config = context.base_config
    rendered = render_load_series(
        solution.fields,
        scene.pixel_m,
        pixel_m=context.pixel_m,
        psf_fwhm_m=psf_fwhm_m,
        rendering=config["rendering"],
        confinement_floor_pa=config["confinement_floor_mpa"] * 1e6,
        otsu=context.settings,
    )
    return [r.otsu.area_m2 for r in rendered]


def _at_measured(values: list[float], record: dict) -> list[float]:
    """``values`` (one per load of a solved value's ``record``, in its order) at the loads the
    criterion reads: those whose measured image shows a contact."""
    return [
        v for v, row in zip(values, record["loads"], strict=True) if row["measured_contact_found"]
    ]


def estimate_model_error(
    context: ScanContext, best: Solved, loads_mn, judgement: dict, what: str = "the best value"
):
    """The model's error at a solved value ``best`` (the grid's best, or the elastic limit:
    ``what`` names it in the log) (amontons.simulate.model_error): the solver pixel's bias
    from a solve at ``model_error_pixel_factor`` times the pixel (0.5: one step finer), and
    the PSF's uncertainty from renders one standard error wider and narrower, at the
    criterion's loads ``loads_mn``. Returns the error and its record; where the bias cannot
    be measured, the stated error of :func:`stated_model_error`, and the record says why."""
    factor = judgement["model_error_pixel_factor"]
    check_scene = replace(best.scene, pixel_m=best.scene.pixel_m * factor)
    log.info(
        "model error: %s solved again at %.0f nm (%g x the pixel)",
        what,
        check_scene.pixel_m * 1e9,
        factor,
    )
    psf_change, psf_note = psf_share(context, best)
    try:
        check = _solve(context, check_scene)
        check_m2 = rendered_areas_m2(context, check_scene, check, context.psf_fwhm_m)
        bias = richardson_log_bias(
            _at_measured(best.rendered_m2, best.record),
            _at_measured(check_m2, best.record),
            factor,
            judgement["model_error_order"],
        )
    except (ContactError, ScanError, SceneError) as error:
        # a second grid that does not converge, does not fit the scan, or renders nothing
        return stated_error(best, loads_mn, judgement, psf_change, psf_note, error)
    error, record = model_error_of(loads_mn, bias, judgement["model_error_order_sd"], psf_change)
    return error, {
        "estimated": True,
        "value": best.record["value"],
        "solver_pixel_nm": best.scene.pixel_m * 1e9,
        "check_pixel_nm": check_scene.pixel_m * 1e9,
        "check_wall_time_s": check.wall_time_s,
        "order": judgement["model_error_order"],
        "psf": psf_note,
        **record,
    }


def stated_error(best: Solved, loads_mn, judgement: dict, psf_change, psf_note: str, error):
    """The stated model error (amontons.simulate.model_error.stated_model_error) at ``best``'s
    solver pixel where its bias could not be measured (``error`` says why), and its record."""
    stated, record = stated_model_error(
        loads_mn, best.scene.pixel_m, judgement["model_error_stated_per_um"], psf_change
    )
    log.warning(
        "model error not measured (%s): counted as the stated %.3g in ln area", error,
        stated.offset_sd,
    )  # fmt: skip
    return stated, {
        "estimated": False,
        "why": str(error),
        "counted": "stated: model_error_stated_per_um times the solver pixel, an offset of "
        "unknown sign shared by every load",
        "value": best.record["value"],
        "solver_pixel_nm": best.scene.pixel_m * 1e9,
        "psf": psf_note,
        **record,
    }


def solve_elastic_limit(context: ScanContext, best: Solved, loads_mn, judgement: dict) -> dict:
    """The nested models' common limit (docs/study.md §6, "The decision"): the elastic model
    solved on the best value's window, rendered and compared as every value is, and its own
    model error measured as the best value's is (:func:`estimate_model_error`), so that the
    verdict judges elastic with the elastic model's error, not with the plastic model's
    measured at its best value. Returns refinement.json's ``elastic_limit``: its residuals
    ln A_sim − ln A_meas at the criterion's loads (a load it renders no contact at taken at
    one image pixel, :func:`floored_log_residuals`) and its model error; where the elastic
    solve fails to converge or to fit the window, or renders nothing to compare, ``solved``
    false and why (the verdict then reads the scan's elastic end alone)."""
    scene = replace(best.scene, model=ELASTIC.name, parameter_si=None)
    try:
        solution = _solve(context, scene)
        compared = _render_and_compare(context, scene, context.base_config, solution)
    except (ConvergenceError, FreeBoundaryError, ScanError, SceneError) as error:
        log.warning("the elastic limit not solved: %s", error)
        return {"solved": False, "why": str(error)}
    record = _solved_record({"model": ELASTIC.name, "value": None}, compared, solution)
    areas = tuple(r.simulated_area_m2 for r in compared.rows)
    limit = Solved(record, ScanStart(), scene, solution, areas)
    _, error_record = estimate_model_error(context, limit, loads_mn, judgement, "the elastic limit")
    residuals = floored_log_residuals(
        [row.simulated_area_m2 for row in compared.used],
        [row.measured_area_m2 for row in compared.used],
        context.pixel_m**2,
    )
    distance = rms(residuals)
    log.info("the elastic limit: D = %.4f over %d loads", distance, len(residuals))
    return {
        "solved": True,
        "model": ELASTIC.name,
        "loads_mn": list(loads_mn),
        "residuals": list(residuals),
        "log_area_distance": distance,
        "wall_time_s": solution.wall_time_s,
        "model_error": error_record,
    }


def psf_share(context: ScanContext, best: Solved) -> tuple[list[float] | None, str]:
    """The PSF's share of the model's error at the best value
    (amontons.simulate.model_error.psf_log_change) and what was done; None where the PSF
    states no standard error or a render loses its contact (then the PSF's share is not
    counted, and the note says why)."""
    se_nm = context.psf_fwhm_nm.get("standard_error")
    if not se_nm:
        return None, "not counted: the PSF states no standard error (a FWHM from the config)"
    fwhm = context.psf_fwhm_m
    change = psf_log_change(
        lambda f: _at_measured(
            rendered_areas_m2(context, best.scene, best.solution, f), best.record
        ),
        fwhm,
        se_nm * 1e-9,
    )
    if change is None:
        return (
            None,
            f"not counted: a render at FWHM {fwhm * 1e9:.0f} ± {se_nm:.0f} nm lost its contact",
        )
    return change, f"counted: FWHM {fwhm * 1e9:.0f} ± {se_nm:.0f} nm (one standard error)"


def judge_and_refine(context, chain, solved, best, judgement, refinement_path):
    """After the coarse grid: the criterion of the measured areas, the model's error at the
    best value, and the values solved about the estimate and the interval's ends
    (amontons.simulate.scan_refine), each from its nearest solved neighbour's pressures.
    Writes ``refinement_path`` (what best_scan_value judges with beside the grid)."""
    folder = Path(chain[0]["point"]).parent.parent
    names = (Path(chain[0]["point"]).name, Path(chain[0]["rendered"]).name)
    if best is None:
        write_json(
            refinement_path,
            {
                "judged": False,
                "why": "no value gives a contact in the window",
                "refined_points": [],
            },
        )
        return
    try:
        criterion = criterion_of_record(best.record)
    except TooFewLoads as error:
        log.warning("not judged, no refinement: %s", error)
        write_json(refinement_path, {"judged": False, "why": str(error), "refined_points": []})
        return
    error, error_record = estimate_model_error(context, best, criterion.loads_mn, judgement)
    criterion = replace(criterion, model_error=error)
    elastic_limit = solve_elastic_limit(context, best, criterion.loads_mn, judgement)
    records = {value: result.record for value, result in solved.items()}
    starts = {value: result.start for value, result in solved.items()}
    points = [point_from_record(r, criterion.n) for r in records.values()]
    if not any(math.isfinite(sum(p.residuals)) for p in points):  # best_scan_value says why
        why = "no value's contact fits the window at every load"
        write_json(refinement_path, {"judged": False, "why": why, "refined_points": []})
        return
    refined = []

    def solve(value: float):
        label = value_label(value)
        neighbour = min(starts, key=lambda v: abs(math.log(v / value)))
        result = solve_value(
            context,
            value,
            str(folder / label / names[0]),
            str(folder / label / names[1]),
            starts[neighbour],
        )
        starts[value] = result.start
        refined.append(str(folder / label / names[0]))
        return point_from_record(result.record, criterion.n)

    _, refinement = refine_scan(
        points,
        criterion,
        judgement["confidence"],
        solve,
        judgement["refine_fraction"],
        judgement["refine_max_values"],
    )
    log.info(
        "refinement: %d values in %d rounds (%s)",
        len(refinement.values),
        refinement.rounds,
        refinement.stopped,
    )
    write_json(
        refinement_path,
        {
            "judged": True,
            "model_error": error_record,
            "elastic_limit": elastic_limit,
            "refinement": refinement.to_record(),
            "refined_points": refined,
        },
    )


def first_start(seed: list[str]) -> ScanStart:
    """The chain's first value's start: the sphere's elastic scene's pressures, where the run
    has them (``seed``, amontons.workflow.scenes.Scenes.scan_seed_fields), else none."""
    if not seed:
        log.info("no elastic scene of this sphere: the first value starts from nothing")
        return ScanStart()
    log.info("the first value starts from the elastic scene's pressures (%s)", seed[0])
    return ScanStart.from_scene_fields(seed[0])


def main(
    context: ScanContext, chain: list[dict], seed: list[str], judgement: dict, refinement_path: str
) -> None:
    """Every value of ``chain`` (amontons.simulate.workflow.scenes.Scenes.scan_value_files:
    value, point and rendered paths, in the order they are solved), each from the one before,
    the first from the elastic scene's fields ``seed`` (none or one path); then the model's
    error and the refinement (:func:`judge_and_refine`)."""
    start = first_start(seed)
    solved, best = {}, None
    for value in chain:
        result = solve_value(
            context, float(value["value"]), value["point"], value["rendered"], start
        )
        start = result.start
        if result.solution is not None and (best is None or result.distance < best.distance):
            best = result
        solved[result.record["value"]] = Solved(result.record, result.start)  # no fields kept
    judge_and_refine(context, chain, solved, best, judgement, refinement_path)


def run(
    chain: list[dict], seed: list[str], judgement: dict, refinement_path: str, **context
) -> None:
    """The scan job: its context (:class:`ScanContext`'s arguments) built, its chain solved
    and refined, inside its log."""
    main(ScanContext(**context), chain, seed, judgement, refinement_path)
