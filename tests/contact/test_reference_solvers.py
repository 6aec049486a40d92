"""Cross-checks against independent solvers, when they are installed (bench extras).

Tamaas (C++ Polonsky-Keer-Rey) and ContactMechanics (Python constrained CG) implement the
same periodic problem with their own kernels, so agreement to near round-off checks our
kernel factor 2/(E*|q|), the rigid-mode treatment and the load convention independently of
our own analytic tests. Skipped when the packages are missing.
"""

import numpy as np
import pytest

from amontons.contact import self_affine, solve

N, PBAR = 64, 0.005


@pytest.fixture(scope="module")
def ours():
    h = self_affine((N, N), 1.0, 0.8, rms_slope=0.1, rng=4)
    return h, solve(h, 1.0, 1.0, load=PBAR * N * N, periodic=True, tol=1e-12)


def test_tamaas_agrees(ours):
    """Tamaas at tolerance 1e-12 vs ours at 1e-12: max pressure difference < 1e-9 of the
    peak (both converge to ~1e-11; the bound leaves room for their different criteria)."""
    tm = pytest.importorskip("tamaas")
    h, res = ours
    tm.set_log_level(tm.LogLevel.error)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [float(N)] * 2, [N, N])
    model.E, model.nu = 1.0, 0.0  # E* = E/(1 - nu²) = 1
    solver = tm.PolonskyKeerRey(
        model, h.copy(), 1e-12, tm.PolonskyKeerRey.pressure, tm.PolonskyKeerRey.pressure
    )
    solver.solve(PBAR)  # Tamaas takes the mean pressure
    p = np.array(model.traction).reshape(N, N)
    assert np.abs(p - res.pressure).max() < 1e-9 * res.pressure.max()


def test_contactmechanics_agrees(ours):
    """ContactMechanics with tight tolerances: max pressure difference < 1e-8 of the peak
    (its stopping rule is on penetration and force changes, looser than ours)."""
    pytest.importorskip("ContactMechanics")
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Systems import NonSmoothContactSystem
    from SurfaceTopography import Topography

    h, res = ours
    sub = PeriodicFFTElasticHalfSpace((N, N), 1.0, (float(N), float(N)))
    system = NonSmoothContactSystem(sub, Topography(h, (float(N), float(N)), periodic=True))
    sol = system.minimize_proxy(
        external_force=PBAR * N * N, pentol=1e-12 * h.std(), forcetol=1e-12, thermotol=1e-12
    )
    p = np.asarray(sol.jac).reshape(N, N)  # compressive force per unit-area pixel
    assert np.abs(p - res.pressure).max() < 1e-8 * res.pressure.max()
