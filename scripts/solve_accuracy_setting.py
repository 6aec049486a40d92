"""Rule solve_accuracy_setting: one problem of the accuracy study at one solver setting (or its
converged reference): cost (wall time, peak memory, iterations) and what the errors are taken
on (areas, rendered Otsu areas, pressure on the common grid), docs/accuracy.md."""

import logging
import os

if "snakemake" in globals():
    os.environ.setdefault("OPENBLAS_NUM_THREADS", str(snakemake.threads))  # noqa: F821

from amontons.accuracy.compare import common_side_px, on_common_grid, rendered_areas_um2
from amontons.accuracy.problems import (
    cost_record,
    periodic_problem,
    solve_problem,
    sphere_problem,
)
from amontons.accuracy.settings import (
    common_pixel_factor,
    common_window_factor,
    problem_kind,
    settings_by_name,
)
from amontons.io.fields import write_load_series
from amontons.io.files import read_json, write_json
from amontons.physics import hertz
from amontons.runlog import run_logged
from amontons.simulate.surface import load_levelled_map

log = logging.getLogger(__name__)


def _common_window_m(problem, study: dict, record: dict | None) -> float:
    """The narrowest window of the study (m): the whole period, or the narrowest window factor
    × the Hertz contact diameter at the largest load."""
    if problem.periodic:
        return problem.window_m
    radius = record["diameter_mm"] * 0.5e-3
    diameter = 2 * hertz.contact_radius(max(problem.loads_n), radius, problem.e_star_pa)
    return common_window_factor(study) * diameter


def _problem(problem_name: str, setting, study: dict, levelled_path: str | None, record: dict):
    """The problem at ``setting``: the periodic surface, or the rough sphere's levelled map."""
    _, geometry = problem_kind(problem_name)
    if geometry == "flat_periodic":
        return periodic_problem(setting, study["periodic"])
    levelled = load_levelled_map(levelled_path)
    return sphere_problem(problem_name, setting, levelled, record, levelled_path)


def _per_load(results, rendered_um2) -> list[dict]:
    """Each load's row of the summary: true and rendered area (µm²) and the solver's cost."""
    return [
        {
            "load_mn": r.load * 1e3,
            "area_um2": r.area * 1e12,
            "rendered_area_um2": area,
            "iterations": int(r.iterations),
            "convolutions": float(r.info.convolutions),
            "solve_s": float(r.info.wall_time_s),
        }
        for r, area in zip(results, rendered_um2, strict=True)
    ]


def main(
    problem_name: str,
    setting_name: str,
    study: dict,
    levelled_path: str | None,
    psf_path: str,
    record: dict,
    fluorescence_pixel_nm: float,
    otsu: dict,
    fields_path: str,
    summary_path: str,
) -> None:
    setting = settings_by_name(problem_name, study)[setting_name]
    problem = _problem(problem_name, setting, study, levelled_path, record)
    log.info(
        "%s at %s: %d² grid of %.1f nm, window %.1f µm",
        problem_name,
        setting_name,
        problem.heights.shape[0],
        problem.pixel_m * 1e9,
        problem.window_m * 1e6,
    )
    results, wall_time_s = solve_problem(problem, setting)
    cost = cost_record(problem, results, wall_time_s)  # the peak before the rendering
    common_pixel = problem.finest_pixel_m * common_pixel_factor(study)
    common_window = _common_window_m(problem, study, record)
    side = common_side_px(common_window, common_pixel)
    rendered = rendered_areas_um2(
        results,
        problem.pixel_m,
        common_window,
        pixel_m=fluorescence_pixel_nm * 1e-9,
        psf_fwhm_m=read_json(psf_path)["fwhm_nm"]["estimate"] * 1e-9,
        otsu=otsu,
    )
    per_load = _per_load(results, rendered)
    summary = {
        "problem": problem_name,
        "setting": setting_name,
        **setting.to_record(),
        "model": problem_kind(problem_name)[0],
        "pixel_nm": problem.pixel_m * 1e9,
        "window_um": problem.window_m * 1e6,
        "common_pixel_nm": common_pixel * 1e9,
        "common_side_px": side,
        **cost,
        "loads": per_load,
    }
    write_load_series(
        fields_path,
        [
            {"pressure": on_common_grid(r.pressure, problem.pixel_m, side, common_pixel)}
            for r in results
        ],
        [{"load_mn": p["load_mn"]} for p in per_load],
        {"problem": problem_name, "setting": setting_name, "common_pixel_nm": common_pixel * 1e9},
    )
    write_json(summary_path, summary)
    log.info(
        "%s at %s: %.2f s, %d iterations, peak %.0f MB",
        problem_name,
        setting_name,
        wall_time_s,
        summary["iterations"],
        cost["peak_rss_mb"],
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        problem_name=sm.wildcards.problem,
        setting_name=sm.wildcards.setting,
        study=sm.params.study,
        levelled_path=sm.input.get("levelled"),
        psf_path=sm.input.psf,
        record=sm.params.record,
        fluorescence_pixel_nm=sm.params.fluorescence_pixel_nm,
        otsu=sm.params.otsu,
        fields_path=sm.output.fields,
        summary_path=sm.output.summary,
    )
