"""Write one sphere's virtual experiment: fluorescence images per load and its truth.

Walking-skeleton forward model: a smooth Hertzian sphere. The contact-solver issues replace the
pressure field by rough-sphere contact-hardening solves; the file layout stays the same.
"""

from __future__ import annotations

import json
import logging
import zlib
from pathlib import Path

import numpy as np

from amontons import hertz
from amontons.images import atomic_path, write_image
from amontons.rawdata import fluorescence_name
from amontons.virtual.fluorescence import pixel_averaged, render_fluorescence

log = logging.getLogger(__name__)


def sphere_rng(seed: int, sphere: str) -> np.random.Generator:
    """A generator that depends on the root seed and the sphere id only (not on job order)."""
    return np.random.default_rng([seed, zlib.crc32(sphere.encode())])


def field_of_view_px(largest_radius_m: float, pixel_m: float, factor: float) -> int:
    """Image side in pixels: ``factor`` × the largest contact diameter, rounded up to 32."""
    side = int(np.ceil(factor * 2 * largest_radius_m / pixel_m))
    return int(32 * np.ceil(side / 32))


def generate_sphere(
    out_dir: str | Path,
    *,
    sphere: str,
    diameter_m: float,
    e_star_pa: float,
    loads_n: list[float],
    pixel_m: float,
    psf_fwhm_m: float,
    background_counts: float,
    contact_counts: float,
    field_of_view_factor: float,
    seed: int,
) -> dict:
    """Write ``fluorescence/<load mN>.tif`` and ``truth.json`` into ``out_dir``; return the truth.

    ``contact_counts`` is the expected signal at the mean contact pressure of the smallest load;
    the signal scales as √p, so it is ``contact_counts·√(p/p̄_min)``.
    """
    out_dir = Path(out_dir)
    radius_m = diameter_m / 2
    rng = sphere_rng(seed, sphere)
    radii = [hertz.contact_radius(f, radius_m, e_star_pa) for f in loads_n]
    side = field_of_view_px(max(radii), pixel_m, field_of_view_factor)
    mean_pressure_min = loads_n[0] / (np.pi * radii[0] ** 2)
    counts_per_sqrt_pa = contact_counts / np.sqrt(mean_pressure_min)
    for load_n in loads_n:

        def pressure(x, y, load_n=load_n):
            return hertz.pressure_profile(np.hypot(x, y), load_n, radius_m, e_star_pa)

        signal = counts_per_sqrt_pa * np.sqrt(pixel_averaged(pressure, (side, side), pixel_m))
        image = render_fluorescence(
            signal,
            pixel_m,
            psf_fwhm_m=psf_fwhm_m,
            background_counts=background_counts,
            rng=rng,
        )
        write_image(out_dir / "fluorescence" / fluorescence_name(load_n * 1e3), image, pixel_m)
        log.info("%s: %g mN, %d² px image written", sphere, load_n * 1e3, side)
    truth = {
        "synthetic": True,
        "sphere": sphere,
        "forward_model": "hertz (smooth sphere)",
        "seed": seed,
        "loads_mn": [f * 1e3 for f in loads_n],
        "contact_radius_um": [a * 1e6 for a in radii],
        "area_um2": [np.pi * a**2 * 1e12 for a in radii],
        "area_exponent": 2 / 3,
        "pixel_nm": pixel_m * 1e9,
        "image_side_px": side,
        "psf_fwhm_nm": psf_fwhm_m * 1e9,
        "background_counts": background_counts,
    }
    with atomic_path(out_dir / "truth.json") as tmp:
        tmp.write_text(json.dumps(truth, indent=2))
    return truth
