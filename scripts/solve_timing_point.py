"""Rule solve_timing_point: one timing point of the accuracy study, a plastic solve of the
rough sphere at the timing setting with its law set by a dimensionless ratio; its cost only,
for the timing model (docs/accuracy.md, "Timing model")."""

import logging
import os

if "snakemake" in globals():
    os.environ.setdefault("OPENBLAS_NUM_THREADS", str(snakemake.threads))  # noqa: F821

from amontons.accuracy.problems import cost_record, solve_problem, timing_problem
from amontons.accuracy.settings import timing_points, timing_setting
from amontons.contact import FreeBoundaryError
from amontons.io.files import write_json
from amontons.models import model_named
from amontons.runlog import run_logged
from amontons.simulate.surface import load_levelled_map

log = logging.getLogger(__name__)


def _law_record(model: str, law) -> dict:
    """The plastic law of ``model`` in config units."""
    parameter = model_named(model).parameter
    return {parameter.key: float(getattr(law, parameter.law_field)) * parameter.from_si}


def main(point: str, study: dict, levelled_path: str, record: dict, summary_path: str) -> None:
    model, ratio = timing_points(study)[point]
    setting = timing_setting(study)
    levelled = load_levelled_map(levelled_path)
    problem = timing_problem(model, ratio, setting, levelled, record, levelled_path)
    try:
        results, wall_time_s = solve_problem(problem, setting)
    except FreeBoundaryError as error:
        # a low yield pressure spreads the contact beyond the window: no cost to record, and
        # the fit leaves the point out (it says so)
        log.warning("%s: outside the window, left out of the timing model: %s", point, error)
        write_json(summary_path, {"point": point, "model": model, "outside_window": str(error)})
        return
    summary = {
        "point": point,
        "model": model,
        "outside_window": None,
        **setting.to_record(),
        "pixel_nm": problem.pixel_m * 1e9,
        **_law_record(model, problem.plasticity),
        **cost_record(problem, results, wall_time_s),
        "loads": [
            {
                "load_mn": r.load * 1e3,
                "area_um2": r.area * 1e12,
                "iterations": int(r.iterations),
                "convolutions": float(r.info.convolutions),
            }
            for r in results
        ],
    }
    write_json(summary_path, summary)
    log.info(
        "%s (ratio %g) at %s: %.2f s, %g convolutions",
        model,
        ratio,
        point,
        wall_time_s,
        summary["convolutions"],
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        point=sm.wildcards.point,
        study=sm.params.study,
        levelled_path=sm.input.levelled,
        record=sm.params.record,
        summary_path=sm.output.summary,
    )
