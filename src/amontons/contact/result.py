"""Result object and exceptions of the contact solver.

All fields are in SI units: pressures in Pa, lengths in m, forces in N, areas in m².
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class ContactError(Exception):
    """Base class of every error raised by :mod:`amontons.contact`."""


class ContactInputError(ContactError, ValueError):
    """An input value is invalid (NaN heights, non-positive load, wrong shape, ...)."""


class ConvergenceError(ContactError, RuntimeError):
    """The constrained conjugate gradient did not converge within ``max_iter`` iterations.

    Attributes
    ----------
    iterations : int
        Iterations performed.
    residual : float
        Last value of the convergence measure (dimensionless).
    tol : float
        Requested tolerance.
    residual_history : numpy.ndarray
        Convergence measure after every iteration.
    """

    def __init__(
        self,
        message: str,
        *,
        iterations: int,
        residual: float,
        tol: float,
        residual_history: np.ndarray,
    ):
        super().__init__(message)
        self.iterations = iterations
        self.residual = residual
        self.tol = tol
        self.residual_history = residual_history


class FreeBoundaryError(ContactError, RuntimeError):
    """Non-periodic solve: pressure on the outermost ring of the window.

    The Hockney-padded solution is only the solution of the real (infinite half-space)
    problem if the pressure vanishes outside the window; contact reaching the window edge
    means the window is too small for the load.

    Attributes
    ----------
    edge_pixels : int
        Number of pixels on the outermost ring that carry pressure.
    edge_force : float
        Force carried by those pixels, N.
    """

    def __init__(self, message: str, *, edge_pixels: int, edge_force: float):
        super().__init__(message)
        self.edge_pixels = edge_pixels
        self.edge_force = edge_force


@dataclass(frozen=True)
class ContactResult:
    """Converged solution of one contact problem.

    Sign convention: elastic displacement ``u`` is positive into the elastic substrate, the
    rigid indenter heights ``h`` are larger where the indenter is closer to the substrate and
    ``displacement`` ``d`` is the rigid-body approach; the gap is ``g = u - h - d``.

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
        Conjugate-gradient iterations (on the finest grid).
    residual : float
        Final convergence measure (dimensionless, see :mod:`amontons.contact.cg`).
    residual_history : ndarray
        Convergence measure after every iteration.
    converged : bool
        True when ``residual < tol``.
    periodic : bool
        Whether the problem was solved with periodic boundary conditions.
    heights : ndarray, optional
        The undeformed indenter heights h that were solved for, m.
    info : dict
        Further diagnostics (convolutions performed, coarse levels, ...).
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
    converged: bool
    periodic: bool
    heights: np.ndarray | None = field(default=None, compare=False)
    info: dict = field(default_factory=dict, compare=False)

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
