"""The native thread pools a solve runs on, held for the duration of the call.

A solve's own threads are its transforms' (one-thread FFTW plans on slabs, run by a pool of
Python threads: :mod:`.fft`) and the numba kernels' (OpenMP). The kernels set their own
count per call (:func:`numba.set_num_threads`, :func:`.kernels.kernel_threads`). BLAS
threads (OpenBLAS) the solver does not want: its numpy calls are level 1, and BLAS threads
spin against the solver's own (benchmarks/README.md, "Speed as a user gets it"). So, during
a call, every BLAS pool runs one thread and every OpenMP pool the solve's ``threads`` (a
pool held to one thread, as it was until 2026-11-26, ran FFTW's threaded plans of that time
on one core: benchmarks/README.md, "A second core"); the caller's limits come back after
it, also on an exception. (An OpenBLAS built on OpenMP and sharing the kernels' libgomp
would take the shared limit back to one; tests/contact/test_thread_pools.py fails in such
an environment.)
"""

from __future__ import annotations

from threadpoolctl import threadpool_limits


def solve_pools(threads: int) -> threadpool_limits:
    """Context: BLAS pools on one thread, OpenMP pools on ``threads`` (an int >= 1, as
    :func:`amontons.contact.options.check_threads` returns it)."""
    return threadpool_limits(limits={"blas": 1, "openmp": int(threads)})
