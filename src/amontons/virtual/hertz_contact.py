"""The contact state of a smooth Hertz sphere (Johnson 1985 §4.2): an analytic contact for the
virtual instruments, where a test needs a truth in closed form."""

from __future__ import annotations

import numpy as np

from amontons.physics import hertz
from amontons.physics.emission import confined_emission
from amontons.physics.hertz import exterior_gap
from amontons.virtual.fluorescence import pixel_averaged
from amontons.virtual.reflection import radial_gap_map
from amontons.virtual.state import ContactState


def hertz_contact_state(
    load_n: float,
    radius_m: float,
    e_star_pa: float,
    shape: tuple[int, int],
    pixel_m: float,
    edge_gap_m: float = 0.0,
    confinement_floor_pa: float = 0.0,
) -> ContactState:
    """Contact state of a smooth Hertz sphere (Johnson 1985 §4.2) at the image centre.

    ``edge_gap_m`` lifts the gap outside the contact by a constant: a stand-in for the average
    local gap that roughness leaves at the fluorescent edge (the appendix measures ≤ 9 nm),
    so that the Newton-ring measurement has a non-zero truth to recover. The emission is
    :func:`confined_emission` with ``confinement_floor_pa``.
    """
    centre = ((shape[0] - 1) / 2, (shape[1] - 1) / 2)
    a = hertz.contact_radius(load_n, radius_m, e_star_pa)

    def pressure(x, y):
        return hertz.pressure_profile(np.hypot(x, y), load_n, radius_m, e_star_pa)

    def gap(r):
        return np.where(r > a, exterior_gap(r, load_n, radius_m, e_star_pa) + edge_gap_m, 0.0)

    rows, cols = np.indices(shape)
    contact = np.hypot(rows - centre[0], cols - centre[1]) * pixel_m <= a
    return ContactState(
        load_n=load_n,
        pressure_pa=pixel_averaged(pressure, shape, pixel_m),
        emission_sqrt_pa=pixel_averaged(
            lambda x, y: confined_emission(
                pressure(x, y), np.hypot(x, y) <= a, confinement_floor_pa
            ),
            shape,
            pixel_m,
        ),
        gap_m=radial_gap_map(shape, pixel_m, centre, gap),
        contact=contact,
        area_m2=float(np.pi * a**2),
        edge_gap_m=edge_gap_m,
        centre_px=centre,
    )
