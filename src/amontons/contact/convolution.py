"""Convolution of a pressure field with the half-space Green's function.

Two operators map a pressure field (Pa) on an ``n0 × n1`` grid to the surface
displacement (m) on the same grid:

``PeriodicConvolution``
    ``u = irfft2(rfft2(p) · 2/(E*|q|))``: one forward and one inverse real 2-D FFT.

``NonPeriodicConvolution``
    Free-space convolution with the Love kernel through Hockney padding to an ``m0 × m1``
    grid, ``m = fast_length(2n)``: the smallest FFTW-friendly even length ``>= 2n`` on each
    axis (:func:`amontons.contact.fft.fast_length`). Any ``m >= 2n`` gives the same
    free-space result (:func:`.greens.hockney_kernel`), and FFTW is several times slower on
    a ``2n`` with a large prime factor (benchmarks/README.md, "Fast FFT lengths"). At least
    three quarters of the padded pressure are zero and only
    one quarter of the padded displacement is wanted, so the default *pruned* transform
    skips that work:

    forward  r2c along axis 1 (length m1) on the n0 non-zero rows only,
             then c2c along axis 0 (length m0) on the m1 // 2 + 1 spectral columns;
    multiply by the real kernel spectrum;
    inverse  c2c along axis 0 on the m1 // 2 + 1 columns,
             then c2r along axis 1 on the first n0 rows only, keep the first n1 columns.

    The row transforms touch n0 of the m0 rows of the plain ``m0 × m1`` transform, so the
    FFT work is about 3/4 of the plain one (ideal speed-up 4/3). ``pruned=False`` gives the
    plain transform, kept for tests and benchmarks. The window's copy into the padded rows,
    the zeroing of the spectrum's padding rows and the copy out run inside the row passes,
    each row slab's share in its own thread (:meth:`.fft.SlabTransform.execute`): on several
    threads no serial pass is left between the transforms.

Operators own aligned work arrays and FFTW plans; :func:`get_operator` caches them per
(shape, spacing, E*, periodic, backend, threads, pruned, planner effort). Operators are not
thread-safe (shared work arrays); use one process per concurrent solve.
"""

from __future__ import annotations

import functools

import numpy as np

from . import fft as _fft
from . import spectrum as _spectrum
from .array_backends import ARRAY_BACKENDS, array_module
from .array_convolution import ArrayConvolution
from .greens import hockney_multiplier, love_square, periodic_multiplier


def _scaled(mult, scale):
    """``scale·mult`` in place: the multiplier with the inverse DFT's 1/N folded in (the
    pyfftw plans run through ``execute()``, which does not normalise)."""
    mult *= scale
    return mult


def fast_padded_shape(shape) -> tuple[int, int]:
    """The FFT grid ``(m0, m1)`` of a Hockney-padded solve on an ``n0 × n1`` window: on each
    axis the smallest FFT-friendly length ``m >= 2n`` (:func:`amontons.contact.fft.fast_length`).
    Any ``m >= 2n`` gives the same free-space convolution (:func:`.greens.hockney_kernel`)."""
    return tuple(_fft.fast_length(2 * int(n)) for n in shape)


class _MultiplierMixin:
    def _multiply(self) -> None:
        """``spec *= multiplier`` on the operator's threads, by the numba kernel of
        :mod:`.spectrum` (the same bits as numpy's complex-by-real product, which is slower:
        benchmarks/README.md, benchmark 1)."""
        with _spectrum.spectrum_threads(self.threads):
            _spectrum.multiply_spectrum(self._spec, self._mult_scaled)

    @property
    def multiplier(self) -> np.ndarray:
        """Kernel spectrum on the rfft2 half-spectrum, m/Pa (see :mod:`.greens`)."""
        if self._multiplier is not None:
            return self._multiplier
        return self._mult_scaled / self._scale


