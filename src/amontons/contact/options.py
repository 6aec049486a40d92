"""The options of a solve, validated once into one frozen :class:`SolveOptions` that is
passed down to every floor, and the validation of a solve's inputs.

Every check raises :class:`~amontons.contact.ContactInputError` naming the value, its unit
and what was expected, and returns the value in the form the solver uses. The option values
live here too: FFT backends and planner efforts (the operators plan with them), plastic
routes (the route table of :mod:`.routes` runs them) and the outer-loop caps.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

# The numba kernels (.kernels) run on OpenMP (the libgomp pyfftw's wheels vendor). libgomp's
# default lets idle workers spin after each parallel region; on a 2-core machine those
# spinning threads take the cores from the next region and from the transforms' threads
# (benchmarks/README.md, "A second core"). PASSIVE makes idle workers sleep. libgomp reads
# it when it is loaded, so it is set before pyfftw is imported; a value the user has set is
# kept.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numpy as np  # noqa: E402

from .array_backends import ARRAY_BACKENDS, array_module  # noqa: E402
from .errors import ContactInputError  # noqa: E402
from .laws import (  # noqa: E402
    PLASTICITY_LAWS,
    ContactHardening,
    PenetrationHardness,
    check_law,
)

try:  # pyfftw is optional: numpy.fft is the fallback
    import pyfftw

    HAVE_PYFFTW = True
except ImportError:  # pragma: no cover - depends on the environment
    pyfftw = None
    HAVE_PYFFTW = False

BACKENDS = ("pyfftw", "numpy")

# FFTW planner flags, cheapest first.
PLANNER_EFFORTS = ("FFTW_ESTIMATE", "FFTW_MEASURE", "FFTW_PATIENT", "FFTW_EXHAUSTIVE")
# The planner effort of a solve when none is given, on any number of threads: measured plans
# (kept on disk, so reproducible) are faster than FFTW_ESTIMATE's and, unlike them, use a
# second thread (benchmarks/README.md, "FFTW planner effort", "A second core").
DEFAULT_PLANNER_EFFORT = "FFTW_MEASURE"


def resolve_backend(backend: str | None, *, arrays: bool = False) -> str:
    """Return the backend name to use: ``"pyfftw"`` if available, else ``"numpy"``.

    With ``arrays`` (a solve's backend) the names of the array kernel set are accepted too
    (:data:`.array_backends.ARRAY_BACKENDS`: ``"cupy"``, ``"numpy-array"`` for tests,
    ``"cupy-array"`` and ``"cupy-terms"`` for benchmarks); the CuPy ones are checked to be
    runnable here.

    Raises
    ------
    ContactInputError
        (a ValueError) For an unknown name, or ``"pyfftw"`` requested but not importable.
    BackendUnavailableError
        ``"cupy"``, ``"cupy-array"`` or ``"cupy-terms"`` without CuPy or a CUDA device.
    """
    if backend is None:
        return "pyfftw" if HAVE_PYFFTW else "numpy"
    if arrays and backend in ARRAY_BACKENDS:
        array_module(backend)  # raises, naming the backend and how to install it
        return backend
    if backend not in BACKENDS:
        allowed = BACKENDS + ARRAY_BACKENDS[:1] if arrays else BACKENDS
        raise ContactInputError(f"unknown backend {backend!r}; expected one of {allowed} or None")
    if backend == "pyfftw" and not HAVE_PYFFTW:
        raise ContactInputError("FFT backend 'pyfftw' requested but pyfftw is not importable")
    return backend


def check_planner_effort(planner_effort: str) -> str:
    """Return ``planner_effort`` if it is one of :data:`PLANNER_EFFORTS`.

    Raises
    ------
    ContactInputError
        (a ValueError) Naming the allowed values.
    """
    if not isinstance(planner_effort, str) or planner_effort not in PLANNER_EFFORTS:
        raise ContactInputError(
            f"planner_effort must be one of {PLANNER_EFFORTS}, got {planner_effort!r}"
        )
    return planner_effort


def resolve_planner_effort(planner_effort: str | None) -> str:
    """The planner effort of a solve: ``planner_effort`` if given (checked), else
    :data:`DEFAULT_PLANNER_EFFORT` (numpy.fft does not plan; its operators ignore it)."""
    if planner_effort is not None:
        return check_planner_effort(planner_effort)
    return DEFAULT_PLANNER_EFFORT


METHODS = ("winkler", "bounded", "appendix")
# The routes that solve one law exactly (its ``exact_route``), as the errors describe them.
EXACT_ROUTES = {
    "winkler": "the exact elastic-plus-Winkler route",
    "bounded": "one bounded CG under the force constraint",
}
_EXACT_ROUTE_LAWS = {law.exact_route: law.__name__ for law in PLASTICITY_LAWS}
# The CG iterations a route can run (docs/models.md §2.2): Polonsky and Keer's, and the
# preconditioned bound-constrained CG of .preconditioned.
ITERATIONS = ("polonsky-keer", "preconditioned")
# the iteration a solve runs unless asked otherwise
DEFAULT_ITERATION = ITERATIONS[0]

# Default caps on the outer loop (max_outer=None): plastic updates per approach of the
# appendix scheme, and active-set rounds of the Winkler route.
MAX_PLASTIC_UPDATES = 200
MAX_ACTIVE_SET_ROUNDS = 50


def check_method(method) -> None:
    """Raise ContactInputError unless ``method`` is None or one of :data:`METHODS`."""
    if method is not None and (not isinstance(method, str) or method not in METHODS):
        raise ContactInputError(
            f"method must be one of {METHODS} (or None: the law's default), got {method!r}"
        )


def resolve_route(law, method) -> str:
    """The route of a plastic solve, ``"winkler"``, ``"bounded"`` or ``"appendix"``.

    ``method=None`` picks the law's default: ``"winkler"`` for contact hardening with local
    increments (exact), ``"bounded"`` for penetration hardness with local increments (one
    bounded CG, exact), ``"appendix"`` otherwise (the only route there).

    Raises
    ------
    ContactInputError
        An unknown method; ``"winkler"`` or ``"bounded"`` for a law it cannot solve;
        ``"appendix"`` for contact hardening with ``alpha = 1``.
    """
    check_method(method)
    exact = law.exact_route if law.increment == "local" else None
    if method is None:
        method = exact or "appendix"
    if method in EXACT_ROUTES and method != exact:
        raise ContactInputError(
            f"method={method!r} ({EXACT_ROUTES[method]}) only solves "
            f"{_EXACT_ROUTE_LAWS[method]} with local increments, not {law!r}; use "
            "method='appendix' or None"
        )
    if method == "appendix" and law.appendix_needs_relaxation and law.alpha == 1:
        raise ContactInputError(
            "the iterative contact-hardening scheme needs over-relaxation alpha < 1; got 1"
        )
    return method


def default_max_outer(route: str) -> int | None:
    """Cap on the outer loop of a route when ``max_outer`` is None (None: the route has no
    outer loop)."""
    if route == "bounded":
        return None
    return MAX_ACTIVE_SET_ROUNDS if route == "winkler" else MAX_PLASTIC_UPDATES


@dataclass(frozen=True)
class CGOptions:
    """What one Polonsky–Keer solve (:func:`.cg.polonsky_keer`) is run with, beside the
    problem: the residual ``tol`` (dimensionless), the iteration cap ``max_iter``, a fresh
    ``u = K*p`` at least every ``refresh`` iterations, whether a solve that stops unconverged
    raises (``raise_on_failure``; else its outcome carries the status), the kernels'
    ``threads`` (None: the operator's threads, else 1), the kernel set of bounded
    load control (``bounded_load_sweep``, as :class:`SolveOptions`'s) and the kernel set
    of the loop (``array_module``: None for the fused numba kernels, else the array
    kernels on that namespace, a name of :data:`.array_backends.ARRAY_BACKENDS`; the
    operator must then be the namespace's, :class:`.array_convolution.ArrayConvolution`)."""

    tol: float = 1e-8
    max_iter: int = 1000
    refresh: int = 100
    raise_on_failure: bool = True
    threads: int | None = None
    bounded_load_sweep: bool = True
    array_module: str | None = None
    iteration: str = DEFAULT_ITERATION


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
    iteration: str = DEFAULT_ITERATION

    @property
    def cg(self) -> CGOptions:
        """The options of every CG solve a route runs for this solve: its ``tol``,
        ``max_iter`` and ``bounded_load_sweep``; never raising (a route returns the
        outcome, converged or not, and :mod:`.api` decides), on the operator's threads."""
        return CGOptions(
            tol=self.tol,
            max_iter=self.max_iter,
            raise_on_failure=False,
            bounded_load_sweep=self.bounded_load_sweep,
            array_module=self.backend if self.backend in ARRAY_BACKENDS else None,
            iteration=self.iteration,
        )


@dataclass(frozen=True)
class LoadStep:
    """What one solve is asked, beside the options: exactly one of ``load`` (N) and
    ``displacement`` (m), a starting pressure ``warm_start`` (Pa) or None, the plastic
    displacement left by earlier loading ``plastic_prev`` (m; None for elastic solves), and
    whether an elastic solve starts coarse-to-fine. Validated by :func:`.api.solve`."""

    load: float | None
    displacement: float | None
    warm_start: np.ndarray | None = None
    plastic_prev: np.ndarray | None = None
    coarse_to_fine: bool = False


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
    iteration=DEFAULT_ITERATION,
) -> SolveOptions:
    """Validate the options of a solve on a grid of ``shape``."""
    tol = check_positive("tol", tol, "(dimensionless)")
    max_iter = default_max_iter(shape) if max_iter is None else check_count("max_iter", max_iter)
    threads = check_threads(threads)
    backend = resolve_backend(backend, arrays=True)
    planner_effort = resolve_planner_effort(planner_effort)
    check_method(method)
    iteration = check_iteration(iteration, backend)
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
        iteration=iteration,
    )


def check_iteration(iteration, backend) -> str:
    """The CG iteration of a solve, one of :data:`ITERATIONS`; the preconditioned one runs
    on the CPU convolutions only (its preconditioner is their inverse spectrum)."""
    if iteration not in ITERATIONS:
        raise ContactInputError(
            f"iteration must be one of {', '.join(map(repr, ITERATIONS))}, got {iteration!r}"
        )
    if iteration == "preconditioned" and backend in ARRAY_BACKENDS:
        raise ContactInputError(
            f"iteration='preconditioned' runs on the CPU backends, not backend={backend!r}; "
            "use iteration='polonsky-keer' there"
        )
    return iteration


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
