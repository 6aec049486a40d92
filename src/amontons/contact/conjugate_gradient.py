"""The CG iteration a route runs, chosen by its options: Polonsky and Keer's
(:func:`.cg.polonsky_keer`) or the preconditioned bound-constrained one
(:func:`.preconditioned.preconditioned_cg`); docs/models.md §2.2."""

from __future__ import annotations

from .cg import polonsky_keer
from .options import CGOptions
from .preconditioned import preconditioned_cg


def conjugate_gradient(operator, heights, options: CGOptions, **problem):
    """Solve with the iteration ``options.iteration`` names; arguments and outcome as
    :func:`.cg.polonsky_keer`."""
    if options.iteration == "preconditioned":
        return preconditioned_cg(operator, heights, options, **problem)
    return polonsky_keer(operator, heights, options, **problem)
