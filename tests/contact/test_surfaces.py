"""Self-affine surface synthesis."""

import numpy as np
import pytest

from amontons.contact import self_affine, sphere
from amontons.contact.surfaces import rms_slope


def test_rms_slope_and_height_exact():
    """The realisation is rescaled to the requested value: exact to round-off (1e-12)."""
    h = self_affine((64, 96), 2e-9, 0.8, rms_slope=0.1, rng=3)
    assert abs(rms_slope(h, 2e-9) / 0.1 - 1) < 1e-12
    h = self_affine((64, 64), 2e-9, 0.5, rms_height=5e-9, rng=3)
    assert abs(h.std() / 5e-9 - 1) < 1e-12
    assert abs(h.mean()) < 1e-12 * 5e-9


def test_seeded_and_reproducible():
    a = self_affine((32, 32), 1.0, 0.8, rms_slope=0.1, rng=11)
    b = self_affine((32, 32), 1.0, 0.8, rms_slope=0.1, rng=np.random.default_rng(11))
    c = self_affine((32, 32), 1.0, 0.8, rms_slope=0.1, rng=12)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_power_spectrum_exponent():
    """Radially averaged PSD ∝ q^(-2-2H): fitted exponent within 0.15 of -3.6 for H = 0.8
    (a single 256² realisation scatters by a few %), and nothing above the short cutoff."""
    n, hurst = 256, 0.8
    h = self_affine((n, n), 1.0, hurst, rms_height=1.0, short_cutoff=8.0, rng=5)
    spec = np.abs(np.fft.fft2(h)) ** 2
    q = 2 * np.pi * np.hypot(*np.meshgrid(np.fft.fftfreq(n), np.fft.fftfreq(n)))
    assert spec[q > 2 * np.pi / 8.0 * 1.0001].max() < 1e-20 * spec.max()
    edges = np.geomspace(2 * np.pi / n * 2, 2 * np.pi / 8.0, 12)
    qm, cm = [], []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        sel = (q >= lo) & (q < hi)
        qm.append(q[sel].mean())
        cm.append(spec[sel].mean())
    slope = np.polyfit(np.log(qm), np.log(cm), 1)[0]
    assert slope == pytest.approx(-2 - 2 * hurst, abs=0.15)


def test_sphere_apex_and_symmetry():
    h = sphere((5, 5), 1.0, 2.0)
    assert h[2, 2] == 0 and h[0, 2] == pytest.approx(-4 / 4)
    np.testing.assert_array_equal(h, h[::-1, ::-1])
