"""Benchmark 1: time per CG iteration as a multiple of one FFT pair of the convolution's grid.

For each grid a full load-controlled solve (tol 1e-8, cold start) is timed; per iteration:
milliseconds, convolutions, and the ratio to one pyfftw r2c + c2r pair of the grid the
convolution works on (n² periodic; non-periodic m², m >= 2n the fast length of the Hockney
padding, ``op.padded_shape``; 2n before 2026-11-23's "Fast FFT lengths"), planned with the
same effort and threads and timed in the same process, alternating with the solves. The
remainder is ratio minus convolutions per iteration: everything an iteration does besides
its FFT pairs (element-wise work, spectrum multiply, point responses). "in conv" is the
time inside the operator calls (the FFT pairs plus their spectrum multiply) in pairs per
iteration, so "ratio − in conv" is the element-wise work alone. "ratio, cold pair" divides
by a pair timed after a sweep over 128 MB: back to back, a pair whose arrays fit in the
last-level cache (1024² here) runs from it, which an FFT inside an iteration never does.
"ratio, MEASURE pair" divides by the floor the issue names (issue 23): a pair planned with
FFTW_MEASURE on the same threads, back to back, whatever effort the solver plans with.
"sweep floor" is what the element-wise work cannot go below on this machine: the bytes the
three sweeps of a periodic iteration must move (SWEEP_BYTES per point) at the memory
bandwidth of a three-array ``np.add`` timed in the same process, in MEASURE pairs.
"host steal %" is the share of the machine's CPU time a virtual machine's host took while
the row's repeats ran (:class:`_common.HostSteal`). Medians of --repeats.

Paths: ``fused`` (numba kernels, the solver's one loop) and ``numpy`` (the reference loop
the tests compare with, tests/contact/numpy_oracle.py). The solve runs inside
:func:`amontons.contact.pools.solve_pools` as :func:`amontons.contact.solve` does, in a
plain process (no thread environment variables, unless ``--pinned``).

    python benchmarks/bench_iteration.py                    # 1024², 2048²
    python benchmarks/bench_iteration.py --sizes 512 1024 2048 --threads 1 2
    python benchmarks/bench_iteration.py --quick            # 256², 512²
"""

from __future__ import annotations

import importlib.util
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from _common import (
    E_STAR,
    HostSteal,
    header,
    median_time,
    parser,
    rough_load,
    rough_surface,
    sphere_problem,
    table,
)

from amontons.contact.cg import polonsky_keer
from amontons.contact.convolution import get_operator
from amontons.contact.fft import RealFFT2Pair, resolve_planner_effort
from amontons.contact.options import CGOptions
from amontons.contact.pools import solve_pools

_ORACLE = Path(__file__).resolve().parents[1] / "tests" / "contact" / "numpy_oracle.py"


