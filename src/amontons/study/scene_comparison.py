"""A scene's rendered contact registered on the sphere's measured fluorescence images and
compared load by load (areas, their ratio, IoU, pixel agreement): the job of rule
compare_scene (docs/simulate.md). The sphere's first microscope scene finds the
registration; the others keep it (amontons.simulate.compare.scene_registration). Loads in mN,
areas in m² inside, µm² in the logs."""

from __future__ import annotations

import logging
from dataclasses import dataclass

import pandas as pd

from amontons.io.fields import read_load_series
from amontons.io.files import read_json, write_json, write_table
from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_fluorescence_loads
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, image_contact_area, otsu_contact_area
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

# How registration.json states the registration's definition.
REGISTRATION_DEFINITION = (
    "measured position = rotate(mirror(simulated position about the "
    "rendered image's centre)) + measured image centre + shift; mirror flips columns, "
    "rotation counter-clockwise as displayed"
)


def check_one_pixel(images, pixel_m: float) -> None:
    """The measured images must have the pixel (m) the scene was rendered at."""
    if abs(images[0].pixel_m - pixel_m) > 1e-6 * pixel_m:
        raise RawDataError(
            f"{images[0].path}: pixel {images[0].pixel_m * 1e9:.4g} nm, but the scene was "
            f"rendered at {pixel_m * 1e9:.4g} nm (the sheet's or the images' pixel); expected "
            "one pixel size"
        )


def rendered_contacts(fields, pixel_m: float, settings: OtsuSettings) -> list[Rendered]:
    """Each rendered load's image (rendered.h5's fields) with its Otsu contact."""
    return [
        Rendered(f["image"], pixel_m, otsu_contact_area(f["image"], pixel_m, settings))
        for f in fields
    ]


@dataclass(frozen=True)
class Outputs:
    """Where a comparison writes: its table (CSV), its registration (JSON) and its figure
    (PNG, PDF)."""

    table: str
    registration: str
    figures: list[str]


def write_nothing_compared(
    outputs: Outputs, loads_mn, images, measured, outside, pixel_m, title: str
) -> None:
    """A scene whose AFM scan held no load's window: the registration says so, the table
    lists the loads left out and the figure shows the measured contacts alone."""
    n = len(loads_mn)
    write_json(outputs.registration, {"status": OUTSIDE_SCAN, "registered_at_load_mn": None})
    write_table(outputs.table, pd.DataFrame(outside))
    plot_scene_comparison(
        loads_mn,
        [image.data for image in images],
        [m.mask for m in measured],
        [None] * n,
        [None] * n,
        [None] * n,
        pixel_m * 1e6,
        title,
        outputs.figures,
    )


def log_rows(rows) -> None:
    for row in rows:
        log.info(
            "%g mN: measured %.1f µm², simulated %.1f µm² (ratio %.3f), IoU %.3f",
            row.load_n * 1e3,
            row.measured_area_m2 * 1e12,
            row.simulated_area_m2 * 1e12,
            row.area_ratio,
            row.iou,
        )


def registration_record(registration, found_here: bool, sphere_record, solve, scene, pixel_m):
    """registration.json: the registration, where it was found (this scene at its largest
    load, or the sphere's first microscope scene), its definition, the AFM scan's centre in
    the image (µm) and the image pixel (nm)."""
    scan_centre = afm_scan_centre_in_image_m(
        registration, [c * 1e-6 for c in solve["window_centre_in_scan_um"]], pixel_m
    )
    return {
        **registration.to_record(),
        "registered_at_load_mn": (
            solve["loads_mn"][-1] if found_here else sphere_record["registered_at_load_mn"]
        ),
        "registered_on": scene if found_here else sphere_record["registered_on"],
        "definition": REGISTRATION_DEFINITION,
        "afm_scan_centre_in_image_um": [c * 1e6 for c in scan_centre],
        "image_pixel_nm": pixel_m * 1e9,
    }


def plot_compared(
    loads_mn, images, measured, by_load: dict, registration, pixel_m, title, figure_paths
) -> None:
    """The comparison figure: every sheet load's measured contact, and where the scene
    simulated it (``by_load``: sheet index -> (rendered, comparison row)), its registered
    mask, IoU and area ratio."""
    n = len(loads_mn)
    plot_scene_comparison(
        loads_mn,
        [image.data for image in images],
        [m.mask for m in measured],
        [
            warped_mask(by_load[i][0], registration, m.mask.shape) if i in by_load else None
            for i, m in enumerate(measured)
        ],
        [by_load[i][1].iou if i in by_load else None for i in range(n)],
        [by_load[i][1].area_ratio if i in by_load else None for i in range(n)],
        pixel_m * 1e6,
        title,
        figure_paths,
    )


def compare_scene(
    rendered_path: str,
    solve_path: str,
    fluorescence,
    sphere_registration_path: str | None,
    outputs: Outputs,
    loads_mn: list[float],
    pixel_nm: float | None,
    images: dict,
    otsu: dict,
    scene: str,
    label: str,
    data_label: str,
) -> None:
    """Compare a scene's rendered loads (rendered.h5) with the sphere's measured images at
        the sheet's ``loads_mn`` (the images' choices ``images``, their pixel ``pixel_nm`` where
        they state none), registered as the sphere's first microscope scene was (its
        registration.json, or None: this is that scene); ``label`` heads the figure's title and
    ``data_label`` says whose data it is."""
    settings = OtsuSettings.from_config(otsu)
    fields, _, attrs = read_load_series(rendered_path)
    pixel_m = attrs["image_pixel_nm"] * 1e-9
    images = read_fluorescence_loads(fluorescence, loads_mn, optional_nm_to_m(pixel_nm), images)
    check_one_pixel(images, pixel_m)
    solve = read_json(solve_path)
    simulated = [sheet_load_index(loads_mn, load) for load in solve["loads_mn"]]
    rendered = rendered_contacts(fields, pixel_m, settings)
    measured = [image_contact_area(image, settings) for image in images]
    outside = [
        outside_scan_record(
            row["load_mn"], row["window_um"], measured[sheet_load_index(loads_mn, row["load_mn"])]
        )
        for row in solve["outside_scan"]
    ]
    if not rendered:
        log.warning("%s: no load simulated (outside_scan); nothing to compare", solve_path)
        title = f"{label}: the AFM scan holds no load's window ({data_label})"
        write_nothing_compared(outputs, loads_mn, images, measured, outside, pixel_m, title)
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
    rows = compare_loads(
        [f * 1e-3 for f in solve["loads_mn"]],
        rendered,
        [measured[i] for i in simulated],
        [row["area_um2"] * 1e-12 for row in solve["loads"]],
        registration,
        pixel_m,
    )
    log_rows(rows)
    record = registration_record(registration, found_here, sphere_record, solve, scene, pixel_m)
    write_json(outputs.registration, record)
    write_table(outputs.table, pd.DataFrame([row.to_record() for row in rows] + outside))
    by_load = dict(zip(simulated, zip(rendered, rows, strict=True), strict=True))
    title = f"{label}: simulated against measured contact ({data_label})"
    plot_compared(
        loads_mn, images, measured, by_load, registration, pixel_m, title, outputs.figures
    )
