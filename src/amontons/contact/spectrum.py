"""The spectrum multiply of a convolution, on the operator's threads (numba kernels).

``multiply_spectrum``         ``spec *= multiplier``: the one step of a convolution outside
                              FFTW, on the operator's threads;
``multiply_spectrum_energy``  the same, returning ``Σ x·(K*x)`` (Parseval) taken before the
                              product, so a CG step needs no inverse transform.

Spectra are complex rfft2 half-spectra (rows in parallel), multipliers real (m/Pa). Rows are
summed in order, so the result is the same bit for bit on any number of threads.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import prange

from . import jit

_JIT = jit.JIT
_INNER = jit.INNER


@numba.njit(**_JIT)
def multiply_spectrum(spec, multiplier):
    """``spec *= multiplier`` in place (complex half-spectrum times the real kernel spectrum,
    m/Pa), rows in parallel: the one step of a convolution outside FFTW. Not numpy's product,
    which runs on one thread and casts the multiplier to complex (benchmarks/README.md, "Why
    the kernels are written as they are")."""
    for i in prange(spec.shape[0]):
        row = spec[i]
        mrow = multiplier[i]
        for j in range(row.size):
            row[j] = row[j] * mrow[j]


@numba.njit(**_JIT)
def multiply_spectrum_energy(spec, multiplier, nyquist):
    """``spec *= multiplier`` in place, as :func:`multiply_spectrum`, and return
    ``Σ w·multiplier·|spec|²`` taken before the product: with ``spec`` the rfft2 half-spectrum
    of a real field ``x`` and ``multiplier`` the kernel spectrum over the number of grid
    points, that is ``Σ x·(K*x)`` (Parseval), the CG step's denominator, without the inverse
    transform. ``nyquist``: the last column is the Nyquist one (even full length) and is
    counted once, like column 0. Rows are summed in order: the same bits on any thread
    count."""
    n0, m1 = spec.shape
    part = np.zeros(n0)
    last = m1 - 1
    for i in prange(n0):
        row = spec[i]
        mrow = multiplier[i]
        z0 = row[0]
        e0 = mrow[0] * (z0.real * z0.real + z0.imag * z0.imag)
        zl = row[last]
        el = mrow[last] * (zl.real * zl.real + zl.imag * zl.imag) if nyquist and last else 0.0
        part[i] = 2.0 * _row_product_energy(row, mrow) - e0 - el
    total = 0.0
    for i in range(n0):
        total += part[i]
    return total


@numba.njit(**_INNER)
def _row_product_energy(row, mrow):
    """``row *= mrow`` in place; returns ``Σ_j mrow_j |row_j|²`` taken before."""
    acc = 0.0
    for j in range(row.size):
        z = row[j]
        k = mrow[j]
        acc += k * (z.real * z.real + z.imag * z.imag)
        row[j] = z * k
    return acc


# the kernels called from Python (the others are compiled into them)
ENTRY_POINTS = (multiply_spectrum, multiply_spectrum_energy)


def spectrum_threads(threads: int):
    """Context: run the spectrum kernels on ``threads`` threads (:func:`.jit.kernel_threads`)."""
    return jit.kernel_threads(threads, ENTRY_POINTS)
