"""Rule fit_timing_model: wall time and peak memory of a solve as a function of its FFT grid,
contact extent, tolerance and plastic law, fitted to the accuracy study's measured solves
and its timing points (docs/accuracy.md, "Timing model")."""

import logging

from amontons.accuracy.timing_fit import fit_timing_model
from amontons.io.files import read_json, write_json
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


# what the fit reads of each solve's summary (amontons.accuracy.problems.cost_record)
KEYS = ("model", "fft_points", "periodic", "contact_px", "ratio", "tol", "convolutions")
COST = ("wall_time_s", "peak_rss_mb")


def main(summary_paths: list, model_path: str) -> None:
    points = []
    for path in summary_paths:
        summary = read_json(path)
        if summary.get("outside_window"):
            log.info("%s: outside its window, left out", path)
            continue
        points.append(
            {
                **{key: summary[key] for key in KEYS + COST},
                "loads": len(summary["loads"]),
            }
        )
    model = fit_timing_model(points)
    log.info(
        "timing model from %d solves: predicted/measured wall time %.2f-%.2f",
        len(points),
        *model["fit"]["time_ratio_range"],
    )
    write_json(model_path, {"source": summary_paths[0].rsplit("/", 3)[0], **model})


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        summary_paths=list(sm.input.summaries) + list(sm.input.timing_points),
        model_path=sm.output.model,
    )
