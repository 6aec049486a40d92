"""The rigid indenter of a scene on its solver grid (docs/simulate.md, "Surface to solver grid").

A sphere's levelled ``afm_before`` map (the topography step's sphere fit and scan-line
alignment) is cut to the scene's window about the fitted apex and brought to the solver pixel
by area averaging: each solver pixel holds the mean height of the AFM area it covers, with
AFM pixels cut by its edge counted by their covered fraction. Point sampling would alias the
roughness finer than the solver pixel into it; averaging keeps the mean height of every
patch the solver sees and removes what it cannot carry.

Sign convention (appendix B.2.2): the sphere is the rigid indenter, heights larger = closer to
the glass (an AFM scan of the apex, apex up, as is); the glass roughness is neglected.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from amontons.config.geometry import LeftOutLoad
from amontons.contact.surfaces import self_affine, sphere
from amontons.io.fields import read_levelled_map
from amontons.io.heightmap import TopographyError, read_height_map
from amontons.io.layout import RawDataError
from amontons.measure.topography import FitParameters, level_sphere, sphere_cap, square_pixels
from amontons.physics.roughness import roughness_statistics
from amontons.simulate.scene import Scene, SceneError, scene_in_scan

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Indenter:
    """Heights (m) of a scene's rigid indenter on its solver grid of ``spacing_m``; the
    window's centre in the AFM frame (m from the scan centre, (row, col)); the roughness
    statistics of the map at its own pixel and of the indenter at the solver pixel."""

    heights: np.ndarray
    spacing_m: float
    centre_in_scan_m: tuple[float, float]
    afm_statistics: dict
    solver_statistics: dict


def overlap_weights(n_in: int, pixel_in: float, first_edge: float, n_out: int, pixel_out):
    """(n_out × n_in) weights averaging an axis of ``n_in`` pixels of ``pixel_in`` (m; pixel
    i spans [i, i+1)·pixel_in) onto ``n_out`` pixels of ``pixel_out`` starting at
    ``first_edge`` (m): each row holds the fraction of the output pixel each input covers."""
    edges_out = first_edge + np.arange(n_out + 1) * pixel_out
    lo = np.maximum(edges_out[:-1, None], np.arange(n_in)[None, :] * pixel_in)
    hi = np.minimum(edges_out[1:, None], (np.arange(n_in)[None, :] + 1) * pixel_in)
    return np.clip(hi - lo, 0.0, None) / pixel_out


def area_average(
    heights: np.ndarray, pixel_in: float, origin_m: tuple[float, float], n_out: int, pixel_out
) -> np.ndarray:
    """Mean of ``heights`` over each pixel of an ``n_out``² grid of ``pixel_out`` (m) whose
    corner lies at ``origin_m`` (row, col; m from the map's corner). The grid must lie inside
    the map (ValueError otherwise)."""
    n0, n1 = heights.shape
    extent = (n0 * pixel_in, n1 * pixel_in)
    for axis, (start, size) in enumerate(zip(origin_m, extent, strict=True)):
        end = start + n_out * pixel_out
        if start < -1e-9 * pixel_in or end > size + 1e-9 * pixel_in:
            raise ValueError(
                f"window [{start * 1e6:.2f}, {end * 1e6:.2f}] µm along axis {axis} leaves the "
                f"map (0 to {size * 1e6:.2f} µm)"
            )
    rows = overlap_weights(n0, pixel_in, origin_m[0], n_out, pixel_out)
    cols = overlap_weights(n1, pixel_in, origin_m[1], n_out, pixel_out)
    return rows @ heights @ cols.T


def _statistics(heights: np.ndarray, pixel_m: float) -> dict:
    stats = roughness_statistics(heights - heights.mean(), pixel_m)
    return {
        "pixel_nm": pixel_m * 1e9,
        "roughness_rms_nm": stats.h_rms_m * 1e9,
        "slope_rms": stats.slope_rms,
    }


@dataclass(frozen=True)
class LevelledMap:
    """An AFM map levelled by the topography step: heights (m) with the scan-line offsets
    removed and the sphere kept, square pixels (m), the fitted sphere (radius m; apex (x, y) m
    from the map centre; apex height m)."""

    heights_m: np.ndarray
    pixel_m: float
    radius_m: float
    apex_xy_m: tuple[float, float]
    apex_height_m: float

    @property
    def roughness_m(self) -> np.ndarray:
        """The map minus the fitted sphere, about its mean, m."""
        cap = sphere_cap(self.heights_m.shape, self.pixel_m, self.radius_m, self.apex_xy_m)
        rough = self.heights_m - cap
        return rough - rough.mean()

    def to_attributes(self) -> dict:
        return {
            "radius_m": self.radius_m,
            "apex_xy_m": list(self.apex_xy_m),
            "apex_height_m": self.apex_height_m,
        }


def level_afm_map(heights: np.ndarray, pixel_m: float, line_levelling: str = "auto") -> LevelledMap:
    """Level a sphere's AFM map with the topography step's sphere fit and scan-line levelling
    (:func:`amontons.measure.topography.level_sphere`; ``line_levelling`` auto, on or off)."""
    return levelled_by(
        heights, pixel_m, level_sphere(heights, pixel_m, line_levelling=line_levelling)
    )


def levelled_by(heights: np.ndarray, pixel_m: float, fit: FitParameters) -> LevelledMap:
    """The map levelled by its sphere fit: its scan-line offsets removed, the sphere kept."""
    return LevelledMap(
        heights - fit.line_levelling.offsets_m[:, None],
        pixel_m,
        fit.radius_m,
        fit.apex_xy_m,
        fit.apex_height_m,
    )


def read_and_fit_afm_map(
    path: str | Path,
    *,
    fallback_pixel_m: float | None,
    nan_policy: str,
    channel: str | None,
    line_levelling: str,
) -> tuple[LevelledMap, FitParameters]:
    """Read a sphere's AFM map (amontons.io.heightmap: any supported format, square pixels),
    fit its sphere and level it: (the levelled map, the fit), the fit the topography step
    reads instead of fitting the same map again. A map that is no sphere's apex raises
    RawDataError naming the file."""
    height_map = square_pixels(
        read_height_map(
            path, fallback_pixel_m=fallback_pixel_m, nan_policy=nan_policy, channel=channel
        )
    )
    try:
        fit = level_sphere(height_map.heights, height_map.pixel_m, line_levelling=line_levelling)
    except TopographyError as error:
        raise RawDataError(f"{path}: {error}; expected the AFM map of a sphere's apex") from error
    return levelled_by(height_map.heights, height_map.pixel_m, fit), fit


def load_levelled_map(path: str | Path) -> LevelledMap:
    """A levelled map as the level_afm_map rule wrote it (HDF5, amontons.io.fields)."""
    heights, pixel_m, attrs = read_levelled_map(path)
    return LevelledMap(
        heights, pixel_m, attrs["radius_m"], tuple(attrs["apex_xy_m"]), attrs["apex_height_m"]
    )


def _apex_rc_m(levelled: LevelledMap) -> tuple[float, float]:
    """The fitted apex (row, col; m from the map's corner)."""
    n0, n1 = levelled.heights_m.shape
    # apex_xy_m is (x, y) = (col, row) from the map centre
    x, y = levelled.apex_xy_m
    return y + n0 * levelled.pixel_m / 2, x + n1 * levelled.pixel_m / 2


def scan_window_m(levelled: LevelledMap) -> float:
    """Side (m) of the largest square about the fitted apex that lies inside the scan: twice
    the apex's distance to the nearest edge (0 for an apex outside the scan)."""
    n0, n1 = levelled.heights_m.shape
    row, col = _apex_rc_m(levelled)
    extent = (n0 * levelled.pixel_m, n1 * levelled.pixel_m)
    return max(0.0, 2 * min(row, col, extent[0] - row, extent[1] - col))


@dataclass(frozen=True)
class ScanCoverage:
    """What of a scene's loads a sphere's AFM scan holds: the scan's width and height (m), the
    largest window about the fitted apex inside it (m), the loads left out, each with the
    window it needs (amontons.config.geometry.LeftOutLoad), and where the scan clipped the
    window of the loads kept, the window they would have had and the one they are solved on
    (m; None where not clipped)."""

    scan_m: tuple[float, float]
    largest_window_m: float
    left_out: tuple[LeftOutLoad, ...]
    clipped_from_m: float | None = None
    solved_window_m: float | None = None

    def without(self, dropped: tuple[float, ...], windows_m: tuple[float, ...]) -> ScanCoverage:
        """This coverage with the loads ``dropped`` (N) left out too, each with its own
        window (``windows_m``, m): their contacts reached the clipped window's edge
        (amontons.simulate.solve.solve_on_clipped_window)."""
        reason = "its contact reaches the edge of the window the scan clipped"
        extra = tuple(
            LeftOutLoad(load, window, reason)
            for load, window in zip(dropped, windows_m, strict=True)
        )
        return replace(self, left_out=extra + self.left_out)

    def to_record(self) -> dict:
        """JSON-ready, units in the key names; ``outside_scan`` lists the loads left out;
        ``window_clipped`` (only where the scan clipped the window) the window the loads
        would have had, the one they were solved on, and its fraction of it."""
        record = {
            "scan_um": [s * 1e6 for s in self.scan_m],
            "largest_window_in_scan_um": self.largest_window_m * 1e6,
            "outside_scan": [load.to_record() for load in self.left_out],
        }
        if self.clipped_from_m is not None:
            record["window_clipped"] = {
                "own_window_um": self.clipped_from_m * 1e6,
                "clipped_to_um": self.solved_window_m * 1e6,
                "fraction": self.solved_window_m / self.clipped_from_m,
            }
        return record


def afm_scene(
    name: str, config: Mapping, sphere: str, record: Mapping, levelled: LevelledMap
) -> tuple[Scene | None, ScanCoverage]:
    """The scene ``name`` on ``sphere``'s levelled map at the loads whose window the scan
    holds (None where it holds none), and what the scan covers."""
    window = scan_window_m(levelled)
    scene, cut = scene_in_scan(name, config, sphere, record, window)
    n0, n1 = levelled.heights_m.shape
    scan = (n1 * levelled.pixel_m, n0 * levelled.pixel_m)
    if cut.clipped_from_m is not None:
        log.info(
            "scene %s, sphere %s: window clipped from %.1f to %.1f µm, the %.1f µm the scan "
            "holds about the apex (the contacts of %s mN fit with the room the solver needs)",
            name,
            sphere,
            cut.clipped_from_m * 1e6,
            cut.window_m * 1e6,
            window * 1e6,
            ", ".join(f"{f * 1e3:g}" for f in cut.frame.loads_n),
        )
    for load in cut.left_out:
        log.info(
            "scene %s, sphere %s: %g mN left out (outside_scan): its window of %.1f µm does not "
            "fit in the %.1f µm the scan holds about the apex (scan %.1f × %.1f µm)",
            name,
            sphere,
            load.load_n * 1e3,
            load.window_m * 1e6,
            window * 1e6,
            scan[0] * 1e6,
            scan[1] * 1e6,
        )
    return scene, ScanCoverage(scan, window, cut.left_out, cut.clipped_from_m, cut.window_m)


def afm_indenter(levelled: LevelledMap, scene: Scene, source: str) -> Indenter:
    """The scene's indenter from a sphere's levelled AFM map: cut to the scene's window about
    the fitted apex and area-averaged to the solver pixel. A window that leaves the scan
    raises SceneError naming ``source`` and the sizes."""
    heights, pixel_m = levelled.heights_m, levelled.pixel_m
    n = scene.side_px
    window = n * scene.pixel_m
    n0, n1 = heights.shape
    apex_rc = _apex_rc_m(levelled)
    origin = (apex_rc[0] - window / 2, apex_rc[1] - window / 2)
    try:
        solver = area_average(heights, pixel_m, origin, n, scene.pixel_m)
    except ValueError as error:
        raise SceneError(
            f"{source}: scene {scene.name}: the solver window ({window * 1e6:.1f} µm about the "
            f"fitted apex) does not fit in the AFM scan ({n0} × {n1} px of "
            f"{pixel_m * 1e9:.1f} nm): {error}; expected a scan that covers the window "
            "(lower window_factor or side_px, or scan a larger field)"
        ) from error
    roughness = solver - sphere(solver.shape, scene.pixel_m, levelled.radius_m)
    centre = (origin[0] + window / 2 - n0 * pixel_m / 2, origin[1] + window / 2 - n1 * pixel_m / 2)
    return Indenter(
        heights=solver - solver.max(),
        spacing_m=scene.pixel_m,
        centre_in_scan_m=centre,
        afm_statistics=_statistics(levelled.roughness_m, pixel_m),
        solver_statistics=_statistics(roughness, scene.pixel_m),
    )


def synthetic_indenter(scene: Scene) -> Indenter:
    """The scene's indenter from its synthetic self-affine surface (periodic; on a sphere of
    the scene's radius for the sphere geometry)."""
    spec = scene.synthetic
    if spec is None:
        raise SceneError(f"scene {scene.name}: no synthetic surface given")
    n = scene.side_px
    rough = self_affine(
        (n, n),
        scene.pixel_m,
        spec.hurst,
        rms_slope=spec.rms_slope,
        rms_height=spec.rms_height_m,
        short_cutoff=spec.short_cutoff_m,
        long_cutoff=spec.long_cutoff_m,
        rng=spec.seed,
    )
    heights = rough if scene.periodic else rough + sphere((n, n), scene.pixel_m, scene.radius_m)
    stats = _statistics(rough, scene.pixel_m)
    return Indenter(
        heights=heights - heights.max(),
        spacing_m=scene.pixel_m,
        centre_in_scan_m=(0.0, 0.0),
        afm_statistics=stats,
        solver_statistics=stats,
    )
