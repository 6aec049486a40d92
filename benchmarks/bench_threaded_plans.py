"""Threaded FFTW plans against slabs of one-thread plans, in rounds (benchmarks/README.md,
"A second core").

Makes ``--plans`` two-thread FFTW_MEASURE plans of an ``n x n`` real pair, each in a fresh
process with its own wisdom file (so each is one independent MEASURE pick), and says of
each transform whether its threads sit outside the column pass (``out``: one parallel
region a pass) or inside its buffered blocks (``in``: a region per block of columns). Then,
in each of ``--rounds`` rounds, times in a fresh process per entry: the one-thread pair, each
threaded plan (imported from its file, nothing re-timed), and the pair as the solver runs it
on ``--threads`` (slabs, ``contact.fft.real_fft2``). Each figure is the median of 15 pairs
back to back, ms; a round's line is printed as it ends, then a summary per entry: median,
range and the rounds in which it gained less than 1.25x over the one-thread pair.

    python benchmarks/bench_threaded_plans.py --size 1024 --plans 12 --rounds 10 --pause 150
"""

from __future__ import annotations

import argparse
import ctypes
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import median_time

from amontons.contact.fft import RealFFT2Pair
from amontons.contact.pools import solve_pools
from amontons.contact.wisdom import WISDOM_ENV, shared_wisdom

try:
    import pyfftw
except ImportError:  # pragma: no cover - the benchmark needs pyfftw
    sys.exit("bench_threaded_plans needs pyfftw")

PAIRS = 15
NO_GAIN = 1.25  # below this speed-up over one thread a round counts as "no gain"
FFTW_WISDOM_ONLY = 1 << 21  # fftw3.h
FFTW_DESTROY_INPUT = 1