class PeriodicConvolution(_MultiplierMixin):
    """Periodic half-space convolution ``u = K * p`` on an ``n0 × n1`` grid.

    Parameters
    ----------
    shape : (n0, n1)
    spacing : float
        Grid spacing, m.
    e_star : float
        Contact modulus, Pa.
    backend : {"pyfftw", "numpy", None}
    threads : int
        Threads of the transforms (:func:`amontons.contact.fft.real_fft2`) and of the
        spectrum multiply.
    planner_effort : str
        FFTW planner effort, one of :data:`amontons.contact.fft.PLANNER_EFFORTS`
        (default ``"FFTW_MEASURE"``, with the machine's wisdom on disk:
        :mod:`amontons.contact.wisdom`).
    """

    periodic = True

    def __init__(
        self,
        shape,
        spacing,
        e_star,
        backend=None,
        threads=1,
        planner_effort=_fft.DEFAULT_PLANNER_EFFORT,
    ):
        self.shape = tuple(int(s) for s in shape)
        self.spacing = float(spacing)
        self.e_star = float(e_star)
        self.backend = _fft.resolve_backend(backend)
        self.threads = int(threads)
        self.planner_effort = _fft.check_planner_effort(planner_effort)
        self._multiplier = periodic_multiplier(self.shape, spacing, e_star)
        self._green = None  # real-space kernel, built on first use
        self._inverse_multipliers = {}  # the preconditioner's, per compliance
        self.ncalls = 0
        if self.backend == "pyfftw":
            spec_shape = self._multiplier.shape
            self._real = _fft.empty(self.shape, np.float64, self.backend)
            self._spec = _fft.empty(spec_shape, np.complex128, self.backend)
            kw = {"threads": threads, "planner_effort": planner_effort}
            self._fwd = _fft.real_fft2(self._real, self._spec, **kw)
            self._inv = _fft.real_fft2(self._spec, self._real, inverse=True, **kw)
            # plans run through execute(), which does not normalise the inverse: fold the
            # 1/(n0 n1) of the inverse DFT into the multiplier instead of an extra pass
            self._scale = 1.0 / (self.shape[0] * self.shape[1])
            self._mult_scaled = _scaled(self._multiplier, self._scale)
            self._multiplier = None  # keep one copy only (memory)

    def __call__(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Return the displacement (m) of pressure ``p`` (Pa); writes into ``out`` if given.

        With pyfftw, when ``p`` and ``out`` are SIMD-aligned C-contiguous float64 arrays
        (e.g. from :func:`amontons.contact.fft.empty`) the plans run on them directly,
        without copies; anything else is copied through the plan's own arrays.
        """
        self.ncalls += 1
        if self.backend == "pyfftw":
            if out is not None and _fft.aligned(p, self.shape) and _fft.aligned(out, self.shape):
                # zero-copy: the r2c plan does not modify its input, the c2r plan writes out
                self._fwd.update_arrays(p, self._spec)
                self._fwd.execute()
                self._multiply()
                self._inv.update_arrays(self._spec, out)
                self._inv.execute()
                return out
            self._fwd.update_arrays(self._real, self._spec)
            self._inv.update_arrays(self._spec, self._real)
            self._real[...] = p
            self._fwd.execute()
            self._multiply()
            self._inv.execute()
            result = self._real
        else:
            result = np.fft.irfft2(np.fft.rfft2(p) * self._multiplier, s=self.shape)
        if out is None:
            return result.copy()
        out[...] = result
        return out

    @property
    def splits(self) -> bool:
        """Whether the convolution can be taken in halves (:meth:`forward`,
        :meth:`multiply_energy`, :meth:`inverse`): with the pyfftw backend."""
        return self.backend == "pyfftw"

    # the preconditioner's transforms in this operator's FFT pairs
    precondition_pairs = 1.0

    def precondition(self, x: np.ndarray, out: np.ndarray, compliance: float = 0.0):
        """``out`` = the kernel's inverse applied to ``x``: a displacement (m) to the
        pressure (Pa) that would cause it on the whole grid, ``F⁻¹[F[x] / (Ĝ + c)]`` with
        ``c`` a uniform Winkler ``compliance`` (m/Pa; 0 for the half-space alone), ``Ĝ``
        the periodic kernel's ``2/(E*|q|)``.

        The Fourier-diagonal preconditioner of :mod:`.preconditioned` (docs/models.md
        §2.2, "The preconditioned iteration"): one forward and one inverse transform on the
        operator's plans. Where ``Ĝ + c`` vanishes (the rigid mode without a compliance)
        the smallest nonzero value stands in: the iteration projects that mode out under
        load control, and under displacement control it must stay finite.
        """
        inverse = self._inverse_multiplier(float(compliance))
        if self.splits:
            self.forward(x)
            with _spectrum.spectrum_threads(self.threads):
                _spectrum.multiply_spectrum(self._spec, inverse)
            return self.inverse(out)
        out[...] = np.fft.irfft2(np.fft.rfft2(x) * inverse, s=self.shape)
        return out

    def _inverse_multiplier(self, compliance: float) -> np.ndarray:
        """``1/(Ĝ + c)`` on the half-spectrum (Pa/m), with the inverse DFT's ``1/N``
        folded in where the plans do not normalise (pyfftw); one array per compliance."""
        cache = self._inverse_multipliers
        if compliance not in cache:
            symbol = self.multiplier + compliance
            positive = symbol > 0
            if not positive.any():
                raise ValueError("the kernel's spectrum has no positive entry to invert")
            inverse = np.where(positive, 1.0 / np.where(positive, symbol, 1.0), 0.0)
            inverse[~positive] = 1.0 / symbol[positive].min()
            if self.splits:
                inverse *= self._scale
            cache[compliance] = inverse
        return cache[compliance]

    def forward(self, p: np.ndarray) -> None:
        """First half of ``K*p``: the spectrum of ``p`` (Pa) into the operator's work array.

        With :meth:`multiply_energy` and :meth:`inverse` this is ``__call__`` taken apart, so
        that the CG step can have ``Σ p·(K*p)`` from the spectrum and skip the inverse when
        the displacement is taken afresh anyway (:mod:`.cg`). pyfftw backend only.
        """
        if _fft.aligned(p, self.shape):
            self._fwd.update_arrays(p, self._spec)
        else:
            self._real[...] = p
            self._fwd.update_arrays(self._real, self._spec)
        self._fwd.execute()

    def multiply_energy(self) -> float:
        """Second half: the work spectrum times the kernel's; returns ``Σ p·(K*p)``
        (m·Pa) of the field last given to :meth:`forward`, by Parseval."""
        with _spectrum.spectrum_threads(self.threads):
            return _spectrum.multiply_spectrum_energy(
                self._spec, self._mult_scaled, self.shape[1] % 2 == 0
            )

    def inverse(self, out: np.ndarray) -> np.ndarray:
        """Last part: ``out = K*p`` (m) from the multiplied work spectrum."""
        if _fft.aligned(out, self.shape):
            self._inv.update_arrays(self._spec, out)
            self._inv.execute()
            return out
        self._inv.update_arrays(self._spec, self._real)
        self._inv.execute()
        out[...] = self._real
        return out

    def real_space_kernel(self) -> np.ndarray:
        """The periodic kernel ``G = irfft2(2/(E*|q|))`` on the grid, m/Pa (built once)."""
        if self._green is None:
            self._green = np.fft.irfft2(self.multiplier, s=self.shape)
        return self._green

    def add_point_responses(self, out: np.ndarray, idx, values) -> None:
        """``out += Σ_j values_j · G(x - x_j)``: displacement (m) of uniform pressures
        ``values`` (Pa) on the single pixels with flat indices ``idx``, added in place.

        Uses the real-space periodic kernel ``G = irfft2(2/(E*|q|))`` (the same discrete
        operator as the FFT path, so results agree to round-off); each point costs a few
        passes over the grid, which beats a convolution for a handful of points.
        """
        g = self.real_space_kernel()
        n0, n1 = self.shape
        for k, v in zip(np.asarray(idx).tolist(), np.asarray(values).tolist(), strict=True):
            a, b = divmod(k, n1)
            # out[i, j] += v G[(i - a) mod n0, (j - b) mod n1], as four un-wrapped blocks
            out[a:, b:] += v * g[: n0 - a, : n1 - b]
            if b:
                out[a:, :b] += v * g[: n0 - a, n1 - b :]
            if a:
                out[:a, b:] += v * g[n0 - a :, : n1 - b]
            if a and b:
                out[:a, :b] += v * g[n0 - a :, n1 - b :]


class NonPeriodicConvolution(_MultiplierMixin):
    """Free-space (Hockney-padded) half-space convolution on an ``n0 × n1`` window.

    Parameters
    ----------
    shape : (n0, n1)
    spacing : float
        Grid spacing, m.
    e_star : float
        Contact modulus, Pa.
    backend : {"pyfftw", "numpy", None}
    threads : int
        Threads of the transforms (:func:`amontons.contact.fft.axis_fft`) and of the
        spectrum multiply.
    pruned : bool
        Use the pruned transform (default) or the plain ``m0 × m1`` one.
    planner_effort : str
        FFTW planner effort, one of :data:`amontons.contact.fft.PLANNER_EFFORTS`
        (default ``"FFTW_MEASURE"``, with the machine's wisdom on disk:
        :mod:`amontons.contact.wisdom`).
    padded_shape : (m0, m1), optional
        The FFT grid, ``m >= 2n`` on each axis; default :func:`fast_padded_shape` (the
        same result to round-off, faster). ``(2n0, 2n1)`` gives plain Hockney padding (tests
        and benchmarks). The operator's ``padded_shape`` attribute holds the one used.
    """

    periodic = False

    def __init__(
        self,
        shape,
        spacing,
        e_star,
        backend=None,
        threads=1,
        pruned=True,
        planner_effort=_fft.DEFAULT_PLANNER_EFFORT,
        padded_shape=None,
    ):
        self.shape = tuple(int(s) for s in shape)
        self.spacing = float(spacing)
        self.e_star = float(e_star)
        self.backend = _fft.resolve_backend(backend)
        self.threads = int(threads)
        self.pruned = bool(pruned)
        self.planner_effort = _fft.check_planner_effort(planner_effort)
        if padded_shape is None:
            padded_shape = fast_padded_shape(self.shape)
        self.padded_shape = tuple(int(s) for s in padded_shape)
        self._multiplier = hockney_multiplier(self.shape, spacing, e_star, self.padded_shape)
        self._green = None  # real-space kernel on the padded grid, built on first use
        self.ncalls = 0
        n0, n1 = self.shape
        m0, m1 = self.padded_shape
        be = self.backend
        if be != "pyfftw":
            return
        spec_shape = self._multiplier.shape  # (m0, m1 // 2 + 1)
        if self.pruned:
            # _rows: real rows; the right half is the padding and stays zero forever.
            # _spec: one complex work array for every stage. All column transforms run in
            # place: FFTW's in-place strided column transforms are faster than out-of-place
            # ones, which is worth re-zeroing the lower half per call (benchmarks/README.md,
            # §2 "Design note").
            self._rows = _fft.empty((n0, m1), np.float64, be)
            self._spec = _fft.empty(spec_shape, np.complex128, be)
            self._out = _fft.empty((n0, m1), np.float64, be)
            kw = {"threads": threads, "planner_effort": planner_effort}
            self._row_fwd = _fft.axis_fft(self._rows, self._spec[:n0], 1, **kw)
            self._col_fwd = _fft.axis_fft(self._spec, self._spec, 0, **kw)
            self._col_inv = _fft.axis_fft(self._spec, self._spec, 0, inverse=True, **kw)
            self._row_inv = _fft.axis_fft(self._spec[:n0], self._out, 1, inverse=True, **kw)
            # planning (FFTW_MEASURE and above) scribbles over the arrays: set the padding
            # afterwards
            self._rows[...] = 0.0
            # plans run through execute(), which does not normalise inverses: the
            # 1/(m0 · m1) of the inverse DFT is folded into the multiplier
            self._scale = 1.0 / (m0 * m1)
            self._mult_scaled = _scaled(self._multiplier, self._scale)
            self._multiplier = None  # keep one copy only (memory)
        else:
            self._real = _fft.empty((m0, m1), np.float64, be)
            self._spec = _fft.empty(spec_shape, np.complex128, be)
            kw = {"threads": threads, "planner_effort": planner_effort}
            self._fwd = _fft.real_fft2(self._real, self._spec, **kw)
            self._inv = _fft.real_fft2(self._spec, self._real, inverse=True, **kw)
            self._real[...] = 0.0
            self._scale = 1.0 / (m0 * m1)
            self._mult_scaled = _scaled(self._multiplier, self._scale)
            self._multiplier = None  # keep one copy only (memory)

    def precondition(self, x: np.ndarray, out: np.ndarray, compliance: float = 0.0):
        """The preconditioner of :meth:`PeriodicConvolution.precondition` on the window
        itself, periodic: the contact keeps off the window's edge, and the periodic inverse
        on ``n0 × n1`` costs a quarter of the padded one's transforms for the same
        iterations (benchmarks/README.md, benchmark 3b). Displacement m to pressure Pa."""
        window = get_operator(
            self.shape, self.spacing, self.e_star, periodic=True, backend=self.backend,
            threads=self.threads, planner_effort=self.planner_effort,
        )  # fmt: skip
        return window.precondition(x, out, compliance)

    @property
    def precondition_pairs(self) -> float:
        """The preconditioner's transforms in this operator's FFT pairs: the window's grid
        over the padded one."""
        return (self.shape[0] * self.shape[1]) / (self.padded_shape[0] * self.padded_shape[1])

    def real_space_kernel(self) -> np.ndarray:
        """The kernel of the padded circular convolution, ``padded_shape = (m0, m1)``, m/Pa
        (built once): the response at ``x`` of a unit pressure on the pixel at the origin is
        ``G[x mod m]``, the same discrete operator as the FFT path. m0·m1 floats."""
        if self._green is None:
            self._green = np.fft.irfft2(self.multiplier, s=self.padded_shape)
        return self._green

    @property
    def splits(self) -> bool:
        """Whether the convolution can be taken in halves (as
        :meth:`PeriodicConvolution.forward`): with the pyfftw backend."""
        return self.backend == "pyfftw"

    def forward(self, p: np.ndarray) -> None:
        """First half of ``K*p``: the padded spectrum of ``p`` (Pa) into the work array
        (as :meth:`PeriodicConvolution.forward`; pyfftw backend only)."""
        n0, n1 = self.shape
        if self.pruned:
            # what one assignment of p would take (a field of the window's shape or one that
            # broadcasts to it), whole, before any slab copies its rows
            window = np.broadcast_to(p, self.shape)
            self._row_fwd.execute(
                before=functools.partial(self._fill_rows, window), after=self._zero_padding
            )
            self._col_fwd.execute()
        else:
            self._real[:n0, :n1] = p
            self._real[n0:, :] = 0.0  # the c2r inverse overwrote the padding
            self._real[:n0, n1:] = 0.0
            self._fwd.execute()

    def _fill_rows(self, p, start: int, stop: int) -> None:
        """Before the row slab ``[start, stop)`` of the forward transform, in its thread:
        the window's rows of ``p`` (Pa) into the padded rows."""
        self._rows[start:stop, : self.shape[1]] = p[start:stop]

    def _zero_padding(self, start: int, stop: int) -> None:
        """After the row slab ``[start, stop)`` of the forward transform, in its thread: the
        same share of the spectrum's padding rows zeroed (the last inverse column pass wrote
        over them). After, not before: the slab's rows are still in cache for its
        transform, as they were when this was a pass of its own."""
        n0 = self.shape[0]
        pad = self.padded_shape[0] - n0
        self._spec[n0 + start * pad // n0 : n0 + stop * pad // n0] = 0.0

    def _take_rows(self, out, start: int, stop: int) -> None:
        """After the row slab ``[start, stop)`` of the inverse transform, in its thread: its
        window's part into ``out`` (m)."""
        out[start:stop] = self._out[start:stop, : self.shape[1]]

    def multiply_energy(self) -> float:
        """The work spectrum times the kernel's; returns ``Σ p·(K*p)`` (m·Pa) over the
        window by Parseval on the padded grid (``p`` is zero on the padding)."""
        with _spectrum.spectrum_threads(self.threads):
            return _spectrum.multiply_spectrum_energy(
                self._spec, self._mult_scaled, self.padded_shape[1] % 2 == 0
            )

    def inverse(self, out: np.ndarray) -> np.ndarray:
        """Last part: ``out = K*p`` (m) on the window from the multiplied work spectrum."""
        n1 = self.shape[1]
        if self.pruned:
            if out.shape != self.shape:
                raise ValueError(f"out has shape {out.shape}; the window is {self.shape}")
            self._col_inv.execute()
            self._row_inv.execute(after=functools.partial(self._take_rows, out))
        else:
            self._inv.execute()
            out[...] = self._real[: self.shape[0], :n1]
        return out

    def __call__(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Return the displacement (m) of pressure ``p`` (Pa); writes into ``out`` if given."""
        self.ncalls += 1
        n0, n1 = self.shape
        m0, m1 = self.padded_shape
        if self.backend == "pyfftw":
            self.forward(p)
            self._multiply()
            if out is None:
                out = np.empty(self.shape)
            return self.inverse(out)
        if self.pruned:
            rows = np.fft.rfft(p, n=m1, axis=1)
            cols = np.fft.fft(rows, n=m0, axis=0)
            cols *= self._multiplier
            back = np.fft.ifft(cols, axis=0)[:n0]
            result = np.fft.irfft(back, n=m1, axis=1)[:, :n1]
        else:
            spec = np.fft.rfft2(p, s=(m0, m1))
            result = np.fft.irfft2(spec * self._multiplier, s=(m0, m1))[:n0, :n1]
        if out is None:
            return result.copy()
        out[...] = result
        return out


@functools.lru_cache(maxsize=8)
def _cached_operator(shape, spacing, e_star, periodic, backend, threads, pruned, effort):
    if periodic:
        return PeriodicConvolution(shape, spacing, e_star, backend, threads, effort)
    return NonPeriodicConvolution(shape, spacing, e_star, backend, threads, pruned, effort)


def get_operator(
    shape,
    spacing,
    e_star,
    *,
    periodic,
    backend=None,
    threads=1,
    pruned=True,
    planner_effort=_fft.DEFAULT_PLANNER_EFFORT,
):
    """Cached convolution operator (plans and kernel spectrum built once).

    Parameters
    ----------
    shape : (n0, n1)
    spacing : float
        m.
    e_star : float
        Pa.
    periodic : bool
    backend : {"pyfftw", "numpy", None}
    threads : int
    pruned : bool
        Non-periodic only: pruned (default) or plain padded transform.
    planner_effort : str
        FFTW planner effort, one of :data:`amontons.contact.fft.PLANNER_EFFORTS`; part of
        the cache key (operators planned with different efforts are distinct).
    """
    backend = _fft.resolve_backend(backend)
    effort = _fft.check_planner_effort(planner_effort)
    if backend == "numpy":
        effort = _fft.DEFAULT_PLANNER_EFFORT  # numpy.fft does not plan: one cache entry
    key_pruned = bool(pruned) and not periodic
    return _cached_operator(
        tuple(int(s) for s in shape),
        float(spacing),
        float(e_star),
        bool(periodic),
        backend,
        int(threads),
        key_pruned,
        effort,
    )


@functools.lru_cache(maxsize=8)
def array_operator(shape, spacing, e_star, periodic, backend) -> ArrayConvolution:
    """The cached :class:`.array_convolution.ArrayConvolution` of an array backend
    (:data:`.array_backends.ARRAY_BACKENDS`), padded to :func:`fast_padded_shape` when not
    periodic (the CPU operator's grid)."""
    module = array_module(backend)
    padded = None if periodic else fast_padded_shape(shape)
    return ArrayConvolution(shape, spacing, e_star, module.xp, padded, module.fft_pair)


def operator_for(opts, shape, spacing, e_star):
    """The cached operator of a grid of ``shape`` (spacing m, E* Pa) under a solve's
    :class:`~.options.SolveOptions` (boundary, backend, threads, planner effort): the
    array namespace's for an array backend."""
    if opts.backend in ARRAY_BACKENDS:
        key = (tuple(int(s) for s in shape), float(spacing), float(e_star), bool(opts.periodic))
        return array_operator(*key, opts.backend)
    return get_operator(
        shape,
        spacing,
        e_star,
        periodic=opts.periodic,
        backend=opts.backend,
        threads=opts.threads,
        planner_effort=opts.planner_effort,
    )


def direct_convolution(p: np.ndarray, spacing: float, e_star: float, *, periodic: bool):
    """Brute-force O(N⁴) convolution, for testing on tiny grids only.

    Non-periodic: sums the Love kernel over every source pixel. Periodic: sums the
    discrete inverse Fourier series with the ``2/(E*|q|)`` multiplier explicitly.
    """
    n0, n1 = p.shape
    u = np.zeros_like(p, dtype=float)
    if periodic:
        q0 = 2 * np.pi * np.fft.fftfreq(n0, d=spacing)
        q1 = 2 * np.pi * np.fft.fftfreq(n1, d=spacing)
        x0 = np.arange(n0) * spacing
        x1 = np.arange(n1) * spacing
        e0 = np.exp(-1j * np.outer(q0, x0))  # (k, i)
        e1 = np.exp(-1j * np.outer(q1, x1))
        ph = e0 @ p @ e1.T
        q = np.hypot(q0[:, None], q1[None, :])
        with np.errstate(divide="ignore"):
            mult = np.where(q > 0, 2.0 / (e_star * q), 0.0)
        uh = ph * mult
        u = (e0.conj().T @ uh @ e1.conj()).real / (n0 * n1)
        return u
    half = spacing / 2
    for i in range(n0):
        for j in range(n1):
            if p[i, j] == 0.0:
                continue
            x = (np.arange(n0)[:, None] - i) * spacing
            y = (np.arange(n1)[None, :] - j) * spacing
            u += p[i, j] * love_square(x, y, half, half, e_star)
    return u
