"""The rough-sphere forward model: one spectrum across grids, the solver window, and the map
from the solver grid onto an instrument's pixels."""

import numpy as np
import pytest

from amontons.contact import ContactHardening
from amontons.physics.newton_rings import APPENDIX_WAVELENGTH_M, FORMAMIDE_REFRACTIVE_INDEX
from amontons.virtual.rough_contact import (
    SolverSettings,
    image_contact_states,
    ring_reach_gap,
    simulate_rough_sphere,
    solver_grid,
)
from amontons.virtual.roughness import Roughness, synthesize

ROUGH = Roughness(rms_m=50e-9, hurst=0.8, rolloff_m=5e-6, reference_pixel_m=32e-9)


def test_synthesized_rms_matches_the_spectrum_and_the_bands_add_up():
    rng = np.random.default_rng(3)
    # 40 µm windows hold 64 roll-off areas: the realisation's rms scatters by a few %, 10 %
    # is the tolerance.
    full = synthesize((1250, 1250), 32e-9, ROUGH, rng)
    assert full.std() == pytest.approx(50e-9, rel=0.1)
    coarse = synthesize((156, 156), 256e-9, ROUGH, rng)
    fine = synthesize((1250, 1250), 32e-9, ROUGH, rng, above_m=256e-9)
    # The fine band's share of the spectrum, ∫ C d²q from π/256 nm to π/32 nm over the whole
    # band: 1.4 % of the power, 12 % of the rms (H = 0.8 puts the height in long waves).
    # 15 %: the grid's band is a square, the integral's a disc.
    q_r, q_s, q_a, two_h = 2 * np.pi / 5e-6, np.pi / 256e-9, np.pi / 32e-9, 1.6
    total = np.pi * q_r**-two_h + 2 * np.pi * (q_r**-two_h - q_a**-two_h) / two_h
    band = 2 * np.pi * (q_s**-two_h - q_a**-two_h) / two_h
    assert fine.std() == pytest.approx(50e-9 * np.sqrt(band / total), rel=0.15)
    assert np.hypot(coarse.std(), fine.std()) == pytest.approx(50e-9, rel=0.1)


def test_solver_grid_is_fft_friendly_and_capped():
    settings = SolverSettings(pixel_m=128e-9, max_grid_px=1024, window_factor=1.3)
    n, dx = solver_grid(123e-6, settings)
    assert n % 2 == 0 and n * dx >= 123e-6 and dx == 128e-9
    assert max(p for p in (2, 3, 5, 7) if n % p == 0) and _smooth(n)
    n, dx = solver_grid(300e-6, settings)
    assert n == 1024 and dx == pytest.approx(300e-6 / 1024)


def _smooth(n):
    for p in (2, 3, 5, 7):
        while n % p == 0:
            n //= p
    return n == 1


@pytest.fixture(scope="module")
def solution():
    """A rough 0.6 mm PS sphere at two loads on a 256 nm solver grid, started from a window
    too small for its contact (factor 1.0 and a Hertz guess): the window must grow."""
    settings = SolverSettings(pixel_m=256e-9, max_grid_px=512, window_factor=1.0)
    return simulate_rough_sphere(
        radius_m=0.3e-3,
        e_star_pa=3.7e9,
        law=ContactHardening(5e15),
        loads_n=[25e-3, 100e-3],
        reflection_load_n=25e-3,
        ring_reach_gap_m=ring_reach_gap(1, APPENDIX_WAVELENGTH_M, FORMAMIDE_REFRACTIVE_INDEX),
        roughness=Roughness(80e-9, 0.8, 10e-6, 32e-9),
        settings=settings,
        rng_seed=5,
    )


def test_contact_stays_inside_the_solver_window(solution):
    for result in solution.results:
        edge = np.zeros_like(result.contact)
        edge[[0, -1], :] = edge[:, [0, -1]] = True
        assert not (result.contact & edge).any()
    assert [r.load for r in solution.results] == pytest.approx([25e-3, 100e-3], rel=1e-8)


@pytest.mark.parametrize("index", [0, 1])
def test_image_grid_carries_the_load_and_the_area(solution, index):
    """Pixel-averaged pressure on 200 nm pixels sums to the load: the 4×4 nearest-pixel
    sub-sampling of a 256 nm grid moves patch edges by < 64 nm, so 2 % on Σp; the
    half-covered contact mask keeps the area within 5 % (patch edges, both ways)."""
    result = solution.results[index]
    pixel = 200e-9
    side = int(np.ceil(solution.window_m / pixel)) // 2 * 2
    state = image_contact_states(
        solution,
        (side, side),
        pixel,
        gap_index=index,
        closing_m=225e-9,
        confinement_floor_pa=50e6,
    )[index]
    assert state.pressure_pa.sum() * pixel**2 == pytest.approx(result.load, rel=0.02)
    assert state.contact.sum() * pixel**2 == pytest.approx(result.area, rel=0.05)
    assert state.area_m2 == result.area
    # bilinear gaps at pixel centres: a contact pixel's centre may sit over a neighbouring
    # open solver pixel, so the gap there is small, not zero
    assert np.all(state.gap_m >= 0) and np.median(state.gap_m[state.contact]) < 1e-9
    assert state.edge_gap_m >= 0
