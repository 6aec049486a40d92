"""Rule measure_edge_gap: gap at the fluorescent contact edge from the Newton rings."""

import logging

from amontons.io.confocal import ImageChoice
from amontons.io.files import write_json
from amontons.io.rawdata import fluorescence_planes
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings
from amontons.measure.edge_gap import measure_edge_gap, unmeasured_edge_gap_record
from amontons.measure.errors import NotMeasurable
from amontons.physics.hertz import contact_radius
from amontons.runlog import run_logged
from amontons.study.plots import plot_edge_gap, plot_unmeasured

log = logging.getLogger(__name__)


def main(
    reflection_path: str,
    fluorescence,
    gap_path: str,
    figure_paths: list[str],
    reflection_load_mn: float,
    pixel_nm: float | None,
    images: dict,
    reflection_images: dict,
    otsu: dict,
    newton_rings: dict,
    data_label: str,
    sphere: str,
    diameter_mm: float,
    e_star_gpa: float,
) -> None:
    title = f"{sphere}: Newton-ring gap at {reflection_load_mn:g} mN ({data_label})"
    (image,), (choice,) = fluorescence_planes(fluorescence, [reflection_load_mn], images)
    try:
        result = measure_edge_gap(
            reflection_path,
            image,
            optional_nm_to_m(pixel_nm),
            choice=choice,
            reflection_choice=ImageChoice(**reflection_images),
            load_mn=reflection_load_mn,
            otsu=OtsuSettings.from_config(otsu),
            n_profiles=newton_rings["n_profiles"],
            edge_model=newton_rings["edge_model"],
            wavelength_m=newton_rings["wavelength_nm"] * 1e-9,
            n_medium=newton_rings["refractive_index"],
            max_rings=newton_rings["max_rings"],
            hertz_radius_m=contact_radius(
                reflection_load_mn * 1e-3, diameter_mm * 0.5e-3, e_star_gpa * 1e9
            ),
            mask_closing_m=newton_rings["mask_closing_um"] * 1e-6,
            margin_m=newton_rings["undetermined_margin_nm"] * 1e-9,
            spread_margin_m=newton_rings["undetermined_spread_nm"] * 1e-9,
        )
    except NotMeasurable as error:
        # A rough sphere scatters its rings, an image may show no contact: the gap is not
        # measurable, and the result says so (a flagged null, never a number), so the other
        # spheres' analysis goes on.
        log.warning("edge gap not measurable: %s", error)
        write_json(gap_path, unmeasured_edge_gap_record(str(error), reflection_load_mn))
        plot_unmeasured(str(error), title, figure_paths)
        return
    rings = result.rings
    if result.undetermined:
        # Not resolved by its own uncertainty: a flagged null like unreadable rings, but the
        # record and the figure keep the profiles that led to it.
        log.warning("edge gap %s", result.undetermined)
    else:
        log.info(
            "%s: edge gap %.2f ± %.2f nm (95 %%) over %d half-profiles",
            reflection_path,
            result.interval.mean_m * 1e9,
            result.interval.half_width_m * 1e9,
            rings.edge_gaps_m.size,
        )
    write_json(gap_path, result.to_record())
    plot_edge_gap(
        [p.ring_r_m * 1e6 for p in rings.half_profiles],
        [p.ring_gap_m * 1e9 for p in rings.half_profiles],
        rings.edge_radii_m * 1e6,
        rings.edge_gaps_m * 1e9,
        title,
        figure_paths,
        equal_area_radius_um=result.equal_area_radius_m * 1e6,
        summary=result.undetermined
        or (
            f"edge: {result.interval.mean_m * 1e9:.1f} ± "
            f"{result.interval.half_width_m * 1e9:.1f} nm (95 %)"
        ),
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        reflection_path=sm.input.reflection,
        fluorescence=sm.input.fluorescence,
        gap_path=sm.output.gap,
        figure_paths=[sm.output.png, sm.output.pdf],
        reflection_load_mn=sm.params.reflection_load_mn,
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        reflection_images=sm.params.reflection_images,
        otsu=sm.params.otsu,
        newton_rings=sm.params.newton_rings,
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
        diameter_mm=sm.params.diameter_mm,
        e_star_gpa=sm.params.e_star_gpa,
    )
