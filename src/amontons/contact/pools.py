"""The native thread pools a solve runs on, held for the duration of the call.

A solve's own threads are FFTW's and the numba kernels'. pyfftw runs FFTW's on OpenMP (a
vendored libgomp), and FFTW spreads each of a threaded plan's loops with an OpenMP
``parallel for`` that takes the pool's own limit, not the plan's thread count: a pool held
to one thread runs a two-thread plan on one core. The kernels set their own count per call
(:func:`numba.set_num_threads`, :func:`.kernels.kernel_threads`), whatever the pool's limit.
BLAS threads (OpenBLAS) the solver does not want: its numpy calls are level 1, and BLAS
threads spin against the solver's own (benchmarks/README.md, "Speed as a user gets it").
So, during a call, every BLAS pool runs one thread and every OpenMP pool the solve's
``threads``; the caller's limits come back after it, also on an exception. (An OpenBLAS
built on OpenMP and sharing FFTW's libgomp would take the shared limit back to one;
tests/contact/test_thread_pools.py fails in such an environment.)
"""

from __future__ import annotations

from threadpoolctl import threadpool_limits


def solve_pools(threads: int) -> threadpool_limits:
    """Context: BLAS pools on one thread, OpenMP pools on ``threads`` (an int >= 1, as
    :func:`amontons.contact.options.check_threads` returns it)."""
    return threadpool_limits(limits={"blas": 1, "openmp": int(threads)})
