"""A scene's solver window and grid, in SI units: the one geometry that the simulation
(amontons.simulate.scene) solves on and that the workflow sizes jobs and checks windows with
(docs/simulate.md §2).

A window is ``side_px`` × ``pixel_nm`` where a scene gives ``side_px``, else ``window_factor``
× the Hertz contact diameter at the largest load; its pixel is ``pixel_nm``, coarsened where
such a window would need more than ``max_side_px`` pixels. Standard library only: the
workflow imports it to build its DAG.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

# The least window over a load's Hertz contact diameter that a window clipped to a small AFM
# scan may keep (docs/simulate.md §2, "A scan smaller than the contact"): the virtual PS
# sphere's contacts fit from 1.15-1.25 at 50-300 mN under both models, at the draft and the
# standard pixel (benchmarks/window_margin.py, 2026-11-27); at 25 mN, rougher relative to its
# contact, from 1.4-1.5. A contact that still reaches the clipped window's edge is refused
# by the solver and its load left out (amontons.simulate.solve.solve_on_clipped_window); one
# that does not has the area of an unclipped window, to the pixel.
CONTACT_MARGIN = 1.25


class GeometryError(ValueError):
    """A scene whose window cannot be set (names the scene and the key)."""


class Frame(NamedTuple):
    """What a scene's surface decides, SI: loads (N, increasing), sphere radius (m; None for
    a flat surface) and contact modulus E* (Pa)."""

    loads_n: tuple[float, ...]
    radius_m: float | None
    e_star_pa: float


def sphere_frame(scene: Mapping, record: Mapping) -> Frame:
    """The frame of a scene on a sphere's AFM map: E* and diameter from its sheet ``record``,
    and its loads (the sheet's where the scene says 'measured', else the scene's; mN)."""
    loads = scene["loads"]
    loads_mn = list(record["loads"]) if loads == "measured" else [float(f) for f in loads]
    return Frame(
        loads_n=tuple(f * 1e-3 for f in loads_mn),
        radius_m=float(record["diameter_mm"]) * 0.5e-3,
        e_star_pa=float(record["e_star_gpa"]) * 1e9,
    )


def synthetic_frame(scene: Mapping) -> Frame:
    """The frame of a scene on a synthetic surface, which names E*, loads and (for the sphere
    geometry) the radius itself."""
    synthetic = scene["synthetic"]
    return Frame(
        loads_n=tuple(float(f) * 1e-3 for f in scene["loads"]),
        radius_m=synthetic["radius_mm"] * 1e-3 if scene["geometry"] == "sphere" else None,
        e_star_pa=synthetic["e_star_gpa"] * 1e9,
    )


def hertz_diameter_m(load_n: float, radius_m: float, e_star_pa: float) -> float:
    """Hertz contact diameter 2a = 2·(3FR/4E*)^(1/3), m (amontons.physics.hertz, to the bit)."""
    return 2 * float((3 * load_n * radius_m / (4 * e_star_pa)) ** (1 / 3))


def window_m(name: str, scene: Mapping, frame: Frame) -> float:
    """Window side (m) of scene ``name`` (its config entry): ``side_px`` × pixel, or
    ``window_factor`` × the Hertz contact diameter at the frame's largest load (a flat surface
    needs ``side_px``)."""
    pixel_m = scene["pixel_nm"] * 1e-9
    if scene.get("side_px") is not None:
        return scene["side_px"] * pixel_m
    if frame.radius_m is None:
        raise GeometryError(f"scene {name}: a flat surface needs side_px (no Hertz diameter)")
    largest = hertz_diameter_m(max(frame.loads_n), frame.radius_m, frame.e_star_pa)
    return scene["window_factor"] * largest


def solver_pixel_m(scene: Mapping, window: float) -> float:
    """Solver pixel (m) of a scene whose window is ``window`` (m): ``pixel_nm``, or coarser
    where a window set by ``window_factor`` would need more than ``max_side_px`` pixels (a
    large contact then costs no more than the cap)."""
    pixel_m = scene["pixel_nm"] * 1e-9
    if scene.get("side_px") is not None:
        return pixel_m
    return max(pixel_m, window / scene["max_side_px"])


def side_px(window: float, pixel_m: float) -> int:
    """Solver grid side (px, even) of a window (m) at ``pixel_m`` (m)."""
    n = int(round(window / pixel_m))
    return n + n % 2


def grid_window_m(name: str, scene: Mapping, frame: Frame) -> float:
    """The side (m) of the grid the solver works on: ``side_px`` whole pixels, which may exceed
    :func:`window_m` by up to a pixel's rounding."""
    window = window_m(name, scene, frame)
    pixel = solver_pixel_m(scene, window)
    return side_px(window, pixel) * pixel


