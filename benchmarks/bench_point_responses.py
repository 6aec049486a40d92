"""Point responses against a convolution: what following a CG step costs per changed point.

When a step changes few points (clipped or added), the fused solver follows it by the
inverse transform of ``K*t`` and the changed points' responses
(``kernels.add_point_responses``) instead of a whole convolution ``u = K*p``
(``cg_iteration.SPARSE_MAX_PERIODIC`` / ``SPARSE_MAX_PADDED`` points at most). Per grid and boundary
condition this prints: ms per point for 1 and 8 points in one call (each call after a
128 MB sweep, as inside an iteration), the inverse half of a convolution, a whole one, and
the break-even: the number of points whose responses cost what the whole convolution saves
over the inverse half, ``(convolution - inverse) / ms per point (8 points)``.

With ``--changes`` it also solves the grid (the benchmarks' rough surface, load control,
tol 1e-8) and counts the iterations by the number of points their step changed, which says
how many iterations a different limit would move from one side to the other.

    python benchmarks/bench_point_responses.py                      # 1024², 2048²
    python benchmarks/bench_point_responses.py --sizes 1024 --changes
"""

from __future__ import annotations

import numpy as np
from _common import E_STAR, TIMING_EFFORT, header, median_time, parser, rough_load, rough_surface
from _common import table as print_table
from threadpoolctl import threadpool_limits

from amontons.contact import kernels
from amontons.contact.cg import polonsky_keer
from amontons.contact.convolution import get_operator
from amontons.contact.options import CGOptions

BINS = ((0, 0), (1, 12), (13, 20), (21, 32), (33, 64), (65, np.inf))


def point_costs(n, periodic, repeats, threads):
    """ms per point (1 and 8 points), inverse half and whole convolution, ms."""
    op = get_operator(
        (n, n), 1.0, E_STAR, periodic=periodic, threads=threads, planner_effort=TIMING_EFFORT
    )
    green = op.real_space_kernel()
    rng = np.random.default_rng(0)
    u = np.zeros((n, n))
    p = rng.random((n, n))
    out = {}
    with kernels.kernel_threads(threads):
        for k in (1, 8):
            idx = rng.integers(0, n * n, size=k)
            vals = rng.normal(size=k)

            def call(i=idx, v=vals):
                kernels.add_point_responses(u, green, i, v)

            out[f"ms / point ({k})"] = median_time(call, repeats, cold=True) * 1e3 / k
    conv = median_time(lambda: op(p, out=u), repeats, cold=True)
    op.forward(p)
    inverse = median_time(lambda: op.inverse(u), repeats, cold=True)
    out["inverse ms"] = inverse * 1e3
    out["convolution ms"] = conv * 1e3
    out["break-even points"] = (conv - inverse) * 1e3 / out["ms / point (8)"]
    return out


def changes_per_iteration(n):
    """Histogram of the points each step of a full solve changed (``BINS``)."""
    counts = []
    update = kernels.update

    def recording(*args):
        res = update(*args)
        counts.append(int(args[15].sum()))  # the per-chunk clipped / added counts
        return res

    h, load = rough_surface(n), rough_load(n)
    op = get_operator(h.shape, 1.0, E_STAR, periodic=True, threads=1)
    kernels.update = recording
    try:
        with threadpool_limits(1):
            polonsky_keer(
                op, h, CGOptions(tol=1e-8, max_iter=2000), pixel_area=1.0, h_scale=h.std(),
                p_init=np.ones_like(h), load=load,
            )  # fmt: skip
    finally:
        kernels.update = update
    c = np.asarray(counts)
    return {
        f"{lo}-{hi if np.isfinite(hi) else ''}": int(np.count_nonzero((c >= lo) & (c <= hi)))
        for lo, hi in BINS
    }


def main():
    ap = parser(__doc__)
    ap.add_argument("--changes", action="store_true", help="also count changes per iteration")
    args = ap.parse_args()
    sizes = args.sizes or ([256, 512] if args.quick else [1024, 2048])
    repeats = args.repeats or 7
    header("Point responses against a convolution", args)
    rows = []
    for n in sizes:
        for periodic in (True, False):
            if n > 1024 and not periodic:
                continue  # the padded (2n)² kernel of 2048² is 128 MB
            row = {"grid": f"{n}²", "bc": "periodic" if periodic else "non-periodic"}
            row.update(point_costs(n, periodic, repeats, args.threads))
            if args.changes and periodic:
                row["iterations by changed points"] = changes_per_iteration(n)
            print(row, flush=True)
            rows.append(row)
    print_table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
