"""Rule measure_contact_area: Otsu contact area of each fluorescence image of one sphere."""

import logging

from amontons.io.files import write_table
from amontons.io.rawdata import read_fluorescence_loads
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, contact_area_table, image_contact_area
from amontons.runlog import run_logged
from amontons.study.plots import plot_contact_separation

log = logging.getLogger(__name__)


def main(
    fluorescence,
    table_path: str,
    figure_paths: list[str],
    loads_mn: list[float],
    pixel_nm: float | None,
    images: dict,
    otsu: dict,
    data_label: str,
    sphere: str,
) -> None:
    settings = OtsuSettings.from_config(otsu)
    images = read_fluorescence_loads(fluorescence, loads_mn, optional_nm_to_m(pixel_nm), images)
    areas = [image_contact_area(image, settings) for image in images]
    table = contact_area_table(loads_mn, images, areas)
    for row in table.itertuples():
        log.info("%s: %g mN → %.1f µm²", row.image, row.load_mn, row.area_um2)
        if not row.contact_found:
            log.warning("%s: no contact found: %s", row.image, row.flag)
        if row.saturated_pixels:
            # The threshold still separates contact from background, but the brightest
            # contact is clipped: the area stands, the intensities do not (flagged).
            log.warning(
                "%s: %d saturated pixels; intensities are clipped", row.image, row.saturated_pixels
            )
    write_table(table_path, table)
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
        fluorescence=sm.input.fluorescence,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        otsu=sm.params.otsu,
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
    )
