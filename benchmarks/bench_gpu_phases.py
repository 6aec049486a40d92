"""Where a GPU solve's time goes, by phase (issue 50): each kernel-set method and each
convolution timed with the device synchronised before and after it.

A solve of the array kernel set (``--backend``) on the periodic benchmark surface or the
padded rough sphere (tol 1e-8, cold start), after one untimed solve that compiles the
kernels and plans the transforms. Every method of the kernel set that the iteration calls
(``gap_moments``, ``direction``, ``step_dots``, ``update``, ``add_point_responses``, ...) and
the convolution ``K*p`` are wrapped: the device is synchronised, the method runs, the
device is synchronised again, and the wall time between is the phase's (its launches, its
device work and its host reads). What is left of the solve's wall time is the loop's own
host work between phases. The synchronisations add a wait per phase that the plain solve
does not pay, so the phases' sum exceeds a plain solve's time (printed beside it): the table
is an attribution, not a timing. On numpy (``--backend numpy-array``) it tries the script.

    python benchmarks/bench_gpu_phases.py --size 2048 --bc periodic      # on a GPU machine
    python benchmarks/bench_gpu_phases.py --size 128 --backend numpy-array
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

from _common import E_STAR, rough_load, rough_surface, sphere_problem

from amontons.contact import solve
from amontons.contact.array_backends import array_module
from amontons.contact.array_convolution import ArrayConvolution
from amontons.contact.array_kernels import array_kernel_set

# the kernel-set methods the iteration calls (amontons.contact.cg.kernel_set)
PHASES = (
    "gap_moments",
    "direction",
    "step_dots",
    "update",
    "event_counts",
    "changed_points",
    "add_point_responses",
    "subtract_scaled",
    "relative_change",
    "free_mask",
    "worst_violation",
    "rescale_free",
    "on_host",
)


class PhaseClock:
    """Wall time and calls per phase, each timed between two device synchronisations."""

    def __init__(self, xp):
        runtime = getattr(getattr(xp, "cuda", None), "runtime", None)
        self.sync = runtime.deviceSynchronize if runtime is not None else (lambda: None)
        self.seconds = defaultdict(float)
        self.calls = defaultdict(int)

    def wrap(self, name, fn):
        def timed(*args, **kwargs):
            self.sync()
            start = time.perf_counter()
            out = fn(*args, **kwargs)
            self.sync()
            self.seconds[name] += time.perf_counter() - start
            self.calls[name] += 1
            return out

        return timed

    def reset(self):
        self.seconds.clear()
        self.calls.clear()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--backend", default="cupy", choices=("cupy", "cupy-terms", "numpy-array"))
    ap.add_argument("--size", type=int, default=2048)
    ap.add_argument("--bc", default="periodic", choices=("periodic", "padded"))
    args = ap.parse_args()
    n = args.size
    if args.bc == "periodic":
        h, load = rough_surface(n), rough_load(n)
    else:
        h, load = sphere_problem(n)
    kw = {"heights": h, "spacing": 1.0, "e_star": E_STAR, "load": load, "tol": 1e-8}
    kw |= {"periodic": args.bc == "periodic", "backend": args.backend}
    clock = PhaseClock(array_module(args.backend).xp)

    solve(**kw)  # compiles the kernels, plans the transforms
    clock.sync()
    start = time.perf_counter()
    plain = solve(**kw)
    clock.sync()
    plain_s = time.perf_counter() - start

    ks = array_kernel_set(args.backend)  # the instance the solves use (cached)
    for name in PHASES:
        setattr(ks, name, clock.wrap(name, getattr(ks, name)))
    ArrayConvolution.__call__ = clock.wrap("convolution", ArrayConvolution.__call__)
    clock.reset()
    clock.sync()
    start = time.perf_counter()
    result = solve(**kw)
    clock.sync()
    total = time.perf_counter() - start
    for name in PHASES:
        delattr(ks, name)

    print(f"# {args.backend}, {n}² {args.bc} elastic, {result.iterations} iterations")
    print(f"# plain solve {plain_s * 1e3:.1f} ms ({plain.iterations} iterations); with the")
    print(f"# phases synchronised {total * 1e3:.1f} ms")
    print("| phase | calls | ms | ms per call | ms per iteration | share |")
    print("|---|---|---|---|---|---|")
    timed = 0.0
    for name, seconds in sorted(clock.seconds.items(), key=lambda kv: -kv[1]):
        timed += seconds
        calls = clock.calls[name]
        print(f"| {name} | {calls} | {seconds * 1e3:.1f} | {seconds * 1e3 / calls:.3f} | "
              f"{seconds * 1e3 / result.iterations:.3f} | {seconds / total:.1%} |")  # fmt: skip
    rest = total - timed
    print(f"| the loop's host work between phases | - | {rest * 1e3:.1f} | - | "
          f"{rest * 1e3 / result.iterations:.3f} | {rest / total:.1%} |")  # fmt: skip


if __name__ == "__main__":
    main()
