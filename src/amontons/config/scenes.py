"""Scenes, scans and the study's curvature pairs in the config, checked before any job: a
scene or scan that cannot run stops the run naming the scene, the key and what was expected
(docs/simulate.md, docs/study.md). Each scene's solver keys are filled from its preset here,
once, so that every rule sees the same resolved scene."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.config.errors import ConfigError
from amontons.config.geometry import (
    Frame,
    hertz_diameter_m,
    sphere_frame,
    synthetic_frame,
    window_m,
)
from amontons.models import ASPERITY_STATISTICS, model_named, model_of_parameter


def _check_scene_window(name: str, scene: Mapping, frames: Mapping[str, Frame], source: str):
    """The window must hold the largest contact the sheet predicts: the Hertz contact at the
    largest load (a rough or hardened contact is larger still; the solver's free-boundary
    check catches what this cannot). ``frames``: each sphere's frame of the scene."""
    for sphere, frame in frames.items():
        largest = max(frame.loads_n)
        contact = hertz_diameter_m(largest, frame.radius_m, frame.e_star_pa)
        window = window_m(name, scene, frame)
        if window <= contact:
            key = "side_px" if scene["side_px"] is not None else "window_factor"
            raise ConfigError(
                f"{source}: scene {name}: the solver window ({key}) is {window * 1e6:.1f} µm, "
                f"smaller than sphere {sphere}'s Hertz contact diameter {contact * 1e6:.1f} µm "
                f"at {largest * 1e3:g} mN; expected a window larger than the largest contact"
            )


def sheet_prior(scene: Mapping) -> tuple[str, str] | None:
    """(key, sheet column) of the model parameter a scene on a sphere's map takes from the
    sheet because its own value is null; None where it needs none. A sphere without that
    column does not run the scene (amontons.workflow.scenes says so per sphere)."""
    parameter = model_named(scene["model"]).parameter
    if parameter is None or scene["surface"] == "synthetic":
        return None
    return None if scene.get(parameter.key) is not None else (parameter.key, parameter.sheet_column)


def _check_one_scene(name: str, scene: Mapping, spheres: Mapping[str, dict], source: str):
    where = f"{source}: scene {name}"
    synthetic = scene["surface"] == "synthetic"
    if synthetic and scene["optics"] == "microscope":
        raise ConfigError(
            f"{where}: optics = 'microscope' on a synthetic surface; expected 'none' (there is "
            "no measured image of a synthetic surface to render like or compare with)"
        )
    model = model_named(scene["model"])
    if model.kind == ASPERITY_STATISTICS and scene["optics"] == "microscope":
        raise ConfigError(
            f"{where}: optics = 'microscope' with model {model.name}; expected 'none' "
            f"({model.label} gives a mean area fraction, not a contact map to render)"
        )
    if synthetic and "synthetic" not in scene:
        raise ConfigError(f"{where}: surface = 'synthetic' needs the key synthetic")
    if synthetic and scene["loads"] == "measured":
        raise ConfigError(f"{where}: loads = 'measured' needs a sphere; expected a list (mN)")
    if scene["geometry"] == "flat_periodic" and not synthetic:
        raise ConfigError(
            f"{where}: geometry = 'flat_periodic' with surface afm_before; expected a "
            "synthetic surface (a sphere's map is neither flat nor periodic)"
        )
    if scene["geometry"] == "flat_periodic" and scene["side_px"] is None:
        raise ConfigError(f"{where}: geometry = 'flat_periodic' needs side_px (no Hertz window)")
    if scene["increment"] == "volume_conserving" and scene["alpha"] >= 1:
        raise ConfigError(
            f"{where}: increment = 'volume_conserving' with alpha = {scene['alpha']:g}; "
            "expected alpha < 1 (eq. B.3 needs over-relaxation)"
        )
    if synthetic and scene["geometry"] == "sphere":
        if "radius_mm" not in scene["synthetic"]:
            raise ConfigError(f"{where}: geometry 'sphere' needs synthetic.radius_mm")
        _check_scene_window(name, scene, {"(synthetic)": synthetic_frame(scene)}, source)
    if synthetic and ("rms_slope" in scene["synthetic"]) == ("rms_height_nm" in scene["synthetic"]):
        raise ConfigError(f"{where}: synthetic needs exactly one of rms_slope and rms_height_nm")
    if not synthetic:
        frames = {sphere: sphere_frame(scene, record) for sphere, record in spheres.items()}
        _check_scene_window(name, scene, frames, source)


PRESET_KEYS = ("pixel_nm", "max_side_px", "window_factor", "tol")


