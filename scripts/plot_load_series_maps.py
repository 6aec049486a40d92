"""Rule plot_load_series_maps: appendix Figs. 5.2 and B.11 for one sphere. Measured and
simulated contact at increasing loads: the experiment, Greenwood-Tripp (its mean-field
real-area fraction: the model has no asperity map), the elastic scene and the hardening
model at the k scan's grid's best k (the scanned value of least distance, docs/study.md
§1), each simulation warped onto the measured image by its
scene's registration."""

import logging

import numpy as np
import pandas as pd

from amontons.io.fields import read_load_series
from amontons.io.files import read_json, write_table
from amontons.io.rawdata import read_fluorescence_loads
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, image_contact_area
from amontons.runlog import run_logged
from amontons.simulate.compare import intersection_over_union
from amontons.simulate.register import Registration, warp_to_measured
from amontons.simulate.render import area_fraction_map
from amontons.simulate.scan_record import grid_best_text, is_decided, significant
from amontons.study_figures import (
    MapPanel,
    crop_box,
    grid_best_path,
    plot_map_grid,
    write_undecided_k_scan,
)

log = logging.getLogger(__name__)


def warped_series(path: str, registration: Registration, shape):
    """Every load's rendered image of ``path`` on the measured grid, with its Otsu mask."""
    fields, per_load, attrs = read_load_series(path)
    out = []
    for field, info in zip(fields, per_load, strict=True):
        image = warp_to_measured(field["image"], registration, shape, order=1)
        out.append((image, image > info["otsu_threshold"]))
    return out, attrs


def main(
    fluorescence,
    gt_solve: str,
    elastic: dict,
    k_scan: dict,
    table_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float | None,
    images: dict,
    otsu: dict,
    label: str,
) -> None:
    images = read_fluorescence_loads(fluorescence, loads_mn, optional_nm_to_m(pixel_nm), images)
    pixel_m = images[0].pixel_m
    settings = OtsuSettings.from_config(otsu)
    measured = [image_contact_area(image, settings) for image in images]
    shape = images[0].data.shape
    box = crop_box(measured[-1].mask)
    best = read_json(k_scan["best"])
    if not is_decided(best):  # the k scan solved nothing: no model to show
        write_undecided_k_scan(best, table_path, figure_paths, label)
        return
    best_path = grid_best_path(k_scan["rendered"], best)
    hardening_registration = Registration.from_record(read_json(k_scan["registration"]))
    elastic_registration = Registration.from_record(read_json(elastic["registration"]))
    series = {
        "elastic": warped_series(elastic["rendered"], elastic_registration, shape)[0],
        "hardening": warped_series(best_path, hardening_registration, shape)[0],
    }
    gt = read_json(gt_solve)["loads"]
    centre = (
        np.asarray(hardening_registration.map_offset_px((0.0, 0.0))) + (np.asarray(shape) - 1) / 2
    )
    rows = {"experiment": [], "greenwood_tripp": [], "elastic": [], "hardening": []}
    records = []
    for i, load in enumerate(loads_mn):
        rows["experiment"].append(
            MapPanel(images[i].data[box], f"{load:g} mN", measured[i].mask[box])
        )
        phi = area_fraction_map(gt[i]["r_um"], gt[i]["area_fraction"], shape, centre, pixel_m)
        rows["greenwood_tripp"].append(MapPanel(phi[box], f"A = {gt[i]['area_um2']:.0f} µm²"))
        records.append(
            {
                "load_mn": load,
                "row": "experiment",
                "area_um2": measured[i].area_m2 * 1e12,
                "area": "measured Otsu",
                "iou": None,
            }
        )
        records.append(
            {
                "load_mn": load,
                "row": "greenwood_tripp",
                "area_um2": gt[i]["area_um2"],
                "area": "model real area",
                "iou": None,
            }
        )
        for name in ("elastic", "hardening"):
            image, mask = series[name][i]
            area = np.count_nonzero(mask) * pixel_m**2 * 1e12
            iou = intersection_over_union(mask, measured[i].mask)
            rows[name].append(MapPanel(image[box], f"IoU {iou:.2f}", mask[box]))
            records.append(
                {
                    "load_mn": load,
                    "row": name,
                    "area_um2": area,
                    "area": "rendered Otsu (registered)",
                    "iou": iou,
                }
            )
    table = pd.DataFrame(records)
    table["best_k_mpa_per_nm"] = best["grid_best"]
    write_table(table_path, table)
    plot_map_grid(
        list(rows.values()),
        [
            "experiment",
            "Greenwood-Tripp\n(area fraction)",
            "elastic",
            f"hardening\ngrid's best\nk = {significant(best['grid_best'])} MPa/nm",
        ],
        pixel_m * 1e6,
        f"{label}: measured and simulated contact at increasing loads; hardening at "
        f"{grid_best_text(best)}; outlines: Otsu masks",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        fluorescence=sm.input.fluorescence,
        gt_solve=sm.input.gt_solve,
        elastic=sm.params.elastic,
        k_scan=sm.params.k_scan,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        otsu=sm.params.otsu,
        label=sm.params.label,
    )
