"""Green's functions (surface displacement per unit pressure) of the elastic half-space
(docs/models.md §2.1).

Units: lengths in m, contact modulus ``e_star`` in Pa; the kernels map a pressure in Pa
to a displacement in m.

Periodic
    For a pressure field ``p(x) = p̂ cos(q·x)`` with angular wavenumber ``|q| = 2π/λ`` the
    surface displacement is ``u(x) = 2 p̂ cos(q·x) / (E* |q|)`` (Johnson 1985, §13.2).
    On an ``n0 × n1`` grid of spacing ``Δ`` the DFT modes have ``q = 2π k / (n Δ)``, so the
    discrete multiplier applied to ``rfft2(p)`` is exactly ``2 / (E* |q|)``: no Δ factors.
    The q = 0 mode is the rigid-body mode. It is set to 0: the elastic displacement has
    zero mean and the rigid-body approach is carried by the solver's displacement ``d``.

Non-periodic
    Love (1929) / Johnson (1985, eq. 3.25): displacement at offset ``(x, y)`` from the
    centre of a ``2a × 2b`` rectangle carrying unit uniform pressure. Its value at the
    centre of a square (``a = b``) is ``(4a / (π E*)) ln(1 + √2) · 2 = 2.2444 a / E*``.
    It is sampled at wrapped offsets on a padded ``m0 × m1`` grid, ``m >= 2n`` on each axis
    (Hockney padding; the operator picks FFT-friendly ``m``, see
    :func:`amontons.contact.fft.fast_length`), so that a circular convolution on the padded
    grid is the exact free-space convolution on the ``n0 × n1`` window.
"""

from __future__ import annotations

import numpy as np


def periodic_multiplier(shape: tuple[int, int], spacing: float, e_star: float) -> np.ndarray:
    """Multiplier ``2/(E*|q|)`` on the ``rfft2`` half-spectrum of an ``shape`` grid.

    Parameters
    ----------
    shape : (n0, n1)
        Grid shape.
    spacing : float
        Grid spacing, m.
    e_star : float
        Contact modulus, Pa.

    Returns
    -------
    ndarray, shape (n0, n1 // 2 + 1), float64, writable (a fresh array per call)
        m/Pa per Fourier mode; the (0, 0) entry (rigid mode) is 0. Computed once per
        convolution operator, which :func:`amontons.contact.convolution.get_operator`
        caches per (shape, spacing, E*).
    """
    n0, n1 = (int(s) for s in shape)
    q0 = 2 * np.pi * np.fft.fftfreq(n0, d=spacing)
    q1 = 2 * np.pi * np.fft.rfftfreq(n1, d=spacing)
    q = np.hypot(q0[:, None], q1[None, :])
    q[0, 0] = 1.0  # avoid a division by zero; the rigid mode is zeroed just below
    mult = 2.0 / (e_star * q)
    mult[0, 0] = 0.0
    return mult


