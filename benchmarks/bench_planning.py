"""Benchmark 0 (supporting): FFTW planner effort - planning time vs transform time.

For the periodic operator (rfft2 + irfft2 of n²) and the pruned non-periodic operator
(padded 2n²), plans are built with FFTW_ESTIMATE, FFTW_MEASURE and FFTW_PATIENT
(``planner_effort=``) in fresh subprocesses with the wisdom file switched off
(``AMONTONS_FFTW_WISDOM=""``), so every planning starts cold, and one convolution is timed
(median). The solver's default is FFTW_MEASURE, planned once per machine and kept on disk
(docs/models.md §2.1, "FFT plans"); the table says what it buys per convolution over
FFTW_ESTIMATE and what the first planning costs.

    python benchmarks/bench_planning.py           # 1024²
    python benchmarks/bench_planning.py --quick   # 256²
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

from _common import header, parser, table

CHILD = r"""
import json, statistics, time
import numpy as np
from amontons.contact.convolution import NonPeriodicConvolution, PeriodicConvolution
n, periodic, threads = {n}, {periodic}, {threads}
t0 = time.perf_counter()
cls = PeriodicConvolution if periodic else NonPeriodicConvolution
op = cls((n, n), 1.0, 1.0, backend="pyfftw", threads=threads, planner_effort={effort!r})
plan = time.perf_counter() - t0
p = np.random.default_rng(0).random((n, n))
out = np.empty((n, n))
op(p, out=out)
ts = []
for _ in range({repeats}):
    t0 = time.perf_counter()
    op(p, out=out)
    ts.append(time.perf_counter() - t0)
print(json.dumps({{"plan": plan, "conv": statistics.median(ts)}}))
"""


def main():
    args = parser(__doc__.splitlines()[0]).parse_args()
    sizes = args.sizes or ([256] if args.quick else [1024])
    repeats = args.repeats or 15
    header("FFTW planner effort", args)
    rows = []
    for n in sizes:
        for periodic in (True, False):
            for effort in ("FFTW_ESTIMATE", "FFTW_MEASURE", "FFTW_PATIENT"):
                code = CHILD.format(
                    n=n, periodic=periodic, threads=args.threads, repeats=repeats, effort=effort
                )
                proc = subprocess.run(
                    [sys.executable, "-c", code],
                    capture_output=True,
                    text=True,
                    check=True,
                    env=dict(os.environ, AMONTONS_FFTW_WISDOM=""),  # plan cold
                )
                r = json.loads(proc.stdout.strip().splitlines()[-1])
                rows.append(
                    {
                        "grid": f"{n}²",
                        "operator": "periodic" if periodic else "non-periodic (pruned)",
                        "effort": effort,
                        "operator build s (plans + kernel)": r["plan"],
                        "convolution ms": r["conv"] * 1e3,
                    }
                )
                print(rows[-1], file=sys.stderr, flush=True)
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
