"""Convolution operators: pruned == plain padded == brute force; backends agree."""

import numpy as np
import pytest

from amontons.contact.convolution import (
    NonPeriodicConvolution,
    PeriodicConvolution,
    direct_convolution,
)
from amontons.contact.fft import HAVE_PYFFTW, fast_length
from amontons.contact.kernels import add_point_responses

BACKENDS = ["numpy"] + (["pyfftw"] if HAVE_PYFFTW else [])

# Every comparison below is between exact methods that differ only by floating-point
# summation order, so the tolerance is round-off: 1e-12 of the field's maximum.
RTOL = 1e-12


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("shape", [(6, 8), (7, 5), (1, 9)])
def test_nonperiodic_pruned_plain_direct(backend, shape):
    """Pruned, plain 2N×2N and brute-force Love-kernel sums agree to round-off
    (odd, even and degenerate one-row shapes)."""
    rng = np.random.default_rng(1)
    p = rng.random(shape)
    ref = direct_convolution(p, 0.3, 2.0, periodic=False)
    pruned = NonPeriodicConvolution(shape, 0.3, 2.0, backend=backend, pruned=True)(p)
    plain = NonPeriodicConvolution(shape, 0.3, 2.0, backend=backend, pruned=False)(p)
    scale = np.abs(ref).max()
    assert np.abs(pruned - ref).max() < RTOL * scale
    assert np.abs(plain - ref).max() < RTOL * scale


@pytest.mark.parametrize("backend", BACKENDS)
def test_periodic_matches_direct(backend):
    """Periodic FFT convolution equals the explicit Fourier sum on a tiny grid."""
    rng = np.random.default_rng(2)
    p = rng.random((6, 9))
    ref = direct_convolution(p, 0.5, 3.0, periodic=True)
    u = PeriodicConvolution(p.shape, 0.5, 3.0, backend=backend)(p)
    assert np.abs(u - ref).max() < RTOL * np.abs(ref).max()


@pytest.mark.skipif(not HAVE_PYFFTW, reason="pyfftw not installed")
@pytest.mark.parametrize("periodic", [True, False])
def test_backends_agree_and_operator_is_reusable(periodic):
    """pyfftw and numpy give the same field; repeated calls on the cached plans (which
    reuse work arrays and padding) give the same answer as the first call."""
    rng = np.random.default_rng(3)
    shape = (64, 48)
    cls = PeriodicConvolution if periodic else NonPeriodicConvolution
    a = cls(shape, 1e-6, 1e9, backend="numpy")
    b = cls(shape, 1e-6, 1e9, backend="pyfftw", threads=2)
    for _ in range(3):
        p = rng.random(shape) * 1e6
        ua, ub = a(p), b(p)
        assert np.abs(ua - ub).max() < RTOL * np.abs(ua).max()


def test_nonperiodic_is_symmetric_operator():
    """Reciprocity: <q, K p> == <p, K q> (the CG needs a symmetric operator)."""
    rng = np.random.default_rng(4)
    op = NonPeriodicConvolution((20, 17), 1.0, 1.0, backend=BACKENDS[-1])
    p, q = rng.random((20, 17)), rng.random((20, 17))
    lhs, rhs = np.vdot(q, op(p)), np.vdot(p, op(q))
    assert abs(lhs - rhs) < 1e-12 * abs(lhs)


def test_point_responses_equal_convolution():
    """The CG's sparse displacement update (periodic operator) adds the responses of a few
    point pressures; it must equal the FFT convolution of the same field to round-off,
    including points next to the wrap-around edges."""
    shape = (12, 10)
    op = PeriodicConvolution(shape, 0.7, 2.0, backend=BACKENDS[-1])
    idx = np.array([0, 5, 11, 10 * 11 + 9, 10 * 6 + 3])
    vals = np.array([1.0, -2.0, 0.5, 3.0, 1.5])
    p = np.zeros(shape)
    np.add.at(p.ravel(), idx, vals)
    ref = op(p)
    out = np.zeros(shape)
    op.add_point_responses(out, idx, vals)
    assert np.abs(out - ref).max() < RTOL * np.abs(ref).max()


def _is_fftw_fast(m):
    """Even and of the form 2^a 3^b 5^c 7^d 11^e 13^f with e + f <= 1 (by trial division)."""
    if m % 2:
        return False
    big = 0
    for f in (11, 13):
        while m % f == 0:
            m //= f
            big += 1
    for f in (2, 3, 5, 7):
        while m % f == 0:
            m //= f
    return m == 1 and big <= 1


