"""Otsu contact area against the virtual experiment's truth (issue 6).

The fluorescence of a contact is ∝ √p (appendix Fig. B.4), so its rim is dim: Otsu's
threshold, half-way between the background and the contact populations, leaves the dimmest
contact out even in a perfect image. These tests pin down what the measurement does
(against the same map rendered without noise) and how far the appendix's method is from
the true area (the analytic rim loss of a Hertz contact)."""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from amontons.optics.area import otsu_contact_area
from amontons.virtual.experiment import hertz_contact_state
from amontons.virtual.fluorescence import FWHM_PER_SIGMA, render_fluorescence
from amontons.virtual.rough_contact import (
    SolverSettings,
    image_contact_states,
    simulate_rough_sphere,
)
from amontons.virtual.roughness import Roughness

PIXEL, FWHM, BACKGROUND, COUNTS = 200e-9, 450e-9, 120.0, 1500.0


@pytest.fixture(scope="module", params=["PS", "glass"])
def rough_states(request):
    """A rough PS sphere (80 nm, k = 5 MPa/nm) and a 3 nm rough glass sphere at 25 and
    200 mN, on 200 nm image pixels (solver grid 256 nm, the small-data setting)."""
    radius, e_star, rms, k = {
        "PS": (0.3e-3, 3.7e9, 80e-9, 5e15),
        "glass": (2e-3, 32.8e9, 3e-9, 1e19),
    }[request.param]
    solution = simulate_rough_sphere(
        radius_m=radius,
        e_star_pa=e_star,
        k_pa_per_m=k,
        loads_n=[25e-3, 200e-3],
        reflection_load_n=25e-3,
        rings=1,
        roughness=Roughness(rms, 0.8, 10e-6, 32e-9),
        settings=SolverSettings(256e-9, 512, 1.3),
        rng_seed=2,
    )
    side = int(np.ceil(min(solution.window_m, 60e-6) / PIXEL)) // 2 * 2
    return image_contact_states(solution, (side, side), PIXEL, gap_index=None, closing_m=FWHM / 2)


def _signal(state, reference):
    """Expected counts above background: √p scaled so the smallest load's mean pressure
    gives COUNTS (as the virtual experiment does)."""
    return COUNTS / np.sqrt(reference.load_n / reference.area_m2) * state.sqrt_pressure


def test_otsu_area_equals_the_noise_free_blurred_truth_within_2_percent(rough_states):
    """Issue 6: the Otsu area of the noisy image equals that of the true map blurred by the
    same PSF and thresholded the same way within 2 % (measured: 0.1-0.5 %): shot noise does
    not move Otsu's threshold."""
    sigma_px = FWHM / FWHM_PER_SIGMA / PIXEL
    for seed, state in enumerate(rough_states):
        signal = _signal(state, rough_states[0])
        noisy = render_fluorescence(
            signal,
            PIXEL,
            psf_fwhm_m=FWHM,
            background_counts=BACKGROUND,
            rng=np.random.default_rng(seed),
        )
        clean = gaussian_filter(signal, sigma_px, mode="constant") + BACKGROUND
        measured = otsu_contact_area(noisy, PIXEL).area_m2
        reference = otsu_contact_area(clean, PIXEL).area_m2
        assert measured == pytest.approx(reference, rel=0.02)


@pytest.mark.parametrize("load", [25e-3, 300e-3])
def test_otsu_without_psf_and_noise_loses_the_dim_rim_of_a_hertz_contact(load):
    """Without PSF and noise, Otsu's area is the true area less the rim where √p is below the
    threshold: with √p ∝ (1 − r²/a²)^(1/4) and τ = threshold/(peak signal), the kept
    fraction is 1 − τ⁴. Measured −3 % for the smooth glass sphere, so the issue's "within
    1 % of the true area" is out of reach for Otsu on a √p image (see the closing note); the
    test asserts the analytic loss to 0.5 % (pixelisation of the rim)."""
    state = hertz_contact_state(load, 2e-3, 32.8e9, (320, 320), PIXEL)
    signal = _signal(state, state)
    area = otsu_contact_area(signal + BACKGROUND, PIXEL)
    peak = signal.max()
    tau = (area.threshold - BACKGROUND) / peak
    assert area.area_m2 / state.area_m2 == pytest.approx(1 - tau**4, abs=0.005)
    assert 0.95 < area.area_m2 / state.area_m2 < 0.99  # the loss the closing note reports
