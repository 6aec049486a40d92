"""Green's functions: Love square-patch kernel and periodic multiplier against analytics."""

import numpy as np
import pytest

from amontons.contact.convolution import PeriodicConvolution
from amontons.contact.greens import hockney_kernel, love_square, periodic_multiplier


def test_love_centre_value():
    """Centre of a uniformly loaded square: u = (8a/(πE*)) ln(1+√2) = 2.2444 a/E*.

    Closed form, so the tolerance is round-off (1e-12 relative).
    """
    a, e_star = 0.37, 2.5
    u = love_square(0.0, 0.0, a, a, e_star)
    expected = 8 * a / (np.pi * e_star) * np.log(1 + np.sqrt(2))
    assert abs(u / expected - 1) < 1e-12
    assert abs(expected * e_star / a - 2.2444) < 1e-4


def test_love_far_field_is_boussinesq():
    """Far from the patch the kernel is Boussinesq's u = F/(π E* r) with F = p·(2a)².

    The patch's finite size corrects the point-load value by O((a/r)²): at r = 40 a
    that is < 1e-3, so the tolerance is 1e-3 relative.
    """
    a, e_star, r = 0.5, 3.0, 20.0
    u = love_square(r, 0.0, a, a, e_star)
    expected = (2 * a) ** 2 / (np.pi * e_star * r)
    assert abs(u / expected - 1) < 1e-3


def test_hockney_kernel_wrapped_and_even():
    """The padded kernel uses wrapped offsets, so it is even: k[i] == k[-i] exactly."""
    k = hockney_kernel((6, 5), 0.1, 1.0)
    assert k.shape == (12, 10)
    np.testing.assert_array_equal(k[1:, :], k[1:, :][::-1, :])
    np.testing.assert_array_equal(k[:, 1:], k[:, 1:][:, ::-1])
    assert abs(k[0, 0] / love_square(0, 0, 0.05, 0.05, 1.0) - 1) < 1e-15


def test_periodic_single_mode_amplitude():
    """p = p̂ cos(q·x) gives u = 2 p̂ cos(q·x)/(E*|q|), |q| = 2π|k|/L (angular wavenumber).

    Exact for a grid-resolved mode up to FFT round-off: tolerance 1e-12 relative.
    Checked for an x mode, a y mode and an oblique mode on a non-square grid.
    """
    n0, n1, dx, e_star, p_hat = 32, 48, 0.25, 7.0, 3.0
    x = np.arange(n0)[:, None] * dx
    y = np.arange(n1)[None, :] * dx
    op = PeriodicConvolution((n0, n1), dx, e_star, backend="numpy")
    for k0, k1 in [(3, 0), (0, 5), (2, 7)]:
        qx, qy = 2 * np.pi * k0 / (n0 * dx), 2 * np.pi * k1 / (n1 * dx)
        phase = qx * x + qy * y
        u = op(p_hat * np.cos(phase))
        expected = 2 * p_hat / (e_star * np.hypot(qx, qy)) * np.cos(phase)
        assert np.abs(u - expected).max() < 1e-12 * np.abs(expected).max()


def test_periodic_rigid_mode_is_zero():
    """A uniform pressure produces no displacement: the q = 0 mode is the rigid mode."""
    mult = periodic_multiplier((8, 8), 1.0, 1.0)
    assert mult[0, 0] == 0.0
    op = PeriodicConvolution((8, 8), 1.0, 1.0, backend="numpy")
    assert np.abs(op(np.full((8, 8), 5.0))).max() < 1e-14


def test_hockney_kernel_on_a_larger_padded_grid():
    """On an m0 × m1 grid (m >= 2n, odd and even) the entries that reach the n0 × n1 window,
    offsets -(n-1)..(n-1), are the Love kernel at those offsets, and the kernel stays even;
    (2n0, 2n1) gives the plain kernel bit for bit; m < 2n is refused. Tolerance 1e-12
    relative (round-off): the kernel is evaluated at |offset|, the check at the signed
    offset, and love_square's logs of near-equal ratios differ there by ~1e-14; a wrong
    offset (one pixel) would be off by >= 1e-3."""
    n0, n1, dx = 6, 5, 0.1
    k = hockney_kernel((n0, n1), dx, 1.0, padded_shape=(15, 12))
    assert k.shape == (15, 12)
    for i in range(-(n0 - 1), n0):
        for j in range(-(n1 - 1), n1):
            expected = love_square(i * dx, j * dx, dx / 2, dx / 2, 1.0)
            assert abs(k[i % 15, j % 12] / expected - 1) < 1e-12
    np.testing.assert_array_equal(k[1:, :], k[1:, :][::-1, :])
    np.testing.assert_array_equal(k[:, 1:], k[:, 1:][:, ::-1])
    plain = hockney_kernel((n0, n1), dx, 1.0)
    np.testing.assert_array_equal(hockney_kernel((n0, n1), dx, 1.0, (12, 10)), plain)
    with pytest.raises(ValueError):
        hockney_kernel((n0, n1), dx, 1.0, padded_shape=(11, 10))
