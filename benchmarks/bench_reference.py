"""Benchmark 4: time to solution against Tamaas 2.9 and ContactMechanics 1.8.

Same periodic self-affine surface (Hurst 0.8, rms slope 0.1, p̄ = 0.005 E*, ~10 % contact),
same load, one thread; this solver with each of its CG iterations (``amontons``:
Polonsky-Keer's, ``amontons-preconditioned``: the preconditioned one). Two problems: the
elastic contact, and penetration hardness at p_Y = 0.1 E* (local increments;
ContactMechanics' PlasticNonSmoothContactSystem, Tamaas left out: its KatoSaturated is much
slower still). Every solver runs in a fresh subprocess
and only the solve call is timed (model set-up and, for us, plan building and the kernels'
load happen before; our plans use planner_effort="FFTW_MEASURE", passed explicitly), median
of --repeats runs.

Threads. This solver runs as a user runs it: a plain process, no thread environment
variables (it bounds the native pools itself); with --pinned it gets
OMP_NUM_THREADS = OPENBLAS_NUM_THREADS = MKL_NUM_THREADS = 1 too. The peers always get those
variables set to --threads: that is their best case (unbounded BLAS pools only slow them).

Matching the accuracy. The solvers stop on different measures: Tamaas PolonskyKeerRey on a
normalised complementarity error, ContactMechanics on penetration / force / relative-change
tolerances, this solver on the larger of the relative pressure change and the rms gap on the
contact over the rms height. Each one's stopping value is set so that all reach the same
*accuracy* against a tightly converged reference (this solver at tol 1e-11, which agrees
with Tamaas at 1e-12 to ~1e-12): tol 3e-9 (ours), tolerance 1e-8 (Tamaas), pentol =
1e-8·h_rms with forcetol = thermotol = 1e-10 (ContactMechanics). The table prints, for every
solver, the max pressure error over the peak, and the relative errors of the contact area
fraction and of the approach. Both are derived from the returned pressure the same way for
every solver (area: points with p > 0; approach: the mean of K*p - h over the free points,
K the periodic kernel), so the comparison does not depend on how a solver reports them.

    python benchmarks/bench_reference.py                        # 512², 1024², both problems
    python benchmarks/bench_reference.py --quick                # 128², 256²
    python benchmarks/bench_reference.py --peer-python /path/to/venv/bin/python

--peer-python runs the peers with another interpreter (an environment that has tamaas and
ContactMechanics; they need not be installed beside this project).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile

import numpy as np
from _common import E_STAR, PINNED, TIMING_EFFORT, header, parser, rough_load, rough_surface, table

from amontons.contact import PenetrationHardness, solve
from amontons.contact.convolution import PeriodicConvolution

# Penetration hardness of the benchmark (issue 14): p_Y = 0.1 E*.
HARDNESS = 0.1 * E_STAR
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
# This solver with its two CG iterations: Polonsky-Keer's (the default) and the
# preconditioned one (docs/models.md §2.2), each in a child of its own.
OURS = ("amontons", "amontons-preconditioned")

# One child per solver and problem: loads the heights, times `repeats` solves, saves the last
# pressure. {problem} is "elastic" or "hardness"; {hardness} is p_Y in E* units.
CHILD = r"""
import json, sys, time
import numpy as np
solver, problem, repeats, threads = {solver!r}, {problem!r}, {repeats}, {threads}
h = np.load({heights!r})
n = h.shape[0]
load, hardness, e_star, L = {load!r}, {hardness!r}, {e_star!r}, float(n)
times, extra = [], {{}}
for _ in range(repeats):
    if solver.startswith("amontons"):
        from amontons.contact import PenetrationHardness, solve
        iteration = "preconditioned" if solver.endswith("preconditioned") else "polonsky-keer"
        kw = dict(periodic=True, threads=threads, planner_effort={effort!r}, iteration=iteration)
        if problem == "hardness":
            kw["plasticity"] = PenetrationHardness(hardness)
        if not times:  # plans, kernels and pools ready before the timing
            solve(h, 1.0, e_star, load=load, tol=1e-2, **kw)
        t0 = time.perf_counter()
        res = solve(h, 1.0, e_star, load=load, tol=3e-9, **kw)
        times.append(time.perf_counter() - t0)
        p = res.pressure
        extra["iterations"] = res.iterations
    elif solver == "tamaas":
        import tamaas as tm
        tm.set_log_level(tm.LogLevel.error)
        model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
        model.E, model.nu = e_star, 0.0  # E* = E / (1 - nu^2)
        s = tm.PolonskyKeerRey(model, h.copy(), 1e-8, tm.PolonskyKeerRey.pressure,
                               tm.PolonskyKeerRey.pressure)
        s.max_iter = 100000
        t0 = time.perf_counter()
        s.solve(load / (L * L))  # Tamaas takes the mean pressure
        times.append(time.perf_counter() - t0)
        p = np.array(model.traction).reshape(n, n)
    elif solver == "contactmechanics":
        from ContactMechanics import PeriodicFFTElasticHalfSpace
        from ContactMechanics.Systems import NonSmoothContactSystem
        from ContactMechanics.PlasticSystemSpecialisations import PlasticNonSmoothContactSystem
        from SurfaceTopography import PlasticTopography, Topography
        sub = PeriodicFFTElasticHalfSpace((n, n), e_star, (L, L))
        topo = Topography(h, (L, L), periodic=True)
        if problem == "hardness":
            system = PlasticNonSmoothContactSystem(sub, PlasticTopography(topo, hardness))
        else:
            system = NonSmoothContactSystem(sub, topo)
        t0 = time.perf_counter()
        sol = system.minimize_proxy(external_force=load, pentol=1e-8 * h.std(),
                                    forcetol=1e-10, thermotol=1e-10, maxiter=100000)
        times.append(time.perf_counter() - t0)
        p = np.asarray(sol.jac).reshape(n, n)  # compressive force per pixel, pixel area 1
        extra["iterations"] = int(sol.nit)