def test_fast_length_is_the_smallest_fast_length():
    """fast_length(n) is the first length >= n that passes the trial-division check."""
    for n in range(1, 4000):
        m = n
        while not _is_fftw_fast(m):
            m += 1
        assert fast_length(n) == m, n
    # the windows of the problem statement: 2n = 2³·107, 2·461, 2³·461
    assert [fast_length(2 * n) for n in (428, 461, 1844)] == [864, 924, 3696]


# Windows whose plain Hockney size 2n has a large prime factor (106 = 2·53, 118 = 2·59,
# 94 = 2·47) and ordinary ones (2n already fast: 64, 48).
LARGE_PRIME_SHAPES = [(53, 53), (59, 47)]
ORDINARY_SHAPES = [(32, 24)]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("shape", LARGE_PRIME_SHAPES + ORDINARY_SHAPES)
def test_fast_padding_equals_direct_and_plain_hockney(backend, shape):
    """The operator pads to fast lengths (reported in padded_shape), and its field equals
    the brute-force Love sum and the plain 2n × 2n Hockney operator to round-off (RTOL):
    padding beyond 2n changes only the summation order."""
    rng = np.random.default_rng(5)
    p = rng.random(shape)
    ref = direct_convolution(p, 0.3, 2.0, periodic=False)
    plain = NonPeriodicConvolution(
        shape, 0.3, 2.0, backend=backend, padded_shape=(2 * shape[0], 2 * shape[1])
    )
    assert plain.padded_shape == (2 * shape[0], 2 * shape[1])
    u_plain = plain(p)
    scale = np.abs(ref).max()
    for pruned in (True, False):
        op = NonPeriodicConvolution(shape, 0.3, 2.0, backend=backend, pruned=pruned)
        assert op.padded_shape == tuple(fast_length(2 * n) for n in shape)
        assert op.multiplier.shape == (op.padded_shape[0], op.padded_shape[1] // 2 + 1)
        for _ in range(2):  # the second call runs on the reused work arrays and padding
            u = op(p)
            assert np.abs(u - ref).max() < RTOL * scale
            assert np.abs(u - u_plain).max() < RTOL * scale
    if shape in LARGE_PRIME_SHAPES:
        assert op.padded_shape != plain.padded_shape  # the test exercises m > 2n


@pytest.mark.parametrize("backend", BACKENDS)
def test_any_padding_at_least_2n_is_exact(backend):
    """Odd and generous paddings (m0 = 2n0 + 7, m1 = 3n1) give the same field: the kernel
    embedding is right for every m >= 2n, not only for the lengths fast_length picks."""
    rng = np.random.default_rng(6)
    shape = (13, 10)
    p = rng.random(shape)
    ref = direct_convolution(p, 0.3, 2.0, periodic=False)
    for pruned in (True, False):
        op = NonPeriodicConvolution(
            shape, 0.3, 2.0, backend=backend, pruned=pruned, padded_shape=(33, 30)
        )
        assert np.abs(op(p) - ref).max() < RTOL * np.abs(ref).max()


def test_padding_below_2n_is_refused():
    """m < 2n would wrap the window onto itself (a wrong, circular answer): refused."""
    with pytest.raises(ValueError, match="smaller than 2"):
        NonPeriodicConvolution((8, 8), 1.0, 1.0, backend="numpy", padded_shape=(16, 15))


@pytest.mark.parametrize("shape", LARGE_PRIME_SHAPES)
def test_point_responses_on_fast_padded_kernel(shape):
    """The fused CG's sparse update sweeps real_space_kernel(), which lives on the padded
    grid (m > 2n here): it must give the convolution of the same point pressures to
    round-off (1e-12 of the peak), including points at the window's corners."""
    n0, n1 = shape
    op = NonPeriodicConvolution(shape, 0.5, 2.0, backend=BACKENDS[-1])
    assert op.real_space_kernel().shape == op.padded_shape
    idx = np.array([0, n1 - 1, n0 * n1 - n1, n0 * n1 - 1, n1 * (n0 // 2) + 3])
    vals = np.array([1.0, -2.0, 0.5, 3.0, 1.5])
    c = np.zeros(n0 * n1)
    np.add.at(c, idx, vals)
    ref = op(c.reshape(shape))
    u = np.zeros(shape)
    add_point_responses(u, op.real_space_kernel(), idx, vals)
    assert np.abs(u - ref).max() <= 1e-12 * np.abs(ref).max()