def _fftw_threaded_pair(n: int, threads: int, flags):
    real = pyfftw.empty_aligned((n, n), "float64")
    spec = pyfftw.empty_aligned((n, n // 2 + 1), "complex128")
    kw = {"axes": (0, 1), "threads": threads}
    with shared_wisdom():
        fwd = pyfftw.FFTW(real, spec, flags=flags, **kw)
        inv = pyfftw.FFTW(
            spec, real, direction="FFTW_BACKWARD", flags=(*flags, "FFTW_DESTROY_INPUT"), **kw
        )
    return real, fwd, inv


def _median_pair_ms(run, real) -> float:
    real[...] = np.random.default_rng(0).random(real.shape)
    return 1e3 * median_time(run, PAIRS, warmup=3)


def _fftw_library():
    """pyfftw's own FFTW (the wheel's vendored copy), for fftw_sprint_plan; None if the
    build keeps it elsewhere."""
    libs = Path(pyfftw.__file__).parent.parent / "pyfftw.libs"
    found = sorted(glob.glob(str(libs / "libfftw3-*.so*")))
    omp = sorted(glob.glob(str(libs / "libfftw3_omp-*.so*")))
    if not (found and omp):
        return None, None
    return ctypes.CDLL(found[0]), ctypes.CDLL(omp[0])


def _where_the_threads_are(n: int, threads: int) -> str:
    """'out' or 'in' for the forward and the inverse plan the process's wisdom holds: are
    the threads split above the column pass's buffered loop, or inside it?"""
    lib, omp = _fftw_library()
    if lib is None:
        return "?/?"
    omp.fftw_plan_with_nthreads(threads)
    for name in ("fftw_plan_dft_r2c_2d", "fftw_plan_dft_c2r_2d", "fftw_sprint_plan"):
        getattr(lib, name).restype = ctypes.c_void_p
    lib.fftw_sprint_plan.argtypes = [ctypes.c_void_p]
    real = pyfftw.empty_aligned((n, n), "float64")
    spec = pyfftw.empty_aligned((n, n // 2 + 1), "complex128")
    r, s = ctypes.c_void_p(real.ctypes.data), ctypes.c_void_p(spec.ctypes.data)
    plans = (
        lib.fftw_plan_dft_r2c_2d(n, n, r, s, FFTW_WISDOM_ONLY),
        lib.fftw_plan_dft_c2r_2d(n, n, s, r, FFTW_WISDOM_ONLY | FFTW_DESTROY_INPUT),
    )
    where = []
    for plan in plans:
        if not plan:
            where.append("?")
            continue
        text = ctypes.string_at(lib.fftw_sprint_plan(plan)).decode()
        buffered, split = text.find("dft-buffered"), text.find("dft-thr-vrank")
        if split < 0:
            where.append("none")
        else:
            where.append("in" if 0 <= buffered < split else "out")
    return "/".join(where)


def make_plan(n: int, threads: int) -> None:
    """Child: one MEASURE pick into the wisdom file of $AMONTONS_FFTW_WISDOM."""
    with solve_pools(threads):
        _fftw_threaded_pair(n, threads, ("FFTW_MEASURE",))
    print(_where_the_threads_are(n, threads))


def time_entry(n: int, threads: int, entry: str) -> None:
    """Child: the median pair of one entry, ms."""
    with solve_pools(threads):
        if entry == "one thread":
            pair = RealFFT2Pair((n, n), threads=1)
            print(_median_pair_ms(pair, pair.real))
        elif entry == "slabs":
            pair = RealFFT2Pair((n, n), threads=threads)
            print(_median_pair_ms(pair, pair.real))
        else:  # a threaded FFTW plan from its own wisdom file, nothing measured
            real, fwd, inv = _fftw_threaded_pair(n, threads, ("FFTW_MEASURE", "FFTW_WISDOM_ONLY"))

            def run():
                fwd.execute()
                inv.execute()

            print(_median_pair_ms(run, real))


def _child(args, *extra, wisdom=None) -> str:
    env = dict(os.environ)
    if wisdom is not None:
        env[WISDOM_ENV] = str(wisdom)
    command = [sys.executable, __file__, "--size", str(args.size), "--threads", str(args.threads)]
    out = subprocess.run(
        [*command, *extra], env=env, capture_output=True, text=True, check=True
    ).stdout
    return out.strip().splitlines()[-1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--plans", type=int, default=12)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--pause", type=float, default=60.0, help="seconds between rounds")
    ap.add_argument("--make-plan", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--time", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.make_plan:
        return make_plan(args.size, args.threads)
    if args.time is not None:
        return time_entry(args.size, args.threads, args.time)

    n = args.size
    print(f"# threaded FFTW plans vs slabs, {n}², {args.threads} threads, {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        files, where = {}, {}
        for k in range(1, args.plans + 1):
            name = f"plan {k:02d}"
            files[name] = Path(tmp) / f"{k:02d}.json"
            where[name] = _child(args, "--make-plan", wisdom=files[name])
        print("# threads of each plan (forward/inverse):", json.dumps(where))
        entries = ["one thread", "slabs", *files]
        seen = {e: [] for e in entries}
        for r in range(args.rounds):
            if r:
                time.sleep(args.pause)
            line = {}
            for entry in entries:
                line[entry] = float(_child(args, "--time", entry, wisdom=files.get(entry)))
                seen[entry].append(line[entry])
            stamp = time.strftime("%H:%M", time.gmtime())
            print(stamp, " ".join(f"{e}={v:.1f}" for e, v in line.items()), flush=True)
        print("| entry | threads (fwd/inv) | median ms | range ms | rounds < 1.25× one thread |")
        print("|---|---|---|---|---|")
        one = seen["one thread"]
        for entry in entries:
            times = seen[entry]
            slow = sum(o / t < NO_GAIN for o, t in zip(one, times, strict=True))
            kind = where.get(entry, "slabs" if entry == "slabs" else "-")
            print(
                f"| {entry} | {kind} | {statistics.median(times):.1f} | "
                f"{min(times):.1f}-{max(times):.1f} | "
                f"{slow if entry != 'one thread' else '-'} of {len(times)} |"
            )


if __name__ == "__main__":
    main()