def numpy_polonsky_keer(*args, **kwargs):
    """The numpy reference loop of the tests (loaded from its file on first use)."""
    spec = importlib.util.spec_from_file_location("numpy_oracle", _ORACLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.numpy_polonsky_keer(*args, **kwargs)


class TimedOperator:
    """Wraps a convolution operator and accumulates the time spent in its calls (the sparse
    point responses are forwarded untimed: they are element-wise work)."""

    def __init__(self, op):
        self.op, self.seconds = op, 0.0

    def __getattr__(self, name):
        return getattr(self.op, name)

    def _timed(self, fn, *args, **kw):
        t0 = time.perf_counter()
        r = fn(*args, **kw)
        self.seconds += time.perf_counter() - t0
        return r

    def __call__(self, x, out=None):
        return self._timed(self.op, x, out=out)

    # the convolution in halves (the fused loop's r = K*t): timed like a whole call
    def forward(self, x):
        return self._timed(self.op.forward, x)

    def multiply_energy(self):
        return self._timed(self.op.multiply_energy)

    def inverse(self, out):
        return self._timed(self.op.inverse, out)


def problem(n, periodic):
    """Heights (m) and load (N) of the benchmark problem (README)."""
    if periodic:
        return rough_surface(n), rough_load(n)
    return sphere_problem(n)


def solve_once(op, h, load, kernels, threads):
    timed = TimedOperator(op)
    t0 = time.perf_counter()
    with solve_pools(threads):
        loop = polonsky_keer if kernels else numpy_polonsky_keer
        options = CGOptions(tol=1e-8, max_iter=5000, threads=threads)  # the numpy loop: no threads
        out = loop(
            timed, h, options, pixel_area=1.0, h_scale=h.std(), p_init=np.ones_like(h), load=load
        )
    return time.perf_counter() - t0, timed.seconds, out


def run(n, periodic, path, threads, effort, repeats):
    """One row: plans, floors and solves all under the pools a solve on ``threads`` holds
    (OpenMP at ``threads``), so that the floors are timed as the solve's transforms run."""
    with solve_pools(threads):
        return _measure(n, periodic, path, threads, effort, repeats)


def _measure(n, periodic, path, threads, effort, repeats):
    h, load = problem(n, periodic)
    effort = resolve_planner_effort(effort)
    op = get_operator(
        h.shape, 1.0, E_STAR, periodic=periodic, threads=threads, planner_effort=effort
    )
    fft_shape = h.shape if periodic else op.padded_shape  # fast lengths >= 2n
    pair = RealFFT2Pair(fft_shape, threads=threads, planner_effort=effort)
    pair.real[...] = np.random.default_rng(0).random(pair.shape)
    measured = RealFFT2Pair(fft_shape, threads=threads, planner_effort="FFTW_MEASURE")
    measured.real[...] = pair.real
    kernels = path == "fused"
    solve_once(op, h, load, kernels, threads)  # warm-up: plans, kernels, caches
    ratios, per_it, pairs, in_conv, cold_ratios = [], [], [], [], []
    measured_pairs, measured_ratios, measured_conv = [], [], []
    bandwidth = _stream_bandwidth(h.size)
    steal = HostSteal()
    with steal:  # the host's share of the row's timed work
        for _ in range(repeats):
            pair_t = _pair_time(pair)
            cold_t = _pair_time(pair, cold=True)
            measured_t = _pair_time(measured)
            dt, conv_s, out = solve_once(op, h, load, kernels, threads)
            pair_t = 0.5 * (pair_t + _pair_time(pair))
            it = out.iterations
            per_it.append(dt / it)
            pairs.append(pair_t)
            cold_ratios.append(dt / it / cold_t)
            ratios.append(dt / it / pair_t)
            in_conv.append(conv_s / it / pair_t)
            measured_pairs.append(measured_t)
            measured_ratios.append(dt / it / measured_t)
            measured_conv.append(conv_s / it / measured_t)
    conv_per_it = out.convolutions / out.iterations
    ratio = statistics.median(ratios)
    conv = statistics.median(in_conv)
    return {
        "grid": f"{n}²",
        "bc": "periodic" if periodic else "non-periodic",
        "path": path,
        "threads": threads,
        "effort": effort.removeprefix("FFTW_"),
        "iterations": out.iterations,
        "ms / iteration": statistics.median(per_it) * 1e3,
        # FFT pairs: a forward transform whose inverse the fused loop skipped counts 0.5
        "convolutions / iteration": conv_per_it,
        "FFT pair ms": statistics.median(pairs) * 1e3,
        "ratio": ratio,
        "ratio, cold pair": statistics.median(cold_ratios),
        "remainder": ratio - conv_per_it,
        "in conv (pairs)": conv,
        "element-wise (pairs)": ratio - conv,
        "MEASURE pair ms": statistics.median(measured_pairs) * 1e3,
        "ratio, MEASURE pair": statistics.median(measured_ratios),
        "element-wise (MEASURE pairs)": statistics.median(
            [r - c for r, c in zip(measured_ratios, measured_conv, strict=True)]
        ),
        "memory GB/s": bandwidth / 1e9,
        "host steal %": steal.percent,
        "sweep floor (MEASURE pairs)": SWEEP_BYTES
        * h.size
        / bandwidth
        / statistics.median(measured_pairs),
        "area": float(np.mean(out.pressure > 0)),
        # how u followed each step: linear (no changed point), point responses, or a full
        # convolution because too many points changed / for the periodic refresh
        "u updates (lin/pts/full chg/full refresh)": "/".join(
            str(v) for v in out.info.get("u_updates", {}).values()
        )
        or "-",
    }


# Bytes per grid point the element-wise work of one iteration must move (float64 fields,
# uint8 free mask): gap_moments reads u, h, t, m (25); direction reads u, h, t, m and writes
# t (33); update reads p, t, m and writes p, m (26).
SWEEP_BYTES = 25 + 33 + 26


def _stream_bandwidth(size, calls=9):
    """Memory bandwidth of one core, bytes/s: ``np.add`` of two float64 arrays of ``size``
    into a third (24 bytes per point), each call after the 128 MB sweep, median."""
    a, b, c = (np.full(size, v) for v in (1.0, 2.0, 0.0))
    return 24 * size / median_time(lambda: np.add(a, b, out=c), calls, warmup=0, cold=True)


def _pair_time(pair, calls=5, cold=False):
    """Median time of one FFT pair over ``calls`` calls, s. Back to back (the default,
    the floor of the tables) a pair whose arrays fit in the last-level cache (1024²: 16 MB)
    runs from it; ``cold`` sweeps a 128 MB array before each call (untimed), so the pair
    meets its data in memory as an FFT inside an iteration does."""
    return median_time(pair, calls, warmup=0, cold=cold)


def main():
    ap = parser(__doc__.splitlines()[0])
    ap.add_argument(
        "--thread-counts", type=int, nargs="*", default=None, help="overrides --threads"
    )
    ap.add_argument(
        "--effort",
        default=None,
        help="FFTW planner effort (default: the solver's, FFTW_MEASURE with the wisdom on disk)",
    )
    ap.add_argument("--paths", nargs="*", default=["fused", "numpy"], choices=["fused", "numpy"])
    ap.add_argument(
        "--bc",
        nargs="*",
        default=["periodic", "non-periodic"],
        choices=["periodic", "non-periodic"],
    )
    args = ap.parse_args()
    sizes = args.sizes or ([256, 512] if args.quick else [1024, 2048])
    repeats = args.repeats or 3
    header("Benchmark 1: CG iteration time / FFT pair", args)
    rows = []
    for n in sizes:
        for bc in args.bc:
            for threads in args.thread_counts or [args.threads]:
                for path in args.paths:
                    rows.append(run(n, bc == "periodic", path, threads, args.effort, repeats))
                    print(rows[-1], file=sys.stderr, flush=True)
    _speed_ups(rows)
    table(rows, list(rows[0]) + ["speed-up vs 1 thread"])


def _speed_ups(rows):
    """Add, to each row on more than one thread, its speed over the same case on one."""
    one = {(r["grid"], r["bc"], r["path"]): r for r in rows if r["threads"] == 1}
    for r in rows:
        base = one.get((r["grid"], r["bc"], r["path"]))
        if base is not None and r["threads"] > 1:
            r["speed-up vs 1 thread"] = base["ms / iteration"] / r["ms / iteration"]


if __name__ == "__main__":
    main()
