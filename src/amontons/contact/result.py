"""What a solve returns: :class:`ContactResult` (public) with its :class:`SolveInfo` and
:class:`CoarseLevel`, and :class:`Outcome`, the one internal outcome every route returns and
the public result is built from.

All fields are in SI units: pressures in Pa, lengths in m, forces in N, areas in m².
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import (
    CONVERGED,
    ITERATION_CAP,
    STALLED,
    STATUS_NAMES,
    ContactError,
    ContactInputError,
    ConvergenceError,
    FreeBoundaryError,
    IgnoredOptionWarning,
)
from .laws import ContactHardening, PenetrationHardness

__all__ = [
    "CONVERGED",
    "ITERATION_CAP",
    "STALLED",
    "STATUS_NAMES",
    "CoarseLevel",
    "ContactError",
    "ContactInputError",
    "ContactResult",
    "ConvergenceError",
    "FreeBoundaryError",
    "IgnoredOptionWarning",
    "Outcome",
    "SolveInfo",
    "Tally",
]


@dataclass
class Outcome:
    """What a route (or one Polonsky–Keer solve) hands up: the last iterate and how it ended.

    Arrays on the solver grid: ``pressure`` (Pa), ``gap``, ``elastic_displacement`` (m) and
    ``plastic_displacement`` (m; None for a CG solve, which knows no plasticity);
    ``displacement`` is the rigid-body approach (m). ``iterations``, ``convolutions`` and
    ``resets`` (steepest-descent restarts) are summed over the CG solves behind it,
    ``outer_iterations`` counts plastic updates or active-set rounds (0: none), ``history``
    holds the residual after every CG iteration (dimensionless), ``coarse_levels`` the
    :class:`CoarseLevel` solves of a coarse-to-fine start. ``status`` is 0 (converged),
    1 (iteration cap) or 2 (stalled), with ``message`` saying why; ``info`` holds a CG
    solve's counters for benchmarks (how ``u`` followed each step, forward-only transforms).
    """

    pressure: np.ndarray
    gap: np.ndarray
    elastic_displacement: np.ndarray
    plastic_displacement: np.ndarray | None
    displacement: float
    iterations: int
    residual: float
    history: np.ndarray
    convolutions: float
    status: int = CONVERGED
    message: str = ""
    outer_iterations: int = 0
    resets: int = 0
    coarse_levels: tuple = ()
    info: dict = field(default_factory=dict)

    @property
    def converged(self) -> bool:
        """True when ``status == 0``."""
        return self.status == CONVERGED


@dataclass
class Tally:
    """Work summed over the conjugate-gradient solves of one step (iterations, convolutions,
    steepest-descent restarts and the residual history of each :class:`Outcome` added)."""

    iterations: int = 0
    convolutions: float = 0.0
    resets: int = 0
    history: list = field(default_factory=list)

    def add(self, out: Outcome) -> None:
        """Add the work of one CG solve."""
        self.iterations += out.iterations
        self.convolutions += out.convolutions
        self.resets += out.resets
        self.history.extend(out.history)


@dataclass(frozen=True)
class CoarseLevel:
    """One coarse grid of a coarse-to-fine start (solved loosely, to ``COARSE_TOL``).

    Attributes
    ----------
    shape : (int, int)
        Grid shape of the level, pixels.
    iterations : int
        Conjugate-gradient iterations on that level.
    convolutions : float
        Convolutions performed on that level, in FFT pairs (as :class:`SolveInfo`).
    """

    shape: tuple[int, int]
    iterations: int
    convolutions: float


@dataclass(frozen=True)
class SolveInfo:
    """Diagnostics of one solve; the same fields on every route (0/None where not applicable).

    Attributes
    ----------
    route : {"elastic", "winkler", "bounded", "appendix"}
        How the solve was done: ``"elastic"`` (no plasticity law; one Polonsky–Keer solve),
        ``"winkler"`` (contact hardening with local increments, solved exactly as an elastic
        half-space plus a Winkler layer), ``"bounded"`` (penetration hardness with local
        increments: one bounded Polonsky–Keer solve under the load or approach, then the
        plastic update) or ``"appendix"`` (the appendix's iterative scheme: bounded solve,
        plastic increment, repeat, with a root find on the approach under load control).
    convolutions : float
        Convolutions on the finest grid, in FFT pairs: a forward transform whose inverse the
        solver skipped counts 0.5 (:mod:`amontons.contact.cg`). Plastic routes under load
        control: those of the final approach only (the root find's trial approaches are not
        counted).
    steepest_descent_resets : int
        Conjugate-gradient restarts from steepest descent (see :mod:`amontons.contact.cg`),
        counted like ``convolutions``.
    outer_iterations : int
        Outer rounds of the returned state: active-set rounds (``"winkler"``), rounds of
        bounded solve and plastic update at the final approach (``"appendix"``; 0 when the
        elastic solution never reaches the hardness), 1 for ``"bounded"`` (its one solve
        and update); 0 for an elastic solve.
    coarse_levels : tuple of CoarseLevel
        Coarse grids solved for a coarse-to-fine start, coarsest first; empty when none ran.
    plasticity : PenetrationHardness or ContactHardening or None
        The plasticity law, None for an elastic solve.
    backend : {"pyfftw", "numpy", "cupy", "numpy-array", "cupy-array", "cupy-terms"}
        Backend used: an FFT backend of the CPU solver, or the array kernel set's
        namespace (``"cupy"`` on the GPU).
    threads : int
        Threads of the transforms and the kernels.
    planner_effort : str
        FFTW planner effort of the convolution plans (unused by the numpy backend).
    tol : float
        Requested tolerance (dimensionless).
    max_iter : int
        Conjugate-gradient iteration cap per solve on the finest grid.
    max_outer : int or None
        Cap on ``outer_iterations``; None for an elastic solve and the ``"bounded"`` route.
    wall_time_s : float
        Wall time of the solve, s.
    iteration : {"polonsky-keer", "preconditioned"}
        The CG iteration that solved it (docs/models.md §2.2); the appendix route always
        runs Polonsky and Keer's.
    """

    route: str
    convolutions: float
    steepest_descent_resets: int
    outer_iterations: int
    coarse_levels: tuple[CoarseLevel, ...]
    plasticity: PenetrationHardness | ContactHardening | None
    backend: str
    threads: int
    planner_effort: str
    tol: float
    max_iter: int
    max_outer: int | None
    wall_time_s: float
    iteration: str = "polonsky-keer"


@dataclass(frozen=True, eq=False)
class ContactResult:
    """Solution of one contact problem, converged or (with ``raise_on_failure=False``) not.

    Sign convention: elastic displacement ``u`` is positive into the elastic substrate, the
    rigid indenter heights ``h`` are larger where the indenter is closer to the substrate and
    ``displacement`` ``d`` is the rigid-body approach; the gap is ``g = u - h - d``.

    Equality is identity (``r == r`` is True, two results never compare equal): the fields
    are arrays; compare them with :func:`numpy.array_equal` if needed.

    Status codes (``status``; as in :class:`scipy.optimize.OptimizeResult`):

    * ``0`` converged: every convergence criterion is below ``tol``;
    * ``1`` iteration cap reached: ``max_iter`` conjugate-gradient iterations, or
      ``max_outer`` plastic updates / active-set rounds, without convergence;
    * ``2`` stalled: stopped for another reason, e.g. the residual stopped falling (its best
      value did not halve in 200 iterations, :class:`amontons.contact.stall.StallMonitor`), a
      periodic displacement-controlled solve reached full contact (the mean pressure is
      then undetermined) or the load control of a plastic solve found no approach that
      carries the load.

    A result with ``status != 0`` is only returned when ``raise_on_failure=False``; it holds
    the last iterate (finite; not checked against the window edge), and ``message`` says
    why the solve stopped.

    Attributes
    ----------
    pressure : ndarray
        Contact pressure, Pa (>= 0).
    gap : ndarray
        Gap between the deformed substrate and the indenter, m (>= 0 up to the tolerance).
    elastic_displacement : ndarray
        Elastic surface displacement u, m, positive into the substrate. Periodic solves
        carry the rigid (q = 0) mode in ``displacement``, so ``u`` has zero mean there.
    plastic_displacement : ndarray
        Plastic displacement of the indenter, m (zeros for an elastic solve).
    contact : ndarray of bool
        Contact mask, ``pressure > 0``.
    load : float
        Total normal force, N.
    displacement : float
        Rigid-body approach d, m.
    spacing : float
        Grid spacing, m.
    iterations : int
        Conjugate-gradient iterations on the finest grid (summed over the solves of a
        plastic step; under load control, those of the final approach).
    residual : float
        Final convergence measure (dimensionless, see :mod:`amontons.contact.cg`).
    residual_history : ndarray
        Convergence measure after every iteration.
    success : bool
        True when the solve converged (``status == 0``).
    status : int
        0 converged, 1 iteration cap reached, 2 stalled (see above).
    message : str
        Why the solve stopped, with the iterations and the residual.
    periodic : bool
        Whether the problem was solved with periodic boundary conditions.
    heights : ndarray, optional
        The undeformed indenter heights h that were solved for, m.
    info : SolveInfo, optional
        Diagnostics: route, convolutions, coarse levels, backend, timing (see
        :class:`SolveInfo`).
    """

    pressure: np.ndarray
    gap: np.ndarray
    elastic_displacement: np.ndarray
    plastic_displacement: np.ndarray
    contact: np.ndarray
    load: float
    displacement: float
    spacing: float
    iterations: int
    residual: float
    residual_history: np.ndarray
    success: bool
    status: int
    message: str
    periodic: bool
    heights: np.ndarray | None = None
    info: SolveInfo | None = None

    def __post_init__(self):
        if self.status not in STATUS_NAMES:
            raise ValueError(f"status must be one of {sorted(STATUS_NAMES)}, got {self.status!r}")
        if bool(self.success) != (self.status == CONVERGED):
            raise ValueError(f"success={self.success!r} contradicts status={self.status!r}")

    @property
    def converged(self) -> bool:
        """Alias of :attr:`success` (read-only), kept for existing callers."""
        return self.success

    @property
    def deformed_heights(self) -> np.ndarray:
        """Indenter topography after plastic flow, h + h_pl, m (what an AFM scan after
        unloading sees, up to the sign convention of the heights)."""
        if self.heights is None:
            raise AttributeError("this result does not carry the heights it was solved for")
        return self.heights + self.plastic_displacement

    @property
    def area(self) -> float:
        """Real contact area, m²: number of contact pixels times spacing²."""
        return float(np.count_nonzero(self.contact)) * self.spacing**2

    @property
    def contact_fraction(self) -> float:
        """Fraction of the window in contact (dimensionless)."""
        return float(np.count_nonzero(self.contact)) / self.contact.size

    @property
    def mean_pressure(self) -> float:
        """Load divided by the real contact area, Pa (nan without contact)."""
        a = self.area
        return self.load / a if a > 0 else float("nan")
