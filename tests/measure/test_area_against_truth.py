"""Otsu contact area against the virtual experiment's truth (issue 6).

The probe's emission is √max(p, p_c) in contact (amontons.virtual.fluorescence). The
virtual experiment's default is the appendix's bare √p law (p_c = 0), which fades to the
background at every rim, and Otsu leaves that rim out. With a confinement floor (here
p_c = 50 MPa) a smooth contact is recovered to < 1 % by Otsu in a perfect image, and what is
left on a rough contact is pixelisation (patches a few 200 nm pixels wide). These tests pin
down each effect with the number it was measured at."""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from amontons.contact import ContactHardening
from amontons.measure.area import otsu_contact_area
from amontons.physics.gaussian import FWHM_PER_SIGMA
from amontons.physics.newton_rings import APPENDIX_WAVELENGTH_M, FORMAMIDE_REFRACTIVE_INDEX
from amontons.virtual.fluorescence import render_fluorescence
from amontons.virtual.hertz_contact import hertz_contact_state
from amontons.virtual.rough_contact import (
    SolverSettings,
    image_contact_states,
    ring_reach_gap,
    simulate_rough_sphere,
)
from amontons.virtual.roughness import Roughness

PIXEL, FWHM, BACKGROUND, COUNTS, FLOOR = 200e-9, 450e-9, 120.0, 1500.0, 50e6
SIGMA_PX = FWHM / FWHM_PER_SIGMA / PIXEL


@pytest.fixture(scope="module", params=["PS", "glass"])
def rough_solution(request):
    """A rough PS sphere (80 nm, k = 5 MPa/nm) and a 3 nm rough glass sphere at 25 and
    200 mN (solver grid 256 nm, the small-data setting)."""
    radius, e_star, rms, k = {
        "PS": (0.3e-3, 3.7e9, 80e-9, 5e15),
        "glass": (2e-3, 32.8e9, 3e-9, 1e19),
    }[request.param]
    solution = simulate_rough_sphere(
        radius_m=radius,
        e_star_pa=e_star,
        law=ContactHardening(k),
        loads_n=[25e-3, 200e-3],
        reflection_load_n=25e-3,
        ring_reach_gap_m=ring_reach_gap(1, APPENDIX_WAVELENGTH_M, FORMAMIDE_REFRACTIVE_INDEX),
        roughness=Roughness(rms, 0.8, 10e-6, 32e-9),
        settings=SolverSettings(256e-9, 512, 1.3),
        rng_seed=2,
    )
    return request.param, solution


def _states(solution, floor):
    """The solution on 200 nm image pixels with the given confinement floor."""
    side = int(np.ceil(min(solution.window_m, 60e-6) / PIXEL)) // 2 * 2
    return image_contact_states(
        solution,
        (side, side),
        PIXEL,
        gap_index=None,
        closing_m=FWHM / 2,
        confinement_floor_pa=floor,
    )


def _signal(state, reference):
    """Expected counts above background, scaled so the smallest load's mean pressure gives
    COUNTS (as the virtual experiment does)."""
    return COUNTS / np.sqrt(reference.load_n / reference.area_m2) * state.emission_sqrt_pa


def _noisy_image(state, reference, seed):
    """The fluorescence image of ``state`` as the virtual experiment renders it: PSF,
    background, shot noise."""
    return render_fluorescence(
        _signal(state, reference),
        PIXEL,
        psf_fwhm_m=FWHM,
        background_counts=BACKGROUND,
        rng=np.random.default_rng(seed),
    )


@pytest.mark.parametrize("floor", [0.0, FLOOR])
def test_otsu_area_equals_the_noise_free_blurred_truth_within_2_percent(rough_solution, floor):
    """Issue 6: the Otsu area of the noisy image equals that of the true map blurred by the
    same PSF and thresholded the same way within 2 % (measured: 0.0-0.6 %, either emission
    law): shot noise does not move Otsu's threshold."""
    states = _states(rough_solution[1], floor)
    for seed, state in enumerate(states):
        clean = gaussian_filter(_signal(state, states[0]), SIGMA_PX, mode="constant")
        measured = otsu_contact_area(_noisy_image(state, states[0], seed), PIXEL).area_m2
        reference = otsu_contact_area(clean + BACKGROUND, PIXEL).area_m2
        assert measured == pytest.approx(reference, rel=0.02)


