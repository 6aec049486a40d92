"""Rule fit_timing_model: wall time and peak memory of a solve as a function of its FFT grid,
iterations and tolerance, fitted to the accuracy study's measured points (docs/accuracy.md)."""

import logging

from amontons.accuracy.settings import problem_kind
from amontons.accuracy.timing import fit_timing_model
from amontons.io.files import read_json, write_json
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(summary_paths: list, model_path: str) -> None:
    points = []
    for path in summary_paths:
        summary = read_json(path)
        points.append(
            {
                "model": problem_kind(summary["problem"])[0],
                "fft_points": summary["fft_points"],
                "loads": len(summary["loads"]),
                "tol": summary["tol"],
                "iterations": summary["iterations"],
                "wall_time_s": summary["wall_time_s"],
                "peak_rss_mb": summary["peak_rss_mb"],
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
    run_logged(main, sm.log[0], summary_paths=list(sm.input.summaries), model_path=sm.output.model)
