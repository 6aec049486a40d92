"""Solver invariants: force balance, complementarity, warm start, control modes,
backends, coarse-to-fine and load series."""

import numpy as np
import pytest

from amontons.contact import ContactInputError, solve, solve_load_series
from amontons.contact.fft import HAVE_PYFFTW


def test_force_balance(rough_case, hertz_case):
    """Σp·Δx² equals the imposed load to round-off (1e-12 relative): load control
    rescales p exactly, so anything larger is a bug."""
    for case in (rough_case, hertz_case):
        res = case["result"]
        total = res.pressure.sum() * case["dx"] ** 2
        assert abs(total / case["load"] - 1) < 1e-12
        assert abs(res.load / case["load"] - 1) < 1e-12


def test_complementarity(rough_case):
    """p >= 0 everywhere; p > 0 ⇒ |gap| small; gap > 0 ⇒ p = 0; no penetration.

    The solve used tol = 1e-10, which bounds the rms gap on the contact and the worst
    penetration at 1e-10·h_rms; the max gap on the contact set is allowed 1e-8·h_rms
    (max vs rms over a few hundred pixels).
    """
    res = rough_case["result"]
    h_rms = rough_case["heights"].std()
    assert (res.pressure >= 0).all()
    assert res.converged and res.residual < 1e-10
    assert np.abs(res.gap[res.contact]).max() < 1e-8 * h_rms
    assert res.gap.min() > -1e-8 * h_rms
    assert (res.pressure[res.gap > 1e-8 * h_rms] == 0).all()
    assert 0.05 < res.contact_fraction < 0.2  # the case is what it claims to be
    # the reported fields are consistent: gap = u - h - d
    recon = res.elastic_displacement - rough_case["heights"] - res.displacement
    assert np.abs(recon - res.gap).max() < 1e-12 * h_rms


def test_warm_start_from_converged_field(rough_case, hertz_case):
    """Restarting from a converged pressure converges in a handful (≤ 5) iterations."""
    res = rough_case["result"]
    again = solve(
        rough_case["heights"],
        rough_case["dx"],
        rough_case["e_star"],
        load=rough_case["load"],
        periodic=True,
        tol=1e-10,
        warm_start=res.pressure,
    )
    assert again.iterations <= 5
    assert np.abs(again.pressure - res.pressure).max() < 1e-8 * res.pressure.max()
    hres = hertz_case["result"]
    again = solve(
        hertz_case["heights"],
        hertz_case["dx"],
        hertz_case["e_star"],
        load=hertz_case["load"],
        warm_start=hres.pressure,
    )
    assert again.iterations <= 5


@pytest.mark.parametrize("case_name", ["rough_case", "hertz_case"])
def test_load_and_displacement_control_agree(case_name, request):
    """Displacement control at the approach found under load control reproduces the load
    and the pressure field: tolerance 1e-6 relative (both solves converge to ≤ 1e-8 in
    the residual; the field inherits that times the problem's condition)."""
    case = request.getfixturevalue(case_name)
    res = case["result"]
    periodic = case_name == "rough_case"
    dc = solve(
        case["heights"],
        case["dx"],
        case["e_star"],
        displacement=res.displacement,
        periodic=periodic,
        tol=1e-10,
    )
    assert abs(dc.load / res.load - 1) < 1e-6
    assert np.abs(dc.pressure - res.pressure).max() < 1e-6 * res.pressure.max()
    assert (dc.contact == res.contact).all()


@pytest.mark.skipif(not HAVE_PYFFTW, reason="pyfftw not installed")
@pytest.mark.parametrize("periodic", [True, False])
def test_backends_give_same_solution(periodic, hertz_case, rough_case):
    """Whole solves with pyfftw and numpy agree to 1e-9 of the peak pressure (same
    algorithm; only FFT round-off differs, amplified mildly by the iteration)."""
    case = rough_case if periodic else hertz_case
    kw = {"load": case["load"], "periodic": periodic, "tol": 1e-10}
    a = solve(case["heights"], case["dx"], case["e_star"], backend="numpy", **kw)
    b = solve(case["heights"], case["dx"], case["e_star"], backend="pyfftw", threads=2, **kw)
    assert np.abs(a.pressure - b.pressure).max() < 1e-9 * a.pressure.max()


@pytest.mark.parametrize("periodic", [True, False])
def test_coarse_to_fine_same_answer(periodic, hertz_case, rough_case):
    """The coarse-to-fine start changes only the starting point, not the solution
    (same 1e-6 criterion as the control-mode test) and actually runs coarse levels."""
    case = rough_case if periodic else hertz_case
    ref = case["result"]
    tol = 1e-10 if periodic else 1e-8
    res = solve(
        case["heights"],
        case["dx"],
        case["e_star"],
        load=case["load"],
        periodic=periodic,
        tol=tol,
        coarse_to_fine=True,
    )
    assert len(res.info.coarse_levels) >= 1
    assert np.abs(res.pressure - ref.pressure).max() < 1e-6 * ref.pressure.max()


def test_load_series(hertz_case):
    """Loads step upward with warm starts: areas and approaches increase, every step
    obeys force balance (1e-12) and matches an independent cold solve (1e-6)."""
    c = hertz_case
    loads = c["load"] * np.array([0.25, 0.5, 1.0])
    series = solve_load_series(c["heights"], c["dx"], c["e_star"], loads)
    assert [r.load for r in series] == pytest.approx(list(loads), rel=1e-12)
    areas = [r.area for r in series]
    ds = [r.displacement for r in series]
    assert areas == sorted(areas) and ds == sorted(ds)
    assert np.abs(series[-1].pressure - c["result"].pressure).max() < (
        1e-6 * c["result"].pressure.max()
    )
    with pytest.raises(ContactInputError, match="increasing"):
        solve_load_series(c["heights"], c["dx"], c["e_star"], loads[::-1])


def test_no_contact_under_displacement_control(hertz_case):
    """An approach that does not reach the indenter gives the exact zero solution."""
    c = hertz_case
    res = solve(c["heights"], c["dx"], c["e_star"], displacement=-1e-3)
    assert res.load == 0 and not res.contact.any() and res.converged