class LeftOutLoad(NamedTuple):
    """A load whose window (m) does not fit in the AFM scan about the sphere's apex, or
    (``reason``) whose contact reached the edge of the window the scan clipped."""

    load_n: float
    window_m: float
    reason: str | None = None

    def to_record(self) -> dict:
        """JSON-ready: the load (mN), the window it needs (µm) and, where it was solved on a
        clipped window and its contact reached the edge, that reason."""
        record = {"load_mn": self.load_n * 1e3, "window_um": self.window_m * 1e6}
        if self.reason is not None:
            record["reason"] = self.reason
        return record


class InScan(NamedTuple):
    """A scene's frame cut to the loads an AFM scan holds, the loads left out, the window
    (m) and solver pixel (m) the kept loads are solved on (None, None where none is kept),
    and the window (m) the kept loads would have had where the scan clipped it (None where
    they are solved on their own window)."""

    frame: Frame
    left_out: tuple[LeftOutLoad, ...]
    window_m: float | None
    pixel_m: float | None
    clipped_from_m: float | None = None


def _grid_within(scene: Mapping, limit_m: float) -> tuple[float, float]:
    """The largest grid window (m, an even number of solver pixels) no wider than ``limit_m``,
    and its solver pixel (m)."""
    pixel = solver_pixel_m(scene, limit_m)
    n = int(limit_m / pixel)
    return (n - n % 2) * pixel, pixel


def contact_room_m(frame: Frame, load_n: float) -> float:
    """The least window (m) a load's contact is solved on: :data:`CONTACT_MARGIN` × its
    Hertz contact diameter (docs/simulate.md, "A scan smaller than the contact")."""
    return CONTACT_MARGIN * hertz_diameter_m(load_n, frame.radius_m, frame.e_star_pa)


def frame_in_scan(name: str, scene: Mapping, frame: Frame, scan_window_m: float) -> InScan:
    """The frame cut to the loads a scan holds, and the loads left out (``outside_scan``).

    ``scan_window_m`` is the side (m) of the largest square about the sphere's apex that lies
    inside the AFM scan. A load is kept where the grid window sized on it as the largest load
    fits in that square, or, failing that, where its contact does with the room the solver
    needs (:func:`contact_room_m`); the loads increase, so the ones left out are the largest.
    A scene with a fixed ``side_px`` keeps all its loads or none. The kept loads are solved
    on the frame's own window where the scan holds it, else on the largest grid window the
    scan holds: as much room about the contact as the scan allows; where that is smaller than
    their own window, ``clipped_from_m`` is their own window.
    """
    fixed = scene.get("side_px") is not None
    kept: list[float] = []
    left_out: list[LeftOutLoad] = []
    for load in frame.loads_n:
        window = grid_window_m(name, scene, frame._replace(loads_n=(*kept, load)))
        fits = window <= scan_window_m or (
            not fixed and contact_room_m(frame, load) <= scan_window_m
        )
        if left_out or not fits:
            left_out.append(LeftOutLoad(load, window))
        else:
            kept.append(load)
    cut = frame._replace(loads_n=tuple(kept))
    if not kept:
        return InScan(cut, tuple(left_out), None, None)
    own = grid_window_m(name, scene, cut)
    if not left_out and own <= scan_window_m:
        window = window_m(name, scene, frame)
        return InScan(cut, (), window, solver_pixel_m(scene, window))
    held, pixel = _grid_within(scene, scan_window_m)
    return InScan(cut, tuple(left_out), held, pixel, own if own > scan_window_m else None)
