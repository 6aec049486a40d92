"""The golden record of the contact solver: a fixed set of solves that every later version
must reproduce, to the last bit on the machine that recorded them and to stated tolerances on
any other (tests/contact/test_golden.py; the tolerances and why: compare.py).

The solves were 26f01d4's, before the rebuild of issue 38, until the bounded iteration's
reset rule changed on 2026-11-28 (docs/models.md §2.2); since then they are that change's,
recorded on the machine named in golden.machine.json (compare.py says what moved). Run from
the repository root to re-record (only when a change of the numbers is intended, and say so
in the commit):

    python tests/contact/golden/record.py

It writes golden.npz and, beside it, golden.machine.json: the CPU, its vector features and
the numerical libraries' versions, which decide whether a machine must match the record to
the last bit. A rebuild that must keep the bits checks them with same_bits.py (``make
golden-bits BASE=<commit before the change>``).

Every solve plans its transforms with FFTW_ESTIMATE in a process that imports no FFTW wisdom
(``AMONTONS_FFTW_WISDOM`` empty, set below before the solver is imported): an ESTIMATE plan
is chosen by rule, not by timing, so the bytes are the same on every machine of the same kind
and do not depend on a wisdom file left by earlier runs. (With wisdom, FFTW uses it for an
ESTIMATE plan too; with FFTW_MEASURE, fresh processes may time their way to other plans.)
One thread. The script therefore always runs in a process of its own: the test starts it
with ``--out`` and compares what it writes with the record.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np
from compare import machine  # beside this script, which always runs as a script

# No wisdom in this process: the plans are FFTW_ESTIMATE's alone (see above).
os.environ["AMONTONS_FFTW_WISDOM"] = ""

import amontons  # noqa: E402 (after the wisdom setting)
from amontons.contact import (  # noqa: E402
    ContactHardening,
    PenetrationHardness,
    self_affine,
    solve,
    solve_load_series,
    solve_scan,
    sphere,
)

PATH = Path(__file__).with_name("golden.npz")
EFFORT = {"threads": 1, "planner_effort": "FFTW_ESTIMATE"}
FIELDS = ("pressure", "gap", "plastic_displacement")
SCALARS = ("displacement", "load", "area", "iterations", "residual")


def rough_periodic(n=128):
    """Self-affine periodic surface (E* = 1 Pa, spacing 1 m), ~10 % contact at 0.005 E*."""
    return self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=3)


def rough_sphere(n=96, spacing=0.2e-6):
    """A rough PMMA-scale sphere (R = 0.75 mm, 30 nm rms roughness), non-periodic."""
    h = sphere((n, n), spacing, 0.75e-3) + self_affine(
        (n, n), spacing, 0.8, rms_height=30e-9, rng=1
    )
    return h, spacing


E_PMMA, K_PMMA = 3.5e9, 7e15  # Pa, Pa/m
P_Y = 30e6  # Pa, penetration hardness (73 points at the bound on the rough sphere at 1e-4 N)
LOAD_SPHERE = 1e-4  # N
D_SPHERE = -1.9e-8  # m, approach of the displacement-controlled 96² sphere solve
D_SPHERE_64 = -5.5e-8  # m, the same on the 64² sphere


def cases():
    """Name → a callable returning one ContactResult or a list of them."""
    hp = rough_periodic()
    n = hp.shape[0]
    hs, dx = rough_sphere()
    hs64, dx64 = rough_sphere(64)
    hard = PenetrationHardness(P_Y)
    return {
        "elastic_periodic_load": lambda: solve(
            hp, 1.0, 1.0, load=0.005 * n * n, periodic=True, **EFFORT
        ),
        "elastic_periodic_displacement": lambda: solve(
            hp, 1.0, 1.0, displacement=-np.quantile(hp, 0.9), periodic=True, **EFFORT
        ),
        "elastic_periodic_coarse_to_fine": lambda: solve(
            hp, 1.0, 1.0, load=0.005 * n * n, periodic=True, coarse_to_fine=True, **EFFORT
        ),
        "elastic_sphere_padded": lambda: solve(hs, dx, E_PMMA, load=LOAD_SPHERE, **EFFORT),
        "elastic_sphere_numpy": lambda: solve(
            hs64, dx64, E_PMMA, load=0.25 * LOAD_SPHERE, backend="numpy"
        ),
        "hardness_bounded_load": lambda: solve(
            hs, dx, E_PMMA, load=LOAD_SPHERE, plasticity=hard, **EFFORT
        ),
        "hardness_bounded_displacement": lambda: solve(
            hs, dx, E_PMMA, displacement=D_SPHERE, plasticity=hard, **EFFORT
        ),
        "hardness_bounded_periodic": lambda: solve(
            hp,
            1.0,
            1.0,
            load=0.005 * n * n,
            periodic=True,
            plasticity=PenetrationHardness(0.1),
            **EFFORT,
        ),
        "hardness_appendix_load": lambda: solve(
            hs64,
            dx64,
            E_PMMA,
            load=0.25 * LOAD_SPHERE,
            plasticity=hard,
            method="appendix",
            **EFFORT,
        ),
        "hardening_winkler_load": lambda: solve(
            hs, dx, E_PMMA, load=LOAD_SPHERE, plasticity=ContactHardening(K_PMMA), **EFFORT
        ),
        "hardening_appendix_load": lambda: solve(
            hs64,
            dx64,
            E_PMMA,
            load=0.25 * LOAD_SPHERE,
            plasticity=ContactHardening(K_PMMA, alpha=0.5),
            method="appendix",
            **EFFORT,
        ),
        "hardening_volume_load": lambda: solve(
            hs64,
            dx64,
            E_PMMA,
            load=0.25 * LOAD_SPHERE,
            plasticity=ContactHardening(K_PMMA, increment="volume", alpha=0.5),
            **EFFORT,
        ),
        "hardness_volume_displacement": lambda: solve(
            hs64,
            dx64,
            E_PMMA,
            displacement=D_SPHERE_64,
            plasticity=PenetrationHardness(P_Y, increment="volume", alpha=0.5),
            **EFFORT,
        ),
        "series_hardening": lambda: solve_load_series(
            hs,
            dx,
            E_PMMA,
            [0.25 * LOAD_SPHERE, LOAD_SPHERE, 2 * LOAD_SPHERE],
            plasticity=ContactHardening(K_PMMA),
            **EFFORT,
        ),
        "series_elastic": lambda: solve_load_series(
            hs, dx, E_PMMA, [0.25 * LOAD_SPHERE, LOAD_SPHERE], **EFFORT
        ),
        "scan_hardness": lambda: solve_scan(
            hs,
            dx,
            E_PMMA,
            [0.25 * LOAD_SPHERE, LOAD_SPHERE],
            [PenetrationHardness(2 * P_Y), PenetrationHardness(P_Y)],
            **EFFORT,
        ),
    }


def machine_path(npz: Path) -> Path:
    """The machine record beside ``npz``: golden.npz -> golden.machine.json."""
    return npz.with_suffix(".machine.json")


def flatten(result) -> list:
    """A case's results as a flat list (a series is a list, a scan a list of lists)."""
    if isinstance(result, list):
        return [r for item in result for r in flatten(item)]
    return [result]


def arrays(name: str, results: list) -> dict[str, np.ndarray]:
    """The stored arrays of one case: every field and scalar of every result."""
    out = {}
    for i, res in enumerate(results):
        for f in FIELDS:
            out[f"{name}/{i}/{f}"] = np.asarray(getattr(res, f))
        for s in SCALARS:
            out[f"{name}/{i}/{s}"] = np.asarray(getattr(res, s))
    return out


def compute(names=None) -> dict[str, np.ndarray]:
    """Solve the cases (all, or those named) and return their arrays."""
    out = {}
    for name, run in cases().items():
        if names is None or name in names:
            out.update(arrays(name, flatten(run())))
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="solve the golden cases and store them")
    parser.add_argument("--out", type=Path, default=PATH, help="npz to write (the record)")
    args = parser.parse_args(argv)
    print(f"solving with {Path(amontons.__file__).parent}", file=sys.stderr)
    data = compute()
    np.savez_compressed(args.out, **data)
    machine_path(args.out).write_text(json.dumps(machine(), indent=1) + "\n")
    size = args.out.stat().st_size
    print(f"{len(data)} arrays in {args.out} ({size / 1e6:.2f} MB)", file=sys.stderr)


if __name__ == "__main__":
    main()
