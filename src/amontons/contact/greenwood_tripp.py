"""Greenwood & Tripp (1967) rough-sphere contact, and the bearing-area contact map.

A sphere of radius R whose surface carries Greenwood–Williamson asperities (summit height
standard deviation σ, asperity radius β, areal density η) presses on a rigid flat. The
roughness-averaged pressure at radius r is the GW pressure of the local mean-plane separation

    p(r) = (4/3) η E* β^½ σ^{3/2} F_{3/2}(u(r)/σ),    u(r) = −d + r²/2R + w(r),

where d is the approach of the sphere and w(r) the elastic bulk deflection under p (positive
into the solid), F_n(h) = ∫_h^∞ (s − h)^n φ(s) ds with φ the standard normal density.

Notation trap (docs/models.md §2.5): in GT's paper B is the sphere radius and β the asperity
radius; the appendix's "B = 1/h''_rms, η h_rms B ≈ 0.05" is β = 1/h''_rms and ησβ ≈ 0.05.

The axisymmetric bulk deflection uses the exact influence of uniform pressure on annuli
(Johnson 1985, §3.4, difference of two uniformly loaded disks), and the nonlinear system is
solved by Newton's method on u with the approach found by bracketing the load.

SI units throughout: m, Pa, N.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
from scipy import integrate, interpolate, optimize, special
from threadpoolctl import threadpool_limits

from .errors import ContactError, ContactInputError

_H_MIN, _H_MAX = -12.0, 10.0


def _f_n_quadrature(n: float, h: float) -> float:
    value, _ = integrate.quad(
        lambda s: (s - h) ** n * np.exp(-0.5 * s * s) / np.sqrt(2 * np.pi), h, np.inf, limit=200
    )
    return value


@cache
def _log_f_spline(n: float) -> interpolate.CubicSpline:
    h = np.linspace(_H_MIN, _H_MAX, 2201)
    return interpolate.CubicSpline(h, np.log([_f_n_quadrature(n, x) for x in h]))


def gw_integral(n: float, h: np.ndarray) -> np.ndarray:
    """F_n(h) = ∫_h^∞ (s − h)^n φ(s) ds for n ∈ {0, ½, 1, 3/2}, any real h.

    Tabulated by quadrature on [−12, 10] (relative error ~1e-8 from the spline); below −12 the
    asymptotic series (−h)^n [1 + n(n−1)/2h²] (next term ~1e-6 relative); above 10 it is < 1e-23
    of its value at 0 and returned as 0.
    """
    h = np.asarray(h, dtype=float)
    out = np.zeros_like(h)
    deep = h < _H_MIN
    table = (h >= _H_MIN) & (h <= _H_MAX)
    out[deep] = (-h[deep]) ** n * (1 + n * (n - 1) / (2 * h[deep] ** 2))
    out[table] = np.exp(_log_f_spline(float(n))(h[table]))
    return out


@dataclass(frozen=True)
class AsperityModel:
    """Greenwood–Williamson asperities: σ (m), asperity radius β (m), density η (1/m²)."""

    sigma_m: float
    beta_m: float
    eta_per_m2: float

    @classmethod
    def from_roughness(
        cls, h_rms_m: float, curvature_rms_per_m: float, eta_sigma_beta: float = 0.05
    ) -> AsperityModel:
        """The appendix's closure: σ = h_rms, β = 1/h''_rms, η = (ησβ)/(σβ).

        Which curvature h''_rms means (mean curvature ½∇²h or ∇²h) changes β by 2; the caller
        states it (docs/models.md §2.5). Units: h_rms in m, curvature in 1/m.
        """
        beta = 1.0 / curvature_rms_per_m
        return cls(h_rms_m, beta, eta_sigma_beta / (h_rms_m * beta))

    def pressure(self, separation_m: np.ndarray, e_star_pa: float) -> np.ndarray:
        """GW nominal pressure at mean-plane separation u, Pa."""
        s = self.sigma_m
        prefactor = (4 / 3) * self.eta_per_m2 * e_star_pa * np.sqrt(self.beta_m) * s**1.5
        return prefactor * gw_integral(1.5, np.asarray(separation_m) / s)

    def pressure_slope(self, separation_m: np.ndarray, e_star_pa: float) -> np.ndarray:
        """dp/du, Pa/m (F'_{3/2} = −(3/2) F_{1/2})."""
        s = self.sigma_m
        prefactor = (4 / 3) * self.eta_per_m2 * e_star_pa * np.sqrt(self.beta_m) * s**1.5
        return -prefactor * 1.5 * gw_integral(0.5, np.asarray(separation_m) / s) / s

    def area_fraction(self, separation_m: np.ndarray) -> np.ndarray:
        """GW real-area fraction π η β σ F_1(u/σ) (dimensionless)."""
        s = self.sigma_m
        return np.pi * self.eta_per_m2 * self.beta_m * s * gw_integral(1.0, separation_m / s)


def disk_displacement(r: np.ndarray, c: float, e_star_pa: float) -> np.ndarray:
    """Surface deflection at radius r under unit uniform pressure on a disk of radius c, m/Pa.

    Johnson (1985) eqs. 3.41: (4c/πE*) E(r/c) inside, (4r/πE*)[E(c/r) − (1 − c²/r²) K(c/r)]
    outside, E and K complete elliptic integrals of modulus k (scipy takes m = k²).
    """
    r = np.asarray(r, dtype=float)
    out = np.empty_like(r)
    inside = r <= c
    k2_in = (r[inside] / c) ** 2
    out[inside] = c * special.ellipe(k2_in)
    ro = r[~inside]
    k2_out = (c / ro) ** 2
    out[~inside] = ro * (special.ellipe(k2_out) - (1 - k2_out) * special.ellipk(k2_out))
    return 4 * out / (np.pi * e_star_pa)


def annulus_influence(edges_m: np.ndarray, e_star_pa: float) -> np.ndarray:
    """Matrix A with w(r_i) = Σ_j A_ij p_j for uniform pressure p_j on annulus [e_j, e_{j+1}],
    evaluated at the annulus mid-radii r_i, m/Pa."""
    centres = 0.5 * (edges_m[:-1] + edges_m[1:])
    disks = np.stack([disk_displacement(centres, c, e_star_pa) for c in edges_m[1:]], axis=1)
    influence = disks.copy()
    influence[:, 1:] -= disks[:, :-1]
    return influence


class GreenwoodTrippError(ContactError, RuntimeError):
    """The GT iteration did not converge, or the radial domain is too small for the load.

    Part of the :class:`~amontons.contact.ContactError` tree (and a RuntimeError, as before).
    """


@dataclass(frozen=True)
class GreenwoodTrippResult:
    """Axisymmetric GT solution on annuli with mid-radii ``r_m``.

    pressure (Pa), separation u (m, mean-plane gap; negative where the mean planes overlap),
    bulk_displacement w (m), approach d (m), load (N), area_fraction (real/nominal), and the
    real contact area (m²) of the GW asperities.
    """

    r_m: np.ndarray
    edges_m: np.ndarray
    pressure: np.ndarray
    separation: np.ndarray
    bulk_displacement: np.ndarray
    area_fraction: np.ndarray
    approach_m: float
    load_n: float
    newton_iterations: int
    sphere_radius_m: float
    e_star_pa: float

    @property
    def real_area_m2(self) -> float:
        rings = np.pi * np.diff(self.edges_m**2)
        return float(np.sum(self.area_fraction * rings))

    def separation_at(self, r_m: np.ndarray) -> np.ndarray:
        """Mean-plane separation at arbitrary radii, m: interpolated on the grid; beyond it the
        rigid sphere plus the Boussinesq far field F/(πE*r) of the bulk deflection."""
        r_m = np.asarray(r_m, dtype=float)
        inside = np.interp(r_m, self.r_m, self.separation)
        r_far = np.maximum(r_m, self.r_m[-1])
        far = (
            -self.approach_m
            + r_far**2 / (2 * self.sphere_radius_m)
            + self.load_n / (np.pi * self.e_star_pa * r_far)
        )
        return np.where(r_m <= self.r_m[-1], inside, far)


def _solve_separation(
    offset: np.ndarray,
    influence: np.ndarray,
    model: AsperityModel,
    e_star_pa: float,
    u0: np.ndarray,
    tol: float,
    max_iter: int,
) -> tuple[np.ndarray, int]:
    """Newton on R(u) = u − offset − A·p(u) = 0 with backtracking on |R|."""
    u = u0.copy()
    scale = model.sigma_m
    for iteration in range(1, max_iter + 1):
        p = model.pressure(u, e_star_pa)
        residual = u - offset - influence @ p
        norm = np.max(np.abs(residual))
        if norm < tol * scale:
            return u, iteration
        jacobian = np.eye(u.size) - influence * model.pressure_slope(u, e_star_pa)[None, :]
        step = np.linalg.solve(jacobian, -residual)
        t = 1.0
        while t > 1e-6:
            trial = u + t * step
            trial_residual = trial - offset - influence @ model.pressure(trial, e_star_pa)
            if np.max(np.abs(trial_residual)) < (1 - 1e-4 * t) * norm:
                break
            t *= 0.5
        u = trial
    raise GreenwoodTrippError(
        f"Newton iteration for the GT separation did not converge in {max_iter} steps "
        f"(max residual {norm:.3e} m, tolerance {tol * scale:.3e} m)"
    )


def greenwood_tripp(
    radius_m: float,
    e_star_pa: float,
    model: AsperityModel,
    load_n: float,
    *,
    r_max_m: float | None = None,
    n_radial: int = 400,
    tol: float = 1e-10,
    max_iter: int = 200,
) -> GreenwoodTrippResult:
    """Solve the GT rough-sphere problem at total load ``load_n``.

    Every native thread pool runs one thread for the call (the influence matrix's products are
    a few hundred square), as in :func:`amontons.contact.solve`; the caller's limits come back.
    """
    with threadpool_limits(limits=1):
        return _greenwood_tripp(
            radius_m, e_star_pa, model, load_n, r_max_m, n_radial, tol, max_iter
        )


def _greenwood_tripp(
    radius_m, e_star_pa, model, load_n, r_max_m, n_radial, tol, max_iter
) -> GreenwoodTrippResult:
    """:func:`greenwood_tripp` without the thread bound.

    ``r_max_m`` defaults to three Hertz radii; the pressure on the outermost annulus must be
    below 1e-6 of the peak, else GreenwoodTrippError asks for a larger domain.
    """
    if load_n <= 0 or e_star_pa <= 0 or radius_m <= 0:
        raise ContactInputError(
            f"GT needs positive load, E* and radius; got {load_n}, {e_star_pa}, {radius_m}"
        )
    hertz_a = (3 * load_n * radius_m / (4 * e_star_pa)) ** (1 / 3)
    r_max = 3 * hertz_a if r_max_m is None else r_max_m
    edges = np.linspace(0.0, r_max, n_radial + 1)
    r = 0.5 * (edges[:-1] + edges[1:])
    rings = np.pi * np.diff(edges**2)
    influence = annulus_influence(edges, e_star_pa)
    state = {"u": r**2 / (2 * radius_m), "iterations": 0}

    def load_at(approach: float) -> float:
        offset = -approach + r**2 / (2 * radius_m)
        u, its = _solve_separation(offset, influence, model, e_star_pa, state["u"], tol, max_iter)
        state["u"], state["iterations"] = u, state["iterations"] + its
        return float(np.sum(model.pressure(u, e_star_pa) * rings)) - load_n

    hertz_d = hertz_a**2 / radius_m
    low, high = -10 * model.sigma_m, hertz_d + 10 * model.sigma_m
    while load_at(high) < 0:
        high = 2 * high
    approach = optimize.brentq(load_at, low, high, xtol=1e-14 * high, rtol=1e-13)
    load_at(approach)
    u = state["u"]
    p = model.pressure(u, e_star_pa)
    if p[-1] > 1e-6 * p.max():
        raise GreenwoodTrippError(
            f"pressure at the domain edge r = {r_max:.3e} m is {p[-1] / p.max():.1e} of the peak;"
            " increase r_max_m"
        )
    w = influence @ p
    result = GreenwoodTrippResult(
        r_m=r,
        edges_m=edges,
        pressure=p,
        separation=u,
        bulk_displacement=w,
        area_fraction=model.area_fraction(u),
        approach_m=float(approach),
        load_n=float(np.sum(p * rings)),
        newton_iterations=state["iterations"],
        sphere_radius_m=radius_m,
        e_star_pa=e_star_pa,
    )
    return result


def bearing_area_map(
    roughness_m: np.ndarray, spacing_m: float, gt: GreenwoodTrippResult, centre_px=None
) -> np.ndarray:
    """Contact map by the bearing-area approximation (appendix B.2.1).

    ``roughness_m`` is the measured topography with the sphere removed, positive towards the
    flat, about its mean plane. A pixel is in contact where it reaches above the GT mean-plane
    separation at its distance from the contact centre (default: the map centre).
    """
    ny, nx = roughness_m.shape
    cy, cx = ((ny - 1) / 2, (nx - 1) / 2) if centre_px is None else centre_px
    y, x = np.indices((ny, nx), dtype=float)
    r = np.hypot((x - cx) * spacing_m, (y - cy) * spacing_m)
    return roughness_m >= gt.separation_at(r)
