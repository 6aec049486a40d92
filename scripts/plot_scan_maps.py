"""Rule plot_scan_maps: appendix Fig. B.8 for one sphere. The measured contact at the largest
load beside the rendered contact of every value of every scan, each warped onto the measured
image by its base scene's registration; the best value of each scan framed."""

import logging

import numpy as np
import pandas as pd

from amontons.io.fields import read_load_series
from amontons.io.files import read_json, write_table
from amontons.io.rawdata import read_fluorescence_loads
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, image_contact_area
from amontons.models import parameter_named
from amontons.runlog import run_logged
from amontons.simulate.register import Registration, warp_to_measured
from amontons.simulate.scan_record import (
    estimate_text,
    held_no_load,
    is_decided,
    not_decided_note,
)
from amontons.study.figures import MapPanel, crop_box, plot_map_grid

log = logging.getLogger(__name__)


def main(
    fluorescence,
    scans: dict,
    table_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float | None,
    images: dict,
    otsu: dict,
    label: str,
) -> None:
    images = read_fluorescence_loads(fluorescence, loads_mn, optional_nm_to_m(pixel_nm), images)
    measured = images[-1]
    contact = image_contact_area(measured, OtsuSettings.from_config(otsu))
    box = crop_box(contact.mask)
    rows = [[MapPanel(measured.data[box], f"measured, {loads_mn[-1]:g} mN", contact.mask[box])]]
    labels = ["experiment"]
    records, estimates = [], []
    for name, scan in scans.items():
        best = read_json(scan["best"])
        decided = is_decided(best)
        rendered_any = not held_no_load(best)  # else no value was solved: nothing rendered
        table = pd.read_csv(scan["table"]).set_index("value")
        # a scan that solved nothing has no registration to warp by
        base = read_json(scan["registration"]) if rendered_any else None
        registration = Registration.from_record(base) if rendered_any else None
        panels = []
        for path in scan["rendered"]:
            fields, per_load, attrs = read_load_series(path)
            value = attrs["value"]
            row = table.loc[value]
            record = {
                "scan": name,
                "parameter": best["parameter"],
                "value": value,
                "log_area_distance": row["log_area_distance"],
                "iou_largest": row["iou_largest"],
                "area_ratio_largest": row["area_ratio_largest"],
                "best": decided and value == best["grid_best"],
                "contact_leaves_window": rendered_any and not fields,
                "load_mn": loads_mn[-1],
            }
            records.append(record)
            if not fields:
                blank = np.zeros_like(measured.data[box], dtype=float)
                note = "contact leaves window" if rendered_any else "not decided"
                panels.append(MapPanel(blank, f"{value:g}\n{note}"))
                continue
            image = warp_to_measured(
                fields[-1]["image"], registration, measured.data.shape, order=1
            )
            threshold = per_load[-1]["otsu_threshold"]
            panels.append(
                MapPanel(
                    image[box],
                    f"{value:g}\nD = {row['log_area_distance']:.3f}",
                    (image > threshold)[box],
                    framed=record["best"],
                )
            )
        rows.append(panels)
        symbol = parameter_named(best["parameter"]).label
        labels.append(f"{best['scene']}\n{symbol}")
        estimate = (
            estimate_text(best) if decided else f"{name} not decided ({not_decided_note(best)})"
        )
        log.info("%s: %s", name, estimate if decided else best["not_decided"])
        estimates.append(estimate)
    write_table(table_path, pd.DataFrame(records))
    plot_map_grid(
        rows,
        labels,
        measured.pixel_m * 1e6,
        f"{label}: contact at {loads_mn[-1]:g} mN, measured and simulated over the scans; "
        f"framed: the grid's best value; estimates: {'; '.join(estimates)}; D: rms log-area "
        "distance over all loads",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        fluorescence=sm.input.fluorescence,
        scans=sm.params.scans,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        otsu=sm.params.otsu,
        label=sm.params.label,
    )
