"""Rule measure_contact_area: Otsu contact area of each fluorescence image of one sphere."""

import logging

import pandas as pd

from amontons.images import atomic_path, read_image, saturated_pixels
from amontons.optics.area import otsu_contact_area
from amontons.plots import plot_contact_separation
from amontons.rawdata import fluorescence_images
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    fluorescence_dir: str,
    table_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float,
    otsu_bins: int,
    min_separation: float,
    data_label: str,
    sphere: str,
) -> None:
    rows, images, areas = [], [], []
    for load, path in zip(loads_mn, fluorescence_images(fluorescence_dir, loads_mn), strict=True):
        image = read_image(path, fallback_pixel_m=pixel_nm * 1e-9)
        area = otsu_contact_area(
            image.data, image.pixel_m, bins=otsu_bins, min_separation=min_separation
        )
        if not area.well_separated:
            log.warning(
                "%s: Otsu separation %.3f < %.3f; the threshold is ill-determined",
                path,
                area.separation,
                min_separation,
            )
        saturated = saturated_pixels(image.data)
        if saturated:
            # The threshold still separates contact from background, but the brightest
            # contact is clipped: the area stands, the intensities do not (flagged).
            log.warning("%s: %d saturated pixels; intensities are clipped", path, saturated)
        rows.append(
            {
                "load_mN": load,
                "area_um2": area.area_m2 * 1e12,
                "contact_pixels": area.n_contact_pixels,
                "pixel_nm": image.pixel_m * 1e9,
                "otsu_threshold_counts": area.threshold,
                "otsu_separation": area.separation,
                "well_separated": area.well_separated,
                "saturated_pixels": saturated,
                "image": str(path),
            }
        )
        log.info("%s: %g mN → %.1f µm²", path, load, area.area_m2 * 1e12)
        images.append(image)
        areas.append(area)
    with atomic_path(table_path) as tmp:
        pd.DataFrame(rows).to_csv(tmp, index=False)
    plot_contact_separation(
        loads_mn,
        [image.data for image in images],
        [area.mask for area in areas],
        [area.threshold for area in areas],
        [area.separation for area in areas],
        min_separation,
        images[0].pixel_m * 1e6,
        f"{sphere}: Otsu contact edge and intensity histogram per load ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        fluorescence_dir=sm.input.fluorescence,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        otsu_bins=sm.params.otsu_bins,
        min_separation=sm.params.min_separation,
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
