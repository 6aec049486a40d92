"""Rule measure_contact_area: Otsu contact area of each fluorescence image of one sphere."""

import logging

import pandas as pd

from amontons.images import atomic_path, saturated_pixels
from amontons.measurements import image_contact_area, read_fluorescence_series
from amontons.optics.area import OtsuSettings
from amontons.plots import plot_contact_separation
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    fluorescence_dir: str,
    table_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float,
    otsu: dict,
    data_label: str,
    sphere: str,
) -> None:
    settings = OtsuSettings.from_config(otsu)
    images = read_fluorescence_series(fluorescence_dir, loads_mn, pixel_nm * 1e-9)
    rows, areas = [], []
    for load, image in zip(loads_mn, images, strict=True):
        path = image.path
        area = image_contact_area(image, settings)
        if not area.contact_found:
            log.warning("%s: no contact found: %s", path, area.flag)
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
                "contrast_noise_sd": area.contrast,
                "largest_patch_px": area.largest_patch_px,
                "contact_found": area.contact_found,
                "flag": area.flag or "",
                "saturated_pixels": saturated,
                "image": str(path),
            }
        )
        log.info("%s: %g mN → %.1f µm²", path, load, area.area_m2 * 1e12)
        areas.append(area)
    with atomic_path(table_path) as tmp:
        pd.DataFrame(rows).to_csv(tmp, index=False)
    plot_contact_separation(
        loads_mn,
        [image.data for image in images],
        [area.mask for area in areas],
        [area.threshold for area in areas],
        [area.separation for area in areas],
        [area.flag for area in areas],
        images[0].pixel_m * 1e6,
        f"{sphere}: Otsu contact edge and intensity histogram per load ({data_label})",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        fluorescence_dir=sm.params.fluorescence_dir,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        otsu=sm.params.otsu,
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
