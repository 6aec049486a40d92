"""Rule measure_edge_gap: gap at the fluorescent contact edge from the Newton rings."""

import json
import logging

from amontons.hertz import contact_radius
from amontons.images import atomic_path
from amontons.measurements import NotMeasurable, measure_edge_gap
from amontons.optics.area import OtsuSettings
from amontons.plots import plot_edge_gap, plot_unmeasured
from amontons.rawdata import fluorescence_image
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    reflection_path: str,
    fluorescence_dir: str,
    gap_path: str,
    figure_paths: list[str],
    reflection_load_mn: float,
    pixel_nm: float,
    otsu: dict,
    n_profiles: int,
    edge_model: str,
    max_rings: int,
    data_label: str,
    sphere: str,
    diameter_mm: float,
    e_star_gpa: float,
) -> None:
    title = f"{sphere}: Newton-ring gap at {reflection_load_mn:g} mN ({data_label})"
    try:
        result = measure_edge_gap(
            reflection_path,
            fluorescence_image(fluorescence_dir, reflection_load_mn),
            pixel_nm * 1e-9,
            otsu=OtsuSettings.from_config(otsu),
            n_profiles=n_profiles,
            edge_model=edge_model,
            max_rings=max_rings,
            hertz_radius_m=contact_radius(
                reflection_load_mn * 1e-3, diameter_mm * 0.5e-3, e_star_gpa * 1e9
            ),
        )
    except NotMeasurable as error:
        # A rough sphere scatters its rings, an image may show no contact: the gap is not
        # measurable, and the result says so (a flagged null, never a number), so the other
        # spheres' analysis goes on.
        log.warning("edge gap not measurable: %s", error)
        with atomic_path(gap_path) as tmp:
            tmp.write_text(
                json.dumps(
                    {"edge_gap_nm": None, "flag": str(error), "load_mN": reflection_load_mn},
                    indent=2,
                )
            )
        plot_unmeasured(str(error), title, figure_paths)
        return
    rings = result.rings
    summary = {
        "quantity": "gap at the fluorescent contact edge from Newton rings, d = (m + 1/2) λ/2n, "
        f"'{rings.edge_model}' curve extrapolated to the Otsu edge",
        "edge_gap_nm": {
            "mean": rings.edge_gap_mean_m * 1e9,
            "sd": rings.edge_gap_sd_m * 1e9,
            "n": int(rings.edge_gaps_m.size),
        },
        "edge_gaps_nm": (rings.edge_gaps_m * 1e9).tolist(),
        "profile_angles_deg": [float(a) for a in rings.angles_rad * 180 / 3.141592653589793],
        "first_ring_gap_nm": rings.first_ring_gap_m * 1e9,
        "rings_per_half_profile": [int(p.ring_r_m.size) for p in rings.half_profiles],
        # profiles without usable rings (roughness scatters them) are left out, not hidden
        "rejected_half_profiles": list(rings.rejected),
        "flag": (
            f"{len(rings.rejected)} of {len(rings.rejected) + rings.edge_gaps_m.size} "
            "half-profiles refused; see rejected_half_profiles"
            if rings.rejected
            else None
        ),
        "contact_radius_um": result.contact_radius_m * 1e6,
        "contact_centre_px": list(result.centre_px),
        "load_mN": reflection_load_mn,
        "reflection": str(result.reflection_path),
        "fluorescence": str(result.fluorescence_path),
    }
    log.info(
        "%s: edge gap %.2f ± %.2f nm over %d half-profiles",
        reflection_path,
        rings.edge_gap_mean_m * 1e9,
        rings.edge_gap_sd_m * 1e9,
        rings.edge_gaps_m.size,
    )
    with atomic_path(gap_path) as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    plot_edge_gap(
        [p.ring_r_m * 1e6 for p in rings.half_profiles],
        [p.ring_gap_m * 1e9 for p in rings.half_profiles],
        result.contact_radius_m * 1e6,
        rings.edge_gaps_m * 1e9,
        title,
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        reflection_path=sm.input.reflection,
        fluorescence_dir=sm.params.fluorescence_dir,
        gap_path=sm.output.gap,
        figure_paths=[sm.output.png, sm.output.pdf],
        reflection_load_mn=sm.params.reflection_load_mn,
        pixel_nm=sm.params.pixel_nm,
        otsu=sm.params.otsu,
        n_profiles=sm.params.newton_rings["n_profiles"],
        edge_model=sm.params.newton_rings["edge_model"],
        max_rings=sm.params.newton_rings["max_rings"],
        data_label=sm.params.data_label,
        sphere=sm.wildcards.sphere,
        diameter_mm=sm.params.diameter_mm,
        e_star_gpa=sm.params.e_star_gpa,
    )
