"""Validation of the inputs of :func:`~amontons.contact.solve` and
:func:`~amontons.contact.solve_load_series`.

Every check raises :class:`~amontons.contact.ContactInputError` naming the value, its unit
and what was expected, and returns the value in the form the solver uses.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from .fft import resolve_backend, resolve_planner_effort
from .plasticity import (
    ContactHardening,
    PenetrationHardness,
    check_method,
    default_max_outer,
    resolve_route,
)
from .result import ContactInputError


@dataclass(frozen=True)
class SolveOptions:
    """Validated options shared by every load step of a solve (SI units).

    ``max_iter`` is resolved from the grid; ``route`` is ``"elastic"`` without a law, else
    the plastic route; ``max_outer`` is resolved for plastic solves and None for elastic ones
    and the ``"bounded"`` route (no outer loop). ``bounded_load_sweep``: the kernel set of
    bounded load control, the fused sweep (True, the only one :func:`solve_options` gives)
    or the numpy step with a convolution per step (False: the reference the tests select
    with :func:`dataclasses.replace`).
    """

    periodic: bool
    tol: float
    max_iter: int
    threads: int
    backend: str
    planner_effort: str
    law: PenetrationHardness | ContactHardening | None
    route: str
    max_outer: int | None
    raise_on_failure: bool
    bounded_load_sweep: bool = True


def solve_options(
    shape,
    *,
    periodic,
    tol,
    max_iter,
    threads,
    backend,
    planner_effort,
    plasticity,
    method,
    max_outer,
    raise_on_failure,
) -> SolveOptions:
    """Validate the options of a solve on a grid of ``shape``."""
    tol = check_positive("tol", tol, "(dimensionless)")
    max_iter = default_max_iter(shape) if max_iter is None else check_count("max_iter", max_iter)
    threads = check_threads(threads)
    backend = resolve_backend(backend)
    planner_effort = resolve_planner_effort(planner_effort)
    check_method(method)
    law = None if plasticity is None else check_law(plasticity)
    route = "elastic" if law is None else resolve_route(law, method)
    if max_outer is not None:
        max_outer = check_count("max_outer", max_outer)
    if law is None or route == "bounded":
        max_outer = None  # no outer loop (a given value is ignored, with a warning)
    elif max_outer is None:
        max_outer = default_max_outer(route)
    return SolveOptions(
        periodic=bool(periodic),
        tol=tol,
        max_iter=max_iter,
        threads=threads,
        backend=backend,
        planner_effort=planner_effort,
        law=law,
        route=route,
        max_outer=max_outer,
        raise_on_failure=bool(raise_on_failure),
    )


def default_max_iter(shape) -> int:
    """Default conjugate-gradient iteration cap on an ``(n0, n1)`` grid."""
    # PK needs O(n) iterations on an n x n grid for rough surfaces (~1200 at 2048²);
    # generous, so hitting the cap means something is wrong, not just slow.
    return 1000 + 4 * (shape[0] + shape[1])


def check_positive(name, value, unit) -> float:
    """``value`` as a finite positive float."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ContactInputError(f"{name} must be a number in {unit}, got {value!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise ContactInputError(f"{name} must be a finite positive number in {unit}, got {v!r}")
    return v


def check_count(name, value) -> int:
    """``value`` as a positive int."""
    try:
        ok = int(value) == value and value >= 1
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ContactInputError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity; all cores where the platform has
    no affinity)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # macOS, Windows
        return os.cpu_count() or 1


def check_threads(threads) -> int:
    """Threads of a solve as an int >= 1; None means every core this process may use."""
    if threads is None:
        return available_cores()
    try:
        ok = int(threads) == threads and threads >= 1
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ContactInputError(f"threads must be an integer >= 1 or None, got {threads!r}")
    return int(threads)


def check_heights(heights) -> np.ndarray:
    """Indenter heights (m) as a finite, C-contiguous float64 2-D array of at least 2x2."""
    h = np.asarray(heights)
    if h.ndim != 2:
        raise ContactInputError(f"heights must be a 2-D array (m), got an array of shape {h.shape}")
    if min(h.shape) < 2:
        raise ContactInputError(f"heights must be at least 2x2 pixels, got shape {h.shape}")
    if not np.issubdtype(h.dtype, np.number) or np.iscomplexobj(h):
        raise ContactInputError(f"heights must be real numbers (m), got dtype {h.dtype}")
    h = np.ascontiguousarray(h, dtype=np.float64)
    bad = ~np.isfinite(h)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise ContactInputError(
            f"heights contain {int(bad.sum())} non-finite value(s) (NaN or inf), first at "
            f"pixel ({i}, {j}); expected finite heights in m"
        )
    return h


def check_control(load, displacement) -> tuple[float | None, float | None]:
    """Exactly one of load (N, > 0) and displacement (m, finite), as floats."""
    if (load is None) == (displacement is None):
        raise ContactInputError(
            "give exactly one of load (N) and displacement (m); got "
            f"load={load!r}, displacement={displacement!r}"
        )
    if load is not None:
        return check_positive("load", load, "N"), None
    try:
        displacement = float(displacement)
    except (TypeError, ValueError):
        raise ContactInputError(
            f"displacement must be a number in m, got {displacement!r}"
        ) from None
    if not math.isfinite(displacement):
        raise ContactInputError(f"displacement must be finite (m), got {displacement!r}")
    return None, displacement


def check_loads(loads) -> np.ndarray:
    """Loads of a series (N) as a non-empty, finite, positive, strictly increasing array."""
    arr = np.asarray(loads, dtype=float)
    if arr.ndim != 1 or arr.size == 0:
        raise ContactInputError(f"loads must be a non-empty 1-D sequence (N), got {loads!r}")
    if not np.isfinite(arr).all() or (arr <= 0).any():
        raise ContactInputError(f"loads must be finite and positive (N), got {arr.tolist()}")
    if arr.size > 1 and (np.diff(arr) <= 0).any():
        raise ContactInputError(f"loads must be strictly increasing (N), got {arr.tolist()}")
    return arr


def check_warm_start(warm_start, shape) -> np.ndarray:
    """A starting pressure (Pa) of the grid's shape, finite and >= 0."""
    w = np.asarray(warm_start, dtype=np.float64)
    if w.shape != shape:
        raise ContactInputError(f"warm_start must have the shape of heights {shape}, got {w.shape}")
    if not np.isfinite(w).all():
        raise ContactInputError("warm_start contains NaN or inf; expected a pressure in Pa")
    if (w < 0).any():
        raise ContactInputError(f"warm_start must be a pressure >= 0 (Pa), min is {w.min():.3e}")
    return w


def check_law(law):
    """A plasticity law: PenetrationHardness or ContactHardening."""
    if not isinstance(law, PenetrationHardness | ContactHardening):
        raise ContactInputError(
            f"plasticity must be PenetrationHardness(p_y) or ContactHardening(k), got {law!r}"
        )
    return law


def check_plastic_history(plastic, shape) -> np.ndarray:
    """Plastic displacement left by earlier loading (m; zeros when None)."""
    if plastic is None:
        return np.zeros(shape)
    h_pl = np.asarray(plastic, dtype=np.float64)
    if h_pl.shape != shape:
        raise ContactInputError(
            f"plastic_displacement must have the shape of heights {shape}, got {h_pl.shape}"
        )
    if not np.isfinite(h_pl).all():
        raise ContactInputError("plastic_displacement contains NaN or inf; expected metres")
    return h_pl
