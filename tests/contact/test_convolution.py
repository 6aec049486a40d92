"""Convolution operators: pruned == plain padded == brute force; backends agree."""

import numpy as np
import pytest

from amontons.contact.convolution import (
    NonPeriodicConvolution,
    PeriodicConvolution,
    direct_convolution,
)
from amontons.contact.fft import HAVE_PYFFTW

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