def resolve_scene_presets(config: dict, source: str) -> None:
    """Fill each scene's solver keys (PRESET_KEYS) that it does not give from its preset: its
    own ``preset`` or the config's ``solver_preset`` (docs/accuracy.md, "Presets"). Explicit
    keys win. Resolved in place, so every rule sees the same resolved scene."""
    presets = config["solver_presets"]
    for name, scene in config["scenes"].items():
        preset = scene.get("preset") or config["solver_preset"]
        if preset not in presets:
            raise ConfigError(
                f"{source}: scene {name}: preset {preset!r} is not in solver_presets; expected "
                f"one of {', '.join(presets)}"
            )
        for key in PRESET_KEYS:
            if scene.get(key) is None:
                scene[key] = presets[preset][key]
        scene["preset"] = preset


def _check_running(config: Mapping, kind: str, source: str) -> None:
    """``run_<kind>`` may name only entries of ``<kind>`` (scenes or scans)."""
    unknown = [name for name in config[f"run_{kind}"] if name not in config[kind]]
    if unknown:
        raise ConfigError(
            f"{source}: run_{kind} names {', '.join(map(repr, unknown))}, not in {kind}; "
            f"expected one of {', '.join(config[kind])}"
        )


def check_scenes(config: Mapping, spheres: Mapping[str, dict], source: str) -> None:
    """Scenes that cannot run stop the run before any job: each message names the scene and
    the key (docs/simulate.md)."""
    _check_running(config, "scenes", source)
    for name in config["run_scenes"]:
        _check_one_scene(name, config["scenes"][name], spheres, source)


def _check_one_scan(name: str, scan: Mapping, config: Mapping, source: str) -> None:
    where = f"{source}: scan {name}"
    base = scan["scene"]
    if base not in config["run_scenes"]:
        raise ConfigError(
            f"{where}: scene {base!r} is not in run_scenes; expected one of "
            f"{', '.join(config['run_scenes']) or '(none)'} (a scan registers on its base "
            "scene's comparison)"
        )
    scene = config["scenes"][base]
    expected = {"surface": "afm_before", "optics": "microscope", "loads": "measured"}
    for key, value in expected.items():
        if scene[key] != value:
            raise ConfigError(
                f"{where}: base scene {base} has {key} = {scene[key]!r}; expected {value!r} "
                "(a scan is judged against the measured images at the measured loads)"
            )
    model = model_of_parameter(scan["parameter"]).name
    if scene["model"] != model:
        raise ConfigError(
            f"{where}: parameter {scan['parameter']} belongs to model {model}, but base scene "
            f"{base} has model {scene['model']}; expected a {model} scene"
        )
    for key in ("range_factor", "prior_free_range"):
        low, high = scan[key]
        if not low < high:
            raise ConfigError(f"{where}: {key} = [{low:g}, {high:g}]; expected low < high")


def check_scans(config: Mapping, source: str) -> None:
    """Scans that cannot run stop the run before any job (docs/study.md)."""
    _check_running(config, "scans", source)
    for name in config["run_scans"]:
        _check_one_scan(name, config["scans"][name], config, source)


def check_curvature_pairs(config: Mapping, source: str) -> None:
    """Fig. B.10's pairs: [flat periodic, curved] synthetic scenes of one model, both running."""
    study = config["study"]
    unknown = [
        name for name in study["run_curvature_pairs"] if name not in study["curvature_pairs"]
    ]
    if unknown:
        raise ConfigError(
            f"{source}: study.run_curvature_pairs names {', '.join(map(repr, unknown))}, not in "
            f"study.curvature_pairs; expected one of {', '.join(study['curvature_pairs'])}"
        )
    for model in study["run_curvature_pairs"]:
        pair = study["curvature_pairs"][model]
        where = f"{source}: study.curvature_pairs.{model}"
        for name, geometry in zip(pair, ("flat_periodic", "sphere"), strict=True):
            if name not in config["run_scenes"]:
                raise ConfigError(
                    f"{where}: scene {name!r} is not in run_scenes; expected a running scene"
                )
            scene = config["scenes"][name]
            if scene["surface"] != "synthetic" or scene["geometry"] != geometry:
                raise ConfigError(
                    f"{where}: scene {name} has surface {scene['surface']} and geometry "
                    f"{scene['geometry']}; expected a synthetic {geometry} scene (the pair is "
                    "[flat periodic, curved])"
                )
        models = {config["scenes"][name]["model"] for name in pair}
        if len(models) != 1:
            raise ConfigError(
                f"{where}: scenes {pair[0]} and {pair[1]} have models {sorted(models)}; "
                "expected one model for both"
            )
