"""The convolution ``u = K*p`` of the array kernel set, on an array namespace's FFT.

:class:`ArrayConvolution` is :mod:`.convolution`'s operator written once for any namespace
``xp`` with ``xp.fft.rfft2``/``irfft2`` (:mod:`.array_backends`): ``numpy.fft`` on the CPU
(tests), ``cupy.fft`` on a GPU, where CuPy keeps a cuFFT plan per transform shape in its
plan cache, so every call after the first on a grid reuses it. The kernel spectra are
those of :mod:`.greens`, built once on the host and moved to the namespace's memory:

periodic   ``u = irfft2(rfft2(p) · 2/(E*|q|))`` on the ``n0 × n1`` grid;
padded     Hockney: ``p`` zero-padded to ``padded_shape`` (``m >= 2n`` per axis, the
           CPU operator's), ``u`` the window of the circular convolution with the Love
           kernel's spectrum.

Where the namespace offers planned transforms (``ArrayModule.fft_pair``: cuFFT's plans run
directly on CuPy, ``numpy.fft`` on numpy), a call is the forward transform of ``p`` (into a
zero-padded buffer of the grid's when padded), one in-place product with the spectrum
divided by the grid's size (the inverse's normalisation folded in) and the inverse into
``out`` (through the padded buffer when padded): three launches periodic, five padded (the
copies into and out of the window), no temporary when ``p`` and ``out`` are contiguous,
where ``xp.fft`` pads into a new array, copies the spectrum (cuFFT's inverse overwrites its
input), normalises in a pass of its own and leaves the window to copy. The price is memory:
the cached operator keeps its spectrum, the padded buffers and both plans' work areas.

The plain (unpruned) transform: the row pruning of the CPU operator saves a quarter of the
FFT work, which on a GPU is not measured (an iteration's time there went to kernel
launches first: benchmarks/README.md, "The GPU route"). The operator
does not split into halves (``splits`` is False): :func:`.cg.polonsky_keer` then takes
``r = K*t`` whole and ``Σ r t`` from ``r``.
"""

from __future__ import annotations

import math

import numpy as np

from .greens import hockney_multiplier, periodic_multiplier


class ArrayConvolution:
    """``u = K*p`` on an ``n0 × n1`` grid (pressure Pa, displacement m) with the FFT of the
    array namespace ``xp``; ``padded_shape`` None for the periodic operator, else the
    Hockney grid ``(m0, m1)``, ``m >= 2n`` (:func:`.convolution.fast_padded_shape`);
    ``fft_pair`` the namespace's planned transforms (``ArrayModule.fft_pair``), or None for
    ``xp.fft``."""

    splits = False

    def __init__(self, shape, spacing, e_star, xp, padded_shape=None, fft_pair=None):
        self.shape = tuple(int(s) for s in shape)
        self.spacing = float(spacing)
        self.e_star = float(e_star)
        self.xp = xp
        self.periodic = padded_shape is None
        if self.periodic:
            self.fft_shape = self.shape
            multiplier = periodic_multiplier(self.shape, spacing, e_star)
        else:
            self.padded_shape = tuple(int(s) for s in padded_shape)
            self.fft_shape = self.padded_shape
            multiplier = hockney_multiplier(self.shape, spacing, e_star, self.padded_shape)
        self.multiplier = xp.asarray(multiplier)
        self._green = None
        self.ncalls = 0
        self._pair = None if fft_pair is None else fft_pair(self.fft_shape)
        if self._pair is not None:
            m0, m1 = self.fft_shape
            self._scaled = xp.asarray(multiplier / math.prod(self.fft_shape))
            self._spectrum = xp.empty((m0, m1 // 2 + 1), dtype=np.complex128)
            # the padded grid's buffers; the input's zeros outside the window stay zero
            self._padded_in = None if self.periodic else xp.zeros(self.fft_shape)
            self._padded_out = None if self.periodic else xp.empty(self.fft_shape)

    def __call__(self, p, out=None):
        """The displacement (m) of pressure ``p`` (Pa, an array of ``xp``); into ``out`` if
        given."""
        self.ncalls += 1
        if self._pair is not None:
            return self._planned(p, out)
        xp = self.xp
        n0, n1 = self.shape
        spec = xp.fft.rfft2(p, s=self.fft_shape)  # zero-padded to fft_shape when padded
        spec *= self.multiplier
        result = xp.fft.irfft2(spec, s=self.fft_shape)[:n0, :n1]
        if out is None:
            return xp.ascontiguousarray(result)
        out[...] = result
        return out

    def _planned(self, p, out):
        """``K*p`` through the planned transforms (module docstring), into ``out`` (of the
        window's shape, float64)."""
        xp, pair, spectrum = self.xp, self._pair, self._spectrum
        n0, n1 = self.shape
        if out is None:
            out = xp.empty(self.shape)
        if self.periodic:
            pair.forward(xp.ascontiguousarray(p), spectrum)
        else:
            self._padded_in[:n0, :n1] = p
            pair.forward(self._padded_in, spectrum)
        spectrum *= self._scaled
        if not self.periodic:
            pair.inverse(spectrum, self._padded_out)
            out[...] = self._padded_out[:n0, :n1]
        elif out.flags.c_contiguous:
            pair.inverse(spectrum, out)
        else:
            whole = xp.empty(self.shape)
            pair.inverse(spectrum, whole)
            out[...] = whole
        return out

    def real_space_kernel(self):
        """The kernel of the (padded) circular convolution on ``fft_shape``, m/Pa, as
        :meth:`.convolution.PeriodicConvolution.real_space_kernel` (built once)."""
        if self._green is None:
            self._green = self.xp.fft.irfft2(self.multiplier, s=self.fft_shape)
        return self._green
