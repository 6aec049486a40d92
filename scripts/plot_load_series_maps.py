"""Rule plot_load_series_maps: appendix Figs. 5.2 and B.11 for one sphere
(amontons.study.load_series_maps): reads the measured images, the Greenwood–Tripp solve and the
elastic scene's and the k scan's rendered series, and writes the figure and its table."""

import logging

from amontons.io.files import read_json
from amontons.io.rawdata import read_fluorescence_loads
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, image_contact_area
from amontons.models import CONTACT_HARDENING, ELASTIC
from amontons.runlog import run_logged
from amontons.simulate.register import Registration
from amontons.simulate.scan_record import is_decided
from amontons.study.figures import crop_box, grid_best_path, write_undecided_k_scan
from amontons.study.load_series_maps import LoadSeries, warped_series, write_load_series

log = logging.getLogger(__name__)


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
    settings = OtsuSettings.from_config(otsu)
    measured = [image_contact_area(image, settings) for image in images]
    shape = images[0].data.shape
    best = read_json(k_scan["best"])
    if not is_decided(best):  # the k scan solved nothing: no model to show
        write_undecided_k_scan(best, table_path, figure_paths, label)
        return
    hardening = Registration.from_record(read_json(k_scan["registration"]))
    elastic_registration = Registration.from_record(read_json(elastic["registration"]))
    best_path = grid_best_path(k_scan["rendered"], best)
    series = LoadSeries(
        images=[image.data for image in images],
        measured=measured,
        greenwood_tripp=read_json(gt_solve)["loads"],
        rendered={
            ELASTIC.name: warped_series(elastic["rendered"], elastic_registration, shape),
            CONTACT_HARDENING.name: warped_series(best_path, hardening, shape),
        },
        registration=hardening,
        loads_mn=loads_mn,
        pixel_m=images[0].pixel_m,
    )
    box = crop_box(measured[-1].mask)
    write_load_series(series, box, best, table_path, figure_paths, label)


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