def love_square(x, y, a: float, b: float, e_star: float):
    """Love/Johnson displacement of a uniformly loaded ``2a × 2b`` rectangle.

    Parameters
    ----------
    x, y : array_like
        Offsets from the rectangle's centre, m.
    a, b : float
        Half-widths of the rectangle in x and y, m.
    e_star : float
        Contact modulus, Pa.

    Returns
    -------
    ndarray
        Surface displacement per unit pressure, m/Pa.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    xp, xm = x + a, x - a
    yp, ym = y + b, y - b
    r_pp = np.hypot(xp, yp)
    r_pm = np.hypot(xp, ym)
    r_mp = np.hypot(xm, yp)
    r_mm = np.hypot(xm, ym)
    # x·ln(...) terms are 0·ln(0)-safe: the logs diverge only logarithmically where their
    # prefactor vanishes, so errstate + nan_to_num keeps the limit 0.
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = xp * np.log((yp + r_pp) / (ym + r_pm))
        t2 = yp * np.log((xp + r_pp) / (xm + r_mp))
        t3 = xm * np.log((ym + r_mm) / (yp + r_mp))
        t4 = ym * np.log((xm + r_mm) / (xp + r_pm))
    total = sum(np.nan_to_num(t, nan=0.0, posinf=0.0, neginf=0.0) for t in (t1, t2, t3, t4))
    return total / (np.pi * e_star)


def _check_padded(shape, padded_shape):
    """``(n0, n1)`` and the padded ``(m0, m1)`` (default ``(2n0, 2n1)``), with ``m >= 2n``."""
    n0, n1 = (int(s) for s in shape)
    m0, m1 = (2 * n0, 2 * n1) if padded_shape is None else (int(s) for s in padded_shape)
    if m0 < 2 * n0 or m1 < 2 * n1:
        raise ValueError(f"padded shape {(m0, m1)} is smaller than 2 x {(n0, n1)}")
    return n0, n1, m0, m1


def hockney_kernel(
    shape: tuple[int, int],
    spacing: float,
    e_star: float,
    padded_shape: tuple[int, int] | None = None,
) -> np.ndarray:
    """Love kernel sampled at wrapped offsets on the ``m0 × m1`` padded grid.

    Parameters
    ----------
    shape : (n0, n1)
        The window.
    spacing : float
        Grid spacing, m.
    e_star : float
        Contact modulus, Pa.
    padded_shape : (m0, m1), optional
        The FFT grid, ``m >= 2n`` on each axis; default ``(2n0, 2n1)`` (plain Hockney).

    Index ``i`` holds the offset ``iΔ`` for ``i <= m/2`` and ``(i - m)Δ`` above. A source
    and a target on the window are at most ``n - 1`` pixels apart, so only the indices
    ``i <= n - 1`` and ``i >= m - n + 1`` reach the window; with ``m >= 2n`` these are the
    true offsets, and the circular convolution on the padded grid is exactly the free-space
    one on the window whatever ``m`` is. The entries in between never reach the window;
    they take the same rule, which keeps the kernel even (its spectrum real).

    Returns
    -------
    ndarray, shape (m0, m1)
        m/Pa.
    """
    n0, n1, m0, m1 = _check_padded(shape, padded_shape)
    # |wrapped offset| in pixels: i for i <= m/2, m - i above
    i0 = np.arange(m0)
    i1 = np.arange(m1)
    a0 = np.minimum(i0, m0 - i0)
    a1 = np.minimum(i1, m1 - i1)
    half = spacing / 2
    # The kernel is even in x and y: evaluate it once on the quadrant of distinct |offsets|
    # (a quarter of the temporaries) and mirror by indexing, which also makes the padded
    # kernel exactly symmetric so its spectrum is exactly real.
    x = np.arange(m0 // 2 + 1)[:, None] * spacing
    y = np.arange(m1 // 2 + 1)[None, :] * spacing
    quadrant = love_square(x, y, half, half, e_star)
    return quadrant[a0[:, None], a1[None, :]]


def hockney_multiplier(
    shape: tuple[int, int],
    spacing: float,
    e_star: float,
    padded_shape: tuple[int, int] | None = None,
) -> np.ndarray:
    """Real spectrum ``rfft2`` of :func:`hockney_kernel` on the ``m0 × m1`` padded grid
    (default ``(2n0, 2n1)``), shape ``(m0, m1 // 2 + 1)``, m/Pa.

    The kernel is even in both directions, so its spectrum is real; the imaginary part
    (round-off only) is dropped, which halves the cost of the multiplication.
    The convolution operators that use it are cached per (shape, spacing, E*), so it is
    computed once per problem; the returned array is writable (a fresh array per call).
    """
    kernel = hockney_kernel(shape, spacing, e_star, padded_shape)
    spec = np.fft.rfft2(kernel)
    del kernel
    mult = np.ascontiguousarray(spec.real)
    return mult
