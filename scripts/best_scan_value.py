"""Rule best_scan_value: a sphere's scan judged (docs/study.md): every value's distance from
the measured areas, the scan's estimate with its interval, and the grid's best value with its
brackets."""

import logging

import pandas as pd

from amontons.fits import fit_power_law
from amontons.io.files import read_json, write_json, write_table
from amontons.runlog import run_logged
from amontons.simulate.scan_best import (
    ScanPoint,
    best_scan_value,
    log_area_scatter,
    not_decided_record,
)
from amontons.simulate.scan_grid import ScanError

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


def main(point_paths: list[str], table_path: str, best_path: str, scan_name: str, confidence):
    records = sorted((read_json(p) for p in point_paths), key=lambda r: r["value"])
    if all(r.get("loads") == [] for r in records):  # the scan held no load (scan_scene)
        write_not_decided(records, table_path, best_path, scan_name)
        return
    solved = [r for r in records if r["outside_window"] is None]
    if not solved:
        raise ScanError(
            f"scan {scan_name}: at every value ({', '.join(str(r['value']) for r in records)}) "
            "the contact leaves the base scene's window; expected a range_factor whose values "
            "give contacts that fit (or a larger window_factor)"
        )
    measured = [row for row in solved[0]["loads"] if row["measured_contact_found"]]
    scatter = log_area_scatter(
        [row["load_mn"] for row in measured], [row["measured_area_um2"] for row in measured]
    )
    points = [
        ScanPoint(r["value"], r["log_area_distance"], r["iou_largest"], r["area_ratio_largest"])
        if r["outside_window"] is None
        else ScanPoint(r["value"], float("inf"), 0.0, float("inf"))
        for r in records
    ]
    best = best_scan_value(points, scatter, len(measured), confidence)
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
    rows = []
    for record in records:
        outside = record["outside_window"] is not None
        largest = {} if outside else record["loads"][-1]
        rows.append(
            {
                "value": record["value"],
                "log_area_distance": record["log_area_distance"],
                "iou_largest": record.get("iou_largest"),
                "area_ratio_largest": record.get("area_ratio_largest"),
                "simulated_area_largest_um2": largest.get("simulated_area_um2"),
                "measured_area_largest_um2": largest.get("measured_area_um2"),
                "best": record["value"] == best.value,
                "contact_leaves_window": outside,
                "wall_time_s": record.get("wall_time_s"),
            }
        )
    write_table(table_path, pd.DataFrame(rows))
    chosen = next(r for r in records if r["value"] == best.value)["loads"]
    loads = [row["load_mn"] for row in chosen]
    rendered = [row["simulated_area_um2"] for row in chosen]
    write_json(
        best_path,
        {
            "sphere": records[0]["sphere"],
            "scan": scan_name,
            "scene": records[0]["scene"],
            "parameter": records[0]["parameter"],
            "values": [r["value"] for r in records],
            "outside_scan": records[0]["outside_scan"],
            **best.to_record(),
            "iou_largest": next(r["iou_largest"] for r in records if r["value"] == best.value),
            "area_ratio_largest": next(
                r["area_ratio_largest"] for r in records if r["value"] == best.value
            ),
            "best_loads": [
                {k: row[k] for k in ("load_mn", "simulated_area_um2", "solver_area_um2")}
                for row in chosen
            ],
            "best_rendered_fit": fit_power_law(
                loads, rendered, x_ref=loads[0], confidence=confidence
            ).to_record(),
        },
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        point_paths=list(sm.params.points),
        table_path=sm.output.table,
        best_path=sm.output.best,
        scan_name=sm.wildcards.scan,
        confidence=sm.params.confidence,
    )
