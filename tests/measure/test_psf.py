"""PSF FWHM from a bead image (appendix Fig. B.2), against the forward model's known FWHM."""

import numpy as np
import pytest

from amontons.measure.psf import PsfError, measure_psf
from amontons.virtual.bead import expected_bead_counts, render_bead

PIXEL = 200e-9
FWHM = 450e-9
# Realistic confocal counts: ~900 counts in the brightest pixel over a 50-count background
# (Poisson noise ≈ 7 counts there, ≈ 30 counts at the peak).
AMPLITUDE = 1000.0
BACKGROUND = 50.0
CENTRE = (20.3 * PIXEL, 19.7 * PIXEL)  # off the pixel grid on purpose


def bead(seed: int, shape=(41, 41), centre=CENTRE, amplitude=AMPLITUDE) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return render_bead(shape, PIXEL, FWHM, centre, amplitude, BACKGROUND, rng)


def test_noise_free_bead_gives_the_fwhm_and_centre():
    # Without noise only the Gaussian approximation of the pixel-integrated profile is left:
    # the pixel correction σ² − p²/12 is good to ~0.2 %, so 0.5 % must hold.
    image = expected_bead_counts((41, 41), PIXEL, FWHM, CENTRE, AMPLITUDE, BACKGROUND)
    result = measure_psf(image, PIXEL)
    assert result.fwhm_m == pytest.approx(FWHM, rel=0.005)
    assert result.centroid_m == pytest.approx(CENTRE, abs=0.01 * PIXEL)
    # Without the correction the fitted FWHM is ~4 % too wide: the correction matters.
    assert result.fitted_fwhm_m > 1.03 * FWHM


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_noisy_bead_fwhm_within_3_percent(seed):
    # Shot noise at these counts scatters the FWHM by ~1.2 % (sd over 40 seeds), so 3 % is
    # a > 2.5 σ bound that a wrong centroid or missing pixel correction (+4 %) breaks.
    result = measure_psf(bead(seed), PIXEL)
    assert result.fwhm_m == pytest.approx(FWHM, rel=0.03)
    # The reported standard error should describe that scatter (within a factor of 3).
    assert 0.004 * FWHM < result.fwhm_se_m < 0.04 * FWHM
    assert result.background_counts == pytest.approx(BACKGROUND, abs=5)
    # Radial profile: starts near the peak, decays to the background.
    assert result.profile_counts[0] > 10 * BACKGROUND
    assert result.profile_counts[-1] == pytest.approx(BACKGROUND, abs=10)


def test_bead_near_the_edge_is_refused():
    image = bead(3, centre=(3 * PIXEL, 20 * PIXEL))
    with pytest.raises(PsfError, match="from the image edge.*margin of 2e-06 m"):
        measure_psf(image, PIXEL)


def test_saturated_bead_is_refused():
    image = bead(4)
    image[20, 20] = np.iinfo(np.uint16).max
    with pytest.raises(PsfError, match="1 saturated pixels.*65535"):
        measure_psf(image, PIXEL)


def test_forward_model_refuses_to_saturate():
    with pytest.raises(ValueError, match="saturate uint16"):
        bead(5, amplitude=80_000)


def test_image_without_bead_is_refused():
    rng = np.random.default_rng(6)
    image = rng.poisson(BACKGROUND, size=(41, 41)).astype(np.uint16)
    with pytest.raises(PsfError, match="no bead"):
        measure_psf(image, PIXEL)


def test_forward_model_is_deterministic_and_uint16():
    first, second = bead(7), bead(7)
    assert first.dtype == np.uint16
    np.testing.assert_array_equal(first, second)


def _coverage(amplitude, background, gain, n_beads, seed):
    """Share of beads whose FWHM ± 1.96 SE covers the true FWHM, and the mean dispersion:
    beads of a 380 nm PSF on 160 nm pixels (not the virtual experiment's 450 nm and 200 nm),
    each at a random sub-pixel centre, in 40 × 40 images; ``gain`` counts per photon."""
    pixel, fwhm = 160e-9, 380e-9
    rng = np.random.default_rng(seed)
    covered, dispersions = [], []
    for _ in range(n_beads):
        centre = tuple((20 + rng.uniform(-0.5, 0.5, size=2)) * pixel)
        photons = render_bead((40, 40), pixel, fwhm, centre, amplitude / gain, background, rng)
        result = measure_psf(photons.astype(np.uint16) * gain, pixel)
        covered.append(abs(result.fwhm_m - fwhm) < 1.96 * result.fwhm_se_m)
        dispersions.append(result.dispersion)
    return np.mean(covered), np.mean(dispersions)


def test_standard_error_covers_the_truth_95_percent_of_the_time():
    """Coverage over 250 simulated beads (600 counts peak on 30 background, Poisson): the
    95 % interval must cover the true FWHM in 90-98 % of beads. The binomial spread of 250
    trials at p = 0.95 is ±1.4 %, so the band is ~3 SD below and ~2 SD above; the old
    unweighted radial fit covered 49 % here (its SE 2.4 nm against a scatter of 6.6 nm)."""
    coverage, dispersion = _coverage(600.0, 30.0, gain=1, n_beads=250, seed=2024)
    assert 0.90 <= coverage <= 0.98
    assert dispersion == pytest.approx(1.0, abs=0.1)  # Poisson counts: χ²/dof ≈ 1


def test_overdispersed_counts_widen_the_standard_error():
    """A camera with 4 counts per photon: the counts scatter 2× more than Poisson's √mean,
    so the SE from the Poisson information alone would cover ~66 %; the Pearson dispersion
    (≈ 4) widens it back. 200 beads: binomial spread ±1.5 %, band 90-98 % as above."""
    coverage, dispersion = _coverage(1200.0, 10.0, gain=4, n_beads=200, seed=7)
    assert dispersion == pytest.approx(4.0, rel=0.15)
    assert 0.90 <= coverage <= 0.98