np.save({out!r}, p)
print(json.dumps({{"times": times, **extra}}))
"""


def run_child(solver, problem, h, load, repeats, threads, python, tmp):
    """Run one solver in a fresh process: ``(info, pressure)``, or ``({"error": ...}, None)``."""
    heights = os.path.join(tmp, f"h_{h.shape[0]}.npy")
    if not os.path.exists(heights):
        np.save(heights, h)
    out = os.path.join(tmp, f"{solver}_{problem}_{h.shape[0]}.npy")
    env = dict(os.environ)
    if not solver.startswith("amontons") or PINNED:
        env.update(dict.fromkeys(THREAD_VARIABLES, str(threads)))
    else:  # a plain process, as a user runs the solver
        for key in THREAD_VARIABLES:
            env.pop(key, None)
    code = CHILD.format(
        solver=solver,
        problem=problem,
        repeats=repeats,
        threads=threads,
        heights=heights,
        load=float(load),
        hardness=float(HARDNESS),
        e_star=float(E_STAR),
        effort=TIMING_EFFORT,
        out=out,
    )
    proc = subprocess.run([python, "-c", code], capture_output=True, text=True, env=env)
    if proc.returncode:
        return {"error": proc.stderr.strip().splitlines()[-1]}, None
    return json.loads(proc.stdout.strip().splitlines()[-1]), np.load(out)


def contact_measures(p, h, p_max=None):
    """``(area fraction, approach)`` of a periodic solution from its pressure alone: the
    fraction of points with ``p > 0``, and the mean of ``K*p - h`` over the free points
    (``0 < p < p_max``), where the gap is zero (unit spacing, E* of the benchmark)."""
    u = PeriodicConvolution(h.shape, 1.0, E_STAR)(p)
    free = p > 0
    if p_max is not None:
        free &= p < p_max * (1 - 1e-12)  # a peer may stop a hair below the bound
    return float(np.mean(p > 0)), float(np.mean((u - h)[free]))


def relative(a, b):
    return abs(a - b) / abs(b) if b else abs(a - b)


def main():
    ap = parser(__doc__.splitlines()[0])
    ap.add_argument("--peer-python", default=sys.executable, help="interpreter that runs the peers")
    ap.add_argument(
        "--problems", nargs="*", default=["elastic", "hardness"], help="elastic, hardness"
    )
    args = ap.parse_args()
    sizes = args.sizes or ([128, 256] if args.quick else [512, 1024])
    repeats = args.repeats or 3
    header("Benchmark 4: time to solution vs Tamaas and ContactMechanics", args)
    print(f"# peers run by {args.peer_python}, their thread variables = {args.threads}")
    peers = {"elastic": ("tamaas", "contactmechanics"), "hardness": ("contactmechanics",)}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for problem in args.problems:
            for n in sizes:
                h, load = rough_surface(n), rough_load(n)
                law = {"plasticity": PenetrationHardness(HARDNESS)} if problem == "hardness" else {}
                ref = solve(h, 1.0, E_STAR, load=load, periodic=True, tol=1e-11, **law).pressure
                p_max = HARDNESS if problem == "hardness" else None
                ref_area, ref_d = contact_measures(ref, h, p_max)
                ours_t = preconditioned_t = None
                for solver in (*OURS, *peers[problem]):
                    python = sys.executable if solver in OURS else args.peer_python
                    info, p = run_child(
                        solver, problem, h, load, repeats, args.threads, python, tmp
                    )
                    row = {"problem": problem, "grid": f"{n}²", "solver": solver}
                    if p is None:
                        rows.append({**row, "time s (median)": info["error"]})
                        continue
                    t = statistics.median(info["times"])
                    ours_t = t if solver == "amontons" else ours_t
                    if solver == "amontons-preconditioned":
                        preconditioned_t = t
                    area, d = contact_measures(p, h, p_max)
                    rows.append(
                        {
                            **row,
                            "runs": len(info["times"]),
                            "time s (median)": t,
                            "iterations": info.get("iterations", "-"),
                            "max |Δp| / max p": float(np.abs(p - ref).max() / ref.max()),
                            "area fraction rel. error": relative(area, ref_area),
                            "approach rel. error": relative(d, ref_d),
                            "load error": float(abs(p.sum() / load - 1)),
                            "time / ours": t / ours_t if ours_t else "-",
                            "time / ours preconditioned": (
                                t / preconditioned_t if preconditioned_t else "-"
                            ),
                        }
                    )
                    print(rows[-1], file=sys.stderr, flush=True)
    columns = list(dict.fromkeys(k for r in rows for k in r))
    table(rows, columns)


if __name__ == "__main__":
    main()
