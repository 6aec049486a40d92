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

The plain (unpruned) transform: the row pruning of the CPU operator saves a quarter of the
FFT work, which on a GPU is not measured (an iteration's time there went to kernel
launches first: benchmarks/README.md, "The GPU route"). The operator
does not split into halves (``splits`` is False): :func:`.cg.polonsky_keer` then takes
``r = K*t`` whole and ``Σ r t`` from ``r``.
"""

from __future__ import annotations

from .greens import hockney_multiplier, periodic_multiplier


class ArrayConvolution:
    """``u = K*p`` on an ``n0 × n1`` grid (pressure Pa, displacement m) with the FFT of the
    array namespace ``xp``; ``padded_shape`` None for the periodic operator, else the
    Hockney grid ``(m0, m1)``, ``m >= 2n`` (:func:`.convolution.fast_padded_shape`)."""

    splits = False

    def __init__(self, shape, spacing, e_star, xp, padded_shape=None):
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

    def __call__(self, p, out=None):
        """The displacement (m) of pressure ``p`` (Pa, an array of ``xp``); into ``out`` if
        given."""
        self.ncalls += 1
        xp = self.xp
        n0, n1 = self.shape
        spec = xp.fft.rfft2(p, s=self.fft_shape)  # zero-padded to fft_shape when padded
        spec *= self.multiplier
        result = xp.fft.irfft2(spec, s=self.fft_shape)[:n0, :n1]
        if out is None:
            return xp.ascontiguousarray(result)
        out[...] = result
        return out

    def real_space_kernel(self):
        """The kernel of the (padded) circular convolution on ``fft_shape``, m/Pa, as
        :meth:`.convolution.PeriodicConvolution.real_space_kernel` (built once)."""
        if self._green is None:
            self._green = self.xp.fft.irfft2(self.multiplier, s=self.fft_shape)
        return self._green
