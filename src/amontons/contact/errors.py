"""Status codes, exceptions and warnings of the contact solver (the floor everything stands on)."""

from __future__ import annotations

import numpy as np

# Status codes of a solve (ContactResult.status, ConvergenceError.status).
CONVERGED = 0  # every convergence criterion below tol
ITERATION_CAP = 1  # stopped at max_iter (CG) or max_outer (plastic updates, active-set rounds)
STALLED = 2  # stopped for another reason: residual stalled, singular problem, failed root find

STATUS_NAMES = {CONVERGED: "converged", ITERATION_CAP: "iteration cap reached", STALLED: "stalled"}


class ContactError(Exception):
    """Base class of every error raised by :mod:`amontons.contact`."""


class ContactInputError(ContactError, ValueError):
    """An input value is invalid (NaN heights, non-positive load, wrong shape, ...)."""


class ConvergenceError(ContactError, RuntimeError):
    """A solve did not converge (raised unless ``raise_on_failure=False``).

    Attributes
    ----------
    iterations : int
        Conjugate-gradient iterations performed.
    residual : float
        Last value of the convergence measure (dimensionless).
    tol : float
        Requested tolerance.
    residual_history : numpy.ndarray
        Convergence measure after every iteration.
    status : int
        The status a returned result would carry: 1 (iteration cap reached) or 2 (stalled
        or other failure; see :class:`ContactResult`).
    """

    def __init__(
        self,
        message: str,
        *,
        iterations: int,
        residual: float,
        tol: float,
        residual_history: np.ndarray,
        status: int = STALLED,
    ):
        super().__init__(message)
        self.iterations = iterations
        self.residual = residual
        self.tol = tol
        self.residual_history = residual_history
        self.status = status


class BackendUnavailableError(ContactError, RuntimeError):
    """A solver backend was asked for that this machine cannot run (``backend="cupy"``
    without CuPy or without a CUDA device); the message names the backend and how to
    install it."""


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


class IgnoredOptionWarning(UserWarning):
    """An option was given that has no effect on this solve and is ignored.

    Issued (``warnings.warn``) by :func:`~amontons.contact.solve` and
    :func:`~amontons.contact.solve_load_series`, once per call; the message names the option
    and why it has no effect. Options that cannot be honoured at all raise
    :class:`ContactInputError` instead.
    """
