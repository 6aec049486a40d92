"""A scene: one simulation the config names (docs/simulate.md), in SI units.

A scene names its surface (a sphere's ``afm_before`` map, or a synthetic self-affine
surface), its geometry (the sphere, non-periodic; or nominally flat, periodic), its contact
model and parameters, its loads, its solver grid and tolerance, and its optics. Only what it
names is computed: :attr:`Scene.plasticity` is None for an elastic scene (no plastic loop),
:attr:`Scene.periodic` drops the Hockney padding, and ``optics: none`` schedules no
rendering job (workflow/rules/simulate.smk).

:func:`scene_for_sphere` resolves a scene's config entry against one sphere's sheet record
(``null`` parameters take the sheet's value: E*, k, p_Y, loads); :func:`synthetic_scene`
resolves a synthetic scene, which names all of them itself.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

from amontons.config import geometry
from amontons.contact import ContactHardening, PenetrationHardness
from amontons.model_laws import law_si
from amontons.models import UnknownModelError, model_named, model_names, with_parameter

INCREMENTS = {"local": "local", "volume_conserving": "volume"}


class SceneError(ValueError):
    """A scene that cannot be simulated as configured (names the scene and the key)."""


@dataclass(frozen=True)
class SyntheticSurface:
    """Self-affine surface (docs/models.md §2.6): Hurst exponent, rms slope or rms height (m),
    short and long cut-off wavelengths (m), seed (on the scene's solver grid)."""

    hurst: float
    rms_slope: float | None
    rms_height_m: float | None
    short_cutoff_m: float | None
    long_cutoff_m: float | None
    seed: int


@dataclass(frozen=True)
class Scene:
    """One simulation, SI units: E* (Pa), sphere radius (m; None for a flat surface), loads
    (N, increasing), solver pixel (m), window side (m), tolerance, model and its law, optics
    and rendering."""

    name: str
    surface: str  # 'afm_before' or 'synthetic'
    geometry: str  # 'sphere' or 'flat_periodic'
    model: str
    e_star_pa: float
    radius_m: float | None
    loads_n: tuple[float, ...]
    pixel_m: float
    window_m: float
    tol: float
    optics: str  # 'none' or 'microscope'
    rendering: str  # 'emission' or 'binary'
    # the model's parameter (its record's Parameter) in SI; None for a model without one
    parameter_si: float | None = None
    increment: str = "local"
    alpha: float = 1.0
    synthetic: SyntheticSurface | None = None

    @property
    def periodic(self) -> bool:
        return self.geometry == "flat_periodic"

    @property
    def side_px(self) -> int:
        """Solver grid side, px (even)."""
        return geometry.side_px(self.window_m, self.pixel_m)

    @property
    def plasticity(self) -> PenetrationHardness | ContactHardening | None:
        """The plasticity law, None for an elastic (or Greenwood–Tripp) scene: no plastic loop."""
        return law_si(
            self.model,
            self.parameter_si,
            increment=INCREMENTS[self.increment],
            alpha=self.alpha,
        )

    def _parameters_record(self) -> dict:
        """Every model's parameter in config units: the scene's own model's value, None for
        the others' (and for a scene without one)."""
        out = {}
        for model in with_parameter():
            own = model.name == self.model and self.parameter_si is not None
            out[model.parameter.key] = self.parameter_si * model.parameter.from_si if own else None
        return out

    def to_record(self) -> dict:
        """JSON/HDF5-attribute-ready settings, units in the key names."""
        record = {
            "scene": self.name,
            "surface": self.surface,
            "geometry": self.geometry,
            "model": self.model,
            "e_star_gpa": self.e_star_pa * 1e-9,
            "radius_mm": None if self.radius_m is None else self.radius_m * 1e3,
            "loads_mn": [f * 1e3 for f in self.loads_n],
            "pixel_nm": self.pixel_m * 1e9,
            "window_um": self.window_m * 1e6,
            "side_px": self.side_px,
            "tol": self.tol,
            "optics": self.optics,
            "rendering": self.rendering,
            **self._parameters_record(),
            "increment": self.increment,
            "alpha": self.alpha,
        }
        if self.synthetic is not None:
            s = self.synthetic
            record["synthetic"] = {
                "hurst": s.hurst,
                "rms_slope": s.rms_slope,
                "rms_height_nm": None if s.rms_height_m is None else s.rms_height_m * 1e9,
                "short_cutoff_um": None if s.short_cutoff_m is None else s.short_cutoff_m * 1e6,
                "long_cutoff_um": None if s.long_cutoff_m is None else s.long_cutoff_m * 1e6,
                "seed": s.seed,
            }
        return record


def _window_m(name: str, config: Mapping, frame: geometry.Frame) -> float:
    """Window side (m): amontons.config.geometry.window_m, its error as a SceneError."""
    try:
        return geometry.window_m(name, config, frame)
    except geometry.GeometryError as exc:
        raise SceneError(str(exc)) from exc


def _sheet_or(name: str, config: Mapping, key: str, record: Mapping, column: str, scale: float):
    """The scene's own value of ``key`` or, where it is null, the sheet's ``column``."""
    value = config.get(key)
    if value is None:
        value = record.get(column)
    if value is None:
        raise SceneError(
            f"scene {name}: {key} is null and sphere {record.get('sphere', '?')} has no "
            f"{column} in the sheet; expected a value in one of them"
        )
    return float(value) * scale


def _model_parameters(name: str, config: Mapping, record: Mapping) -> dict:
    try:
        model = model_named(config["model"])
    except UnknownModelError as exc:
        raise SceneError(
            f"scene {name}: model = {config['model']!r}; expected one of {model_names()}"
        ) from exc
    out = {"increment": config.get("increment", "local"), "alpha": config.get("alpha", 1.0)}
    parameter = model.parameter
    if parameter is not None:
        value = _sheet_or(
            name, config, parameter.key, record, parameter.sheet_column, parameter.to_si
        )
        if value <= 0:
            raise SceneError(
                f"scene {name}: {parameter.key} = {value * parameter.from_si:g}; expected > 0"
            )
        out["parameter_si"] = value
    return out


def _scene(
    name: str,
    config: Mapping,
    frame: geometry.Frame,
    *,
    record: Mapping,
    synthetic: SyntheticSurface | None = None,
) -> Scene:
    """The Scene of a config entry, given what its surface decides (its frame: loads, radius
    and E*, SI), the sheet record its null model parameters come from, and a synthetic
    surface."""
    window_m = _window_m(name, config, frame)
    return Scene(
        name=name,
        surface=config["surface"],
        geometry=config["geometry"],
        model=config["model"],
        e_star_pa=frame.e_star_pa,
        radius_m=frame.radius_m,
        loads_n=frame.loads_n,
        pixel_m=geometry.solver_pixel_m(config, window_m),
        window_m=window_m,
        tol=config["tol"],
        optics=config["optics"],
        rendering=config.get("rendering", "emission"),
        synthetic=synthetic,
        **_model_parameters(name, config, record),
    )


def scene_for_sphere(name: str, config: Mapping, sphere: str, record: Mapping) -> Scene:
    """The scene ``name`` (its config entry) on the AFM map of ``sphere`` (its sheet record:
    diameter_mm, e_star_gpa, loads, hardness_mpa, hardening_k_mpa_per_nm)."""
    if config["surface"] != "afm_before":
        raise SceneError(f"scene {name}: surface = {config['surface']!r} is not a sphere's map")
    frame = geometry.sphere_frame(config, record)
    return _scene(name, config, frame, record={**record, "sphere": sphere})


def scene_in_scan(
    name: str, config: Mapping, sphere: str, record: Mapping, scan_window_m: float
) -> tuple[Scene | None, geometry.InScan]:
    """The scene ``name`` on the AFM map of ``sphere`` cut to the loads whose window, or
    whose contact with the room the solver needs, fits in the largest square about the apex
    that the scan holds (``scan_window_m``, m), on the window
    amontons.config.geometry.frame_in_scan gives them (the scene's own where the scan holds
    it), and that cut (the loads left out, the window clipped); where no load fits, the
    scene is None."""
    if config["surface"] != "afm_before":
        raise SceneError(f"scene {name}: surface = {config['surface']!r} is not a sphere's map")
    frame = geometry.sphere_frame(config, record)
    try:
        cut = geometry.frame_in_scan(name, config, frame, scan_window_m)
    except geometry.GeometryError as exc:
        raise SceneError(str(exc)) from exc
    if not cut.frame.loads_n:
        return None, cut
    scene = _scene(name, config, cut.frame, record={**record, "sphere": sphere})
    return replace(scene, window_m=cut.window_m, pixel_m=cut.pixel_m), cut


def synthetic_scene(name: str, config: Mapping) -> Scene:
    """A scene on a synthetic self-affine surface: it names E*, loads and (for the sphere
    geometry) the radius itself, and reads nothing of the experiment."""
    if config["surface"] != "synthetic":
        raise SceneError(f"scene {name}: surface = {config['surface']!r} is not synthetic")
    synthetic = config["synthetic"]
    if config["loads"] == "measured":
        raise SceneError(f"scene {name}: loads = 'measured' needs a sphere; give a list (mN)")
    surface = SyntheticSurface(
        hurst=synthetic["hurst"],
        rms_slope=synthetic.get("rms_slope"),
        rms_height_m=_scaled(synthetic.get("rms_height_nm"), 1e-9),
        short_cutoff_m=_scaled(synthetic.get("short_cutoff_um"), 1e-6),
        long_cutoff_m=_scaled(synthetic.get("long_cutoff_um"), 1e-6),
        seed=int(synthetic["seed"]),
    )
    frame = geometry.synthetic_frame(config)
    return _scene(name, config, frame, record={"sphere": "(synthetic)"}, synthetic=surface)


def _scaled(value, scale):
    return None if value is None else float(value) * scale
