"""Indenter geometries: spheres and self-affine random surfaces (heights in m;
docs/models.md §2.6).

Heights follow the solver's convention: larger = closer to the elastic flat.
"""

from __future__ import annotations

import numpy as np


def sphere(shape, spacing, radius, centre=None) -> np.ndarray:
    """Paraboloidal sphere cap ``-r²/(2R)``, m.

    Parameters
    ----------
    shape : (n0, n1)
    spacing : float
        Grid spacing, m.
    radius : float
        Sphere radius R, m.
    centre : (float, float), optional
        Apex position in pixel coordinates; default the window centre ``((n0-1)/2,
        (n1-1)/2)``, which makes the field exactly mirror-symmetric.
    """
    n0, n1 = shape
    c0, c1 = ((n0 - 1) / 2, (n1 - 1) / 2) if centre is None else centre
    x = (np.arange(n0) - c0) * spacing
    y = (np.arange(n1) - c1) * spacing
    r2 = x[:, None] ** 2 + y[None, :] ** 2
    return -r2 / (2 * radius)


def _wavevectors(shape, spacing):
    n0, n1 = shape
    q0 = 2 * np.pi * np.fft.fftfreq(n0, d=spacing)
    q1 = 2 * np.pi * np.fft.rfftfreq(n1, d=spacing)
    return q0[:, None], q1[None, :]


def rms_slope(heights, spacing) -> float:
    """Spectral rms slope ``sqrt(<|∇h|²>)`` of a periodic height map (dimensionless).

    The gradient is taken in Fourier space (exact for a band-limited periodic field).
    Nyquist modes, whose derivative is undefined on the grid, are excluded.
    """
    h = np.asarray(heights, dtype=float)
    q0, q1 = _wavevectors(h.shape, spacing)
    spec = np.fft.rfft2(h)
    spec = _drop_nyquist(spec, h.shape)
    gx = np.fft.irfft2(1j * q0 * spec, s=h.shape)
    gy = np.fft.irfft2(1j * q1 * spec, s=h.shape)
    return float(np.sqrt(np.mean(gx**2 + gy**2)))


def _drop_nyquist(spec, shape):
    spec = spec.copy()
    n0, n1 = shape
    if n0 % 2 == 0:
        spec[n0 // 2, :] = 0
    if n1 % 2 == 0:
        spec[:, n1 // 2] = 0
    return spec


def self_affine(
    shape,
    spacing,
    hurst,
    *,
    rms_slope=None,
    rms_height=None,
    short_cutoff=None,
    long_cutoff=None,
    rng=None,
) -> np.ndarray:
    """Periodic, isotropic self-affine random surface by Fourier synthesis, m.

    Power spectrum ``C(q) ∝ q^(-2-2H)`` between ``2π/long_cutoff`` and
    ``2π/short_cutoff``, constant (roll-off) below ``2π/long_cutoff`` and zero above
    ``2π/short_cutoff``; Gaussian random amplitudes and phases (filtered white noise), zero
    mean, no Nyquist modes. The realisation is scaled so that *its* rms slope (spectral, see
    :func:`rms_slope`) or rms height equals the requested value exactly.

    Parameters
    ----------
    shape : (n0, n1)
    spacing : float
        Grid spacing, m.
    hurst : float
        Hurst exponent H, 0 < H < 1.
    rms_slope, rms_height : float
        Exactly one: target rms slope (dimensionless) or rms height (m).
    short_cutoff : float, optional
        Shortest wavelength, m (default: no cut-off below the grid's Nyquist limit).
    long_cutoff : float, optional
        Roll-off wavelength, m (default: the window size).
    rng : numpy.random.Generator or int, optional
        Random generator or seed (same seed, same surface).
    """
    if (rms_slope is None) == (rms_height is None):
        raise ValueError("give exactly one of rms_slope and rms_height")
    if not 0 < hurst < 1:
        raise ValueError(f"hurst must be in (0, 1), got {hurst}")
    rng = np.random.default_rng(rng)
    n0, n1 = shape
    q0, q1 = _wavevectors(shape, spacing)
    q = np.hypot(q0, q1)
    q_long = 2 * np.pi / (long_cutoff if long_cutoff else max(n0, n1) * spacing)
    q_short = 2 * np.pi / short_cutoff if short_cutoff else np.inf
    qq = np.maximum(q, q_long)
    amp = qq ** (-1.0 - hurst)  # sqrt of C(q) ∝ q^(-2-2H)
    amp[q > q_short] = 0.0
    amp[0, 0] = 0.0
    noise = rng.standard_normal(shape)
    spec = _drop_nyquist(np.fft.rfft2(noise) * amp, shape)
    h = np.fft.irfft2(spec, s=shape)
    if rms_height is not None:
        h *= rms_height / h.std()
    else:
        h *= rms_slope / globals()["rms_slope"](h, spacing)
    return h