@pytest.mark.parametrize("load", [25e-3, 100e-3, 300e-3])
def test_otsu_area_of_a_perfect_image_of_a_smooth_contact_is_the_true_area_within_1_percent(load):
    """Issue 6: with PSF and noise off, Otsu's area equals the true area within 1 % for the
    smooth glass sphere (measured −0.4 to −0.6 %: the rim pixels that the edge crosses)."""
    state = hertz_contact_state(load, 2e-3, 32.8e9, (320, 320), PIXEL, confinement_floor_pa=FLOOR)
    area = otsu_contact_area(_signal(state, state) + BACKGROUND, PIXEL)
    assert area.area_m2 == pytest.approx(state.area_m2, rel=0.01)


def test_otsu_area_of_a_perfect_image_of_a_rough_contact_is_pixelised(rough_solution):
    """With PSF and noise off and a confinement floor, a rough contact's Otsu area is still
    2-6 % below the true area (measured at 25 and 200 mN: glass −2.5 and −2.4 %, PS −4.7 and
    −5.6 %): patches a few pixels wide lose the pixels their edges only partly cover. The
    issue's 1 % is out of reach at 200 nm pixels for these contacts (closing note); the
    bounds are the measured band ± ~1 %, a loss, never a gain."""
    name, solution = rough_solution
    low, high = {"PS": (0.93, 0.965), "glass": (0.965, 0.985)}[name]
    states = _states(solution, FLOOR)
    for state in states:
        ratio = otsu_contact_area(_signal(state, states[0]) + BACKGROUND, PIXEL).area_m2
        assert low < ratio / state.area_m2 < high


@pytest.mark.parametrize("load", [25e-3, 300e-3])
def test_otsu_without_confinement_floor_loses_the_dim_rim_of_a_hertz_contact(load):
    """The bare √p law (p_c = 0): without PSF and noise, Otsu's area is the true area less the
    rim where √p is below the threshold: with √p ∝ (1 − r²/a²)^(1/4) and τ = threshold/(peak
    signal), the kept fraction is 1 − τ⁴ (measured −3 %); asserted to 0.5 % (pixelisation of
    the rim)."""
    state = hertz_contact_state(load, 2e-3, 32.8e9, (320, 320), PIXEL)
    signal = _signal(state, state)
    area = otsu_contact_area(signal + BACKGROUND, PIXEL)
    tau = (area.threshold - BACKGROUND) / signal.max()
    assert area.area_m2 / state.area_m2 == pytest.approx(1 - tau**4, abs=0.005)
    assert 0.95 < area.area_m2 / state.area_m2 < 0.99


def test_confinement_floor_keeps_the_rim_of_a_rough_contact(rough_solution):
    """The floor is what makes the Otsu area of the noisy image track the true area: with
    the bare √p law it keeps 82-95 % of it (measured at 25 and 200 mN: PS 0.819 and 0.852,
    glass 0.925 and 0.950), with the floor 90-100 % (PS 0.905 and 0.904, glass 0.995 and
    0.974), at every load at least 2 % more (glass at 200 mN: +2.4 %)."""
    solution = rough_solution[1]
    ratios = {}
    for floor in (0.0, FLOOR):
        states = _states(solution, floor)
        ratios[floor] = []
        for seed, state in enumerate(states):
            noisy = _noisy_image(state, states[0], seed)
            ratios[floor].append(otsu_contact_area(noisy, PIXEL).area_m2 / state.area_m2)
    bare, floored = np.array(ratios[0.0]), np.array(ratios[FLOOR])
    assert np.all((bare > 0.8) & (bare < 0.96))
    assert np.all((floored > 0.89) & (floored < 1.01))
    assert np.all(floored - bare > 0.02)


def test_blurred_binary_contact_map_overstates_the_measured_area(rough_solution):
    """The appendix compares simulated maps as regions of contact convolved with the PSF
    (B.2.4), i.e. a binary map, with measured Otsu areas. Under the √p emission law that
    binary rendering is brighter at every rim than the measured image, so its Otsu area
    exceeds the measured one by 6-21 % (measured at 25 and 200 mN: glass +11 and +6 %, PS +21
    and +17 %): a comparison of simulated and measured maps must render both with the same
    emission law. Bounds: the measured band ± ~3 %."""
    name, solution = rough_solution
    low, high = {"PS": (1.14, 1.25), "glass": (1.03, 1.14)}[name]
    states = _states(solution, 0.0)
    for seed, state in enumerate(states):
        noisy = _noisy_image(state, states[0], seed)
        binary = gaussian_filter(state.contact.astype(float), SIGMA_PX, mode="constant")
        ratio = otsu_contact_area(binary, PIXEL).area_m2 / otsu_contact_area(noisy, PIXEL).area_m2
        assert low < ratio < high, ratio
