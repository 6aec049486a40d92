"""Rule best_scan_value: a sphere's scan judged (docs/study.md): every value's distance from
the measured areas, the scan's estimate with its interval, and the grid's best value with its
brackets."""

import logging

import pandas as pd

from amontons.io.files import read_json, write_json, write_table
from amontons.power_law import fit_power_law
from amontons.runlog import run_logged
from amontons.simulate.scan_best import (
    best_scan_value,
    criterion_of_record,
    elastic_limit_chi2,
    interval_resolution,
    model_error_of_record,
    not_decided_record,
    point_from_record,
    too_few_loads_record,
)
from amontons.simulate.scan_criterion import TooFewLoads
from amontons.simulate.scan_grid import ScanError
from amontons.simulate.scan_record import NOT_DECIDED

log = logging.getLogger(__name__)


def write_not_decided(records: list[dict], table_path: str, best_path: str, scan_name: str):
    """A scan with nothing to judge: every value's row, none solved, and best.json saying
    why (amontons.simulate.scan_best.not_decided_record). An answer, not a failure."""
    best = {"scan": scan_name, **not_decided_record(records)}
    log.warning("%s: not decided: %s", scan_name, best["not_decided"])
    rows = [
        {
            "value": record["value"],
            "log_area_distance": None,
            "iou_largest": None,
            "area_ratio_largest": None,
            "simulated_area_largest_um2": None,
            "measured_area_largest_um2": None,
            "best": False,
            "contact_leaves_window": False,
            "wall_time_s": record.get("wall_time_s"),
        }
        for record in records
    ]
    write_table(table_path, pd.DataFrame(rows))
    write_json(best_path, best)


def main(
    point_paths: list[str],
    refinement_path: str,
    table_path: str,
    best_path: str,
    scan_name: str,
    confidence: float,
):
    grid = sorted((read_json(p) for p in point_paths), key=lambda r: r["value"])
    if all(r.get("loads") == [] for r in grid):  # the scan held no load (scan_scene)
        write_not_decided(grid, table_path, best_path, scan_name)
        return
    judgement = read_json(refinement_path)
    refined = [read_json(p) for p in judgement["refined_points"]]
    records = sorted(grid + refined, key=lambda r: r["value"])
    solved = [r for r in records if r["outside_window"] is None]
    if not solved:
        raise ScanError(
            f"scan {scan_name}: at every value ({', '.join(str(r['value']) for r in records)}) "
            "the contact leaves the base scene's window; expected a range_factor whose values "
            "give contacts that fit (or a larger window_factor)"
        )
    error = model_error_of_record(judgement.get("model_error"))
    try:
        criterion = criterion_of_record(solved[0], error)
    except TooFewLoads as error:
        best = {
            "scan": scan_name,
            **too_few_loads_record(solved[0], error, [r["value"] for r in grid]),
        }
        log.warning("%s: not decided: %s", scan_name, best[NOT_DECIDED])
        write_table(table_path, pd.DataFrame(scan_rows(grid, None)))
        write_json(best_path, best)
        return
    points = [point_from_record(r, criterion.n) for r in records]
    best = best_scan_value(points, criterion, confidence, [r["value"] for r in grid])
    log.info(
        "%s: %s = %g, interval %s; grid's best %g (D = %.4f; scan bracket %s)",
        scan_name,
        records[0]["parameter"],
        best.refined,
        [best.scatter_low, best.scatter_high],
        best.value,
        best.distance,
        [best.resolution_low, best.resolution_high],
    )
    write_table(table_path, pd.DataFrame(scan_rows(records, best.value, refined)))
    write_json(
        best_path,
        {
            "sphere": records[0]["sphere"],
            "scan": scan_name,
            "scene": records[0]["scene"],
            "parameter": records[0]["parameter"],
            "values": [r["value"] for r in grid],
            "refined_values": [r["value"] for r in refined],
            "outside_scan": records[0]["outside_scan"],
            **best.to_record(),
            "criterion_loads_mn": list(criterion.loads_mn),
            **judgement_record(judgement, solved[0]),
            "interval_resolution": interval_resolution([p.value for p in points], best),
            **grid_best_record(next(r for r in grid if r["value"] == best.value), confidence),
        },
    )


def judgement_record(judgement: dict, solved: dict) -> dict:
    """best.json's model error, elastic limit (with its χ² under the elastic model's own
    error and the scatter of ``solved``'s loads, one solved value's scan_point.json) and
    refinement, from the scan job's refinement.json ``judgement``."""
    return {
        "model_error": judgement.get("model_error")
        or {"estimated": False, "why": "the scan job measured none"},
        "chi2_elastic_measured_sd": elastic_limit_chi2(solved, judgement.get("elastic_limit")),
        "elastic_limit": judgement.get("elastic_limit")
        or {"solved": False, "why": "the scan job solved none"},
        "refinement": judgement.get("refinement"),
    }


def grid_best_record(chosen: dict, confidence: float) -> dict:
    """best.json's numbers of the grid's best value (``chosen``, its scan_point.json): its
    IoU and area ratio at the largest load, its loads' areas and its rendered power law."""
    loads = [row["load_mn"] for row in chosen["loads"]]
    rendered = [row["simulated_area_um2"] for row in chosen["loads"]]
    return {
        "iou_largest": chosen["iou_largest"],
        "area_ratio_largest": chosen["area_ratio_largest"],
        "best_loads": [
            {k: row[k] for k in ("load_mn", "simulated_area_um2", "solver_area_um2")}
            for row in chosen["loads"]
        ],
        "best_rendered_fit": fit_power_law(
            loads, rendered, x_ref=loads[0], confidence=confidence
        ).to_record(),
    }


def scan_rows(records: list[dict], best_value: float | None, refined=()) -> list[dict]:
    """scan.csv: one row per solved value (the grid's, then refinement's, by value), the
    grid's best marked."""
    refined_values = {r["value"] for r in refined}
    rows = []
    for record in records:
        outside = record["outside_window"] is not None
        largest = {} if outside or not record["loads"] else record["loads"][-1]
        rows.append(
            {
                "value": record["value"],
                "refined": record["value"] in refined_values,
                "log_area_distance": record["log_area_distance"],
                "iou_largest": record.get("iou_largest"),
                "area_ratio_largest": record.get("area_ratio_largest"),
                "simulated_area_largest_um2": largest.get("simulated_area_um2"),
                "measured_area_largest_um2": largest.get("measured_area_um2"),
                "best": record["value"] == best_value,
                "contact_leaves_window": outside,
                "wall_time_s": record.get("wall_time_s"),
            }
        )
    return rows


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        point_paths=list(sm.params.points),
        refinement_path=sm.input.refinement,
        table_path=sm.output.table,
        best_path=sm.output.best,
        scan_name=sm.wildcards.scan,
        confidence=sm.params.confidence,
    )
