"""Westergaard: periodic sinusoidal indenter (docs/models.md §2.7)."""

import numpy as np
import pytest

from amontons.contact import solve


@pytest.mark.parametrize("ratio", [0.1, 0.35, 0.7])
def test_contact_half_width(ratio):
    """Half-width a from p̄ = p* sin²(πa/λ), p* = πE*h0/λ, within 1 % at three loads.

    1-D-like problem: h = h0 cos(2πx/λ) along x on a (4 × 1024) periodic grid, one period.
    a is measured as (contact pixels per row)·Δx/2; pixel counting is exact to ±1 pixel
    on 2a ≥ 200 pixels (≤ 0.5 %), leaving the rest for the edge discretisation.
    """
    n0, n1, lam, h0, e_star = 4, 1024, 1.0, 0.01, 2.0
    dx = lam / n1
    x = np.arange(n1) * dx
    h = np.broadcast_to(h0 * np.cos(2 * np.pi * x / lam), (n0, n1)).copy()
    p_star = np.pi * e_star * h0 / lam
    p_mean = ratio * p_star
    load = p_mean * n0 * n1 * dx**2
    res = solve(h, dx, e_star, load=load, periodic=True)
    a_num = np.count_nonzero(res.contact[0]) * dx / 2
    a_ws = lam / np.pi * np.arcsin(np.sqrt(ratio))
    assert a_num / dx > 100
    assert abs(a_num / a_ws - 1) < 0.01


def test_pressure_profile_mid_load():
    """Pressure profile p(x) = 2p̄ cos(πx/λ) sqrt(sin²(πa/λ) - sin²(πx/λ)) / sin²(πa/λ)
    within 1 % of p̄ for |x| < 0.9a (pointwise absolute error in units of p̄; the
    square-root edge itself is not resolved by the pixels)."""
    n0, n1, lam, h0, e_star = 4, 1024, 1.0, 0.01, 2.0
    dx = lam / n1
    x = np.arange(n1) * dx
    x = np.where(x > lam / 2, x - lam, x)
    h = np.broadcast_to(h0 * np.cos(2 * np.pi * x / lam), (n0, n1)).copy()
    p_mean = 0.35 * np.pi * e_star * h0 / lam
    res = solve(h, dx, e_star, load=p_mean * n0 * n1 * dx**2, periodic=True)
    a = lam / np.pi * np.arcsin(np.sqrt(0.35))
    s2 = np.sin(np.pi * a / lam) ** 2
    inner = np.abs(x) < 0.9 * a
    p_ws = (
        2
        * p_mean
        * np.cos(np.pi * x[inner] / lam)
        * np.sqrt(s2 - np.sin(np.pi * x[inner] / lam) ** 2)
        / s2
    )
    assert np.abs(res.pressure[0, inner] - p_ws).max() < 0.01 * p_mean
