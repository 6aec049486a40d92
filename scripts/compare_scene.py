"""Rule compare_scene: a scene's rendered contact registered on the sphere's measured
fluorescence images, and compared load by load (areas, their ratio, IoU, pixel agreement).
The sphere's first microscope scene finds the registration; the others keep it
(amontons.simulate.compare.scene_registration)."""

import logging

import pandas as pd

from amontons.io.fields import read_load_series
from amontons.io.files import read_json, write_json, write_table
from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_fluorescence_loads
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, image_contact_area, otsu_contact_area
from amontons.runlog import run_logged
from amontons.simulate.compare import (
    OUTSIDE_SCAN,
    afm_scan_centre_in_image_m,
    compare_loads,
    outside_scan_record,
    scene_registration,
    sheet_load_index,
    warped_mask,
)
from amontons.simulate.render import Rendered
from amontons.study.plots import plot_scene_comparison

log = logging.getLogger(__name__)


def main(
    rendered_path: str,
    solve_path: str,
    fluorescence,
    sphere_registration_path: str | None,
    table_path: str,
    registration_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float | None,
    images: dict,
    otsu: dict,
    data_label: str,
    scene: str,
    label: str,
) -> None:
    settings = OtsuSettings.from_config(otsu)
    fields, _, attrs = read_load_series(rendered_path)
    pixel_m = attrs["image_pixel_nm"] * 1e-9
    images = read_fluorescence_loads(fluorescence, loads_mn, optional_nm_to_m(pixel_nm), images)
    if abs(images[0].pixel_m - pixel_m) > 1e-6 * pixel_m:
        raise RawDataError(
            f"{images[0].path}: pixel {images[0].pixel_m * 1e9:.4g} nm, but the scene was "
            f"rendered at {pixel_m * 1e9:.4g} nm (the sheet's or the images' pixel); expected "
            "one pixel size"
        )
    solve = read_json(solve_path)
    simulated_mn = solve["loads_mn"]
    simulated = [sheet_load_index(loads_mn, load) for load in simulated_mn]
    rendered = [
        Rendered(f["image"], pixel_m, otsu_contact_area(f["image"], pixel_m, settings))
        for f in fields
    ]
    measured = [image_contact_area(image, settings) for image in images]
    outside = [
        outside_scan_record(
            row["load_mn"], row["window_um"], measured[sheet_load_index(loads_mn, row["load_mn"])]
        )
        for row in solve["outside_scan"]
    ]
    if not rendered:
        log.warning("%s: no load simulated (outside_scan); nothing to compare", solve_path)
        write_json(registration_path, {"status": OUTSIDE_SCAN, "registered_at_load_mn": None})
        write_table(table_path, pd.DataFrame(outside))
        plot_scene_comparison(
            loads_mn,
            [image.data for image in images],
            [m.mask for m in measured],
            [None] * len(loads_mn),
            [None] * len(loads_mn),
            [None] * len(loads_mn),
            pixel_m * 1e6,
            f"{label}: the AFM scan holds no load's window ({data_label})",
            figure_paths,
        )
        return
    sphere_record = (
        None if sphere_registration_path is None else read_json(sphere_registration_path)
    )
    registration, found_here = scene_registration(
        rendered, [images[i].data for i in simulated], sphere_record
    )
    log.info(
        "registration %s: %s",
        "found on this scene" if found_here else f"the sphere's ({sphere_registration_path})",
        registration,
    )
    solver_areas = [row["area_um2"] * 1e-12 for row in solve["loads"]]
    rows = compare_loads(
        [f * 1e-3 for f in simulated_mn],
        rendered,
        [measured[i] for i in simulated],
        solver_areas,
        registration,
        pixel_m,
    )
    for row in rows:
        log.info(
            "%g mN: measured %.1f µm², simulated %.1f µm² (ratio %.3f), IoU %.3f",
            row.load_n * 1e3,
            row.measured_area_m2 * 1e12,
            row.simulated_area_m2 * 1e12,
            row.area_ratio,
            row.iou,
        )
    scan_centre = afm_scan_centre_in_image_m(
        registration, [c * 1e-6 for c in solve["window_centre_in_scan_um"]], pixel_m
    )
    write_json(
        registration_path,
        {
            **registration.to_record(),
            "registered_at_load_mn": (
                simulated_mn[-1] if found_here else sphere_record["registered_at_load_mn"]
            ),
            "registered_on": scene if found_here else sphere_record["registered_on"],
            "definition": "measured position = rotate(mirror(simulated position about the "
            "rendered image's centre)) + measured image centre + shift; mirror flips columns, "
            "rotation counter-clockwise as displayed",
            "afm_scan_centre_in_image_um": [c * 1e6 for c in scan_centre],
            "image_pixel_nm": pixel_m * 1e9,
        },
    )
    write_table(table_path, pd.DataFrame([row.to_record() for row in rows] + outside))
    by_load = dict(zip(simulated, zip(rendered, rows, strict=True), strict=True))
    plot_scene_comparison(
        loads_mn,
        [image.data for image in images],
        [m.mask for m in measured],
        [
            warped_mask(by_load[i][0], registration, m.mask.shape) if i in by_load else None
            for i, m in enumerate(measured)
        ],
        [by_load[i][1].iou if i in by_load else None for i in range(len(loads_mn))],
        [by_load[i][1].area_ratio if i in by_load else None for i in range(len(loads_mn))],
        pixel_m * 1e6,
        f"{label}: simulated against measured contact ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        rendered_path=sm.input.rendered,
        solve_path=sm.input.solve,
        fluorescence=sm.input.fluorescence,
        sphere_registration_path=(
            sm.input.sphere_registration[0] if sm.input.sphere_registration else None
        ),
        table_path=sm.output.table,
        registration_path=sm.output.registration,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        otsu=sm.params.otsu,
        data_label=sm.params.data_label,
        scene=sm.wildcards.scene,
        label=f"{sm.wildcards.sphere}, scene {sm.wildcards.scene}",
    )
