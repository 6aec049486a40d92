"""Validation of the workflow configuration and the sample sheet, with messages a user can act on.

JSON Schema (via ``jsonschema``) checks structure and types; the checks that a schema cannot
express (strictly increasing loads, unique sphere ids, materials present in the sheet) live here
too (the reflection and FLIM loads among the loads, material names that are not target names),
so that every bad configuration fails before any job runs and names the key, the value and
what was expected. Standard library, jsonschema and yaml only: the workflow imports it to
build its DAG.
"""

from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from pathlib import Path

import jsonschema
import yaml


class ConfigError(ValueError):
    """A configuration or sample-sheet value is not what the workflow expects."""


def load_schema(path: str | Path) -> dict:
    """Read a JSON Schema written as YAML."""
    with open(path) as stream:
        return yaml.safe_load(stream)


def _key_path(error: jsonschema.ValidationError) -> str:
    return ".".join(str(part) for part in error.absolute_path) or "<top level>"


def _schema_at(schema: Mapping, error: jsonschema.ValidationError) -> Mapping:
    node = schema
    for part in error.absolute_path:
        if isinstance(part, int):
            node = node.get("items", {})
        elif part in node.get("properties", {}):
            node = node["properties"][part]
        else:
            extra = node.get("additionalProperties")
            node = extra if isinstance(extra, Mapping) else {}
    return node


def _describe(error: jsonschema.ValidationError, schema: Mapping) -> str:
    where = _key_path(error)
    if error.validator == "additionalProperties":
        allowed = sorted(_schema_at(schema, error).get("properties", {}))
        unknown = sorted(set(error.instance) - set(allowed))
        return (
            f"unknown key(s) {', '.join(repr(k) for k in unknown)} in {where}; "
            f"allowed keys: {', '.join(allowed)}"
        )
    if error.validator == "enum":
        allowed = ", ".join(repr(v) for v in error.validator_value)
        return f"{where} = {error.instance!r} is not allowed; allowed values: {allowed}"
    if error.validator == "required":
        return f"{where}: {error.message}"
    description = error.schema.get("description", "")
    expected = f" (expected: {description})" if description else ""
    return f"{where} = {error.instance!r}: {error.message}{expected}"


def validate(data: Mapping, schema: Mapping, source: str) -> None:
    """Raise ConfigError listing every schema violation of ``data``, each naming its key.

    ``source`` names the file the data came from, for the message.
    """
    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path)))
    if errors:
        lines = "\n  ".join(_describe(e, schema) for e in errors)
        raise ConfigError(f"{source}: invalid configuration\n  {lines}")


def parse_loads_mn(text: str, where: str) -> list[float]:
    """Parse a comma-separated, strictly increasing list of positive loads in mN."""
    try:
        loads = [float(part) for part in str(text).split(",")]
    except ValueError as exc:
        raise ConfigError(
            f"{where}: loads_mn = {text!r} is not a comma-separated list of numbers"
        ) from exc
    if any(load <= 0 for load in loads):
        raise ConfigError(f"{where}: loads_mn = {text!r}; every load must be positive (mN)")
    steps = [b - a for a, b in zip(loads, loads[1:], strict=False)]
    if any(step <= 0 for step in steps):
        raise ConfigError(
            f"{where}: loads_mn = {text!r} is not strictly increasing; loads are stepped upward "
            "and carry plastic history, so list them in increasing order without repeats"
        )
    return loads


# A power-law fit with standard errors (load-area, intensity-pressure) needs this many loads.
MIN_LOADS = 3
_BOOLEAN_WORDS = {"true": True, "false": False, "yes": True, "no": False, "1": True, "0": False}
# Names of the workflow's wildcard-free target rules: a material of the same name would make a
# second rule of that name (each material gets its own target, `snakemake PS`).
RESERVED_NAMES = frozenset(
    {"all", "optics", "surface", "friction", "fits", "figures", "virtual_experiment", "scenes"}
    | {"scans", "study", "accuracy"}
    | {"synthetic"}  # the folder of the synthetic scenes, results/<run>/synthetic/
)


def _typed(value: str, kind: str | None):
    """A sheet cell as the schema's type: numbers stay text when they do not parse, so that
    the schema names the cell rather than this function."""
    if kind in ("number", "integer"):
        try:
            number = float(value)
        except ValueError:
            return value
        return int(number) if kind == "integer" and number.is_integer() else number
    if kind == "boolean":
        return _BOOLEAN_WORDS.get(value.strip().lower(), value)
    return value


def _row_record(row: Mapping[str, str], schema: Mapping) -> dict:
    """A sheet row without its empty cells, each value of the schema's type."""
    properties = schema.get("properties", {})
    record = {}
    for key, value in row.items():
        if value is None or value.strip() == "":
            continue
        record[key] = _typed(value.strip(), properties.get(key, {}).get("type"))
    return record


def _sheet_rows(path: Path) -> list[dict[str, str]]:
    """The sheet's rows (tab-separated, '#' comment lines skipped) with their line numbers."""
    with open(path, encoding="utf-8", newline="") as stream:
        lines = [(n, line) for n, line in enumerate(stream, start=1) if not line.startswith("#")]
    reader = csv.DictReader((line for _, line in lines), delimiter="\t")
    rows = []
    for (number, _), row in zip(lines[1:], reader, strict=False):
        if None in row:
            raise ConfigError(f"{path}, line {number}: more cells than columns: {row[None]}")
        rows.append({"_line": number, **row})
    return rows


def check_sheet_loads(sphere: str, record: Mapping, where: str) -> None:
    """The reflection and FLIM loads of a sphere must be among its loads_mn."""
    for column in ("reflection_load_mn", "flim_load_mn"):
        value = record.get(column)
        if value is None:
            continue
        if not any(abs(float(value) - load) < 1e-9 for load in record["loads"]):
            raise ConfigError(
                f"{where}, sphere {sphere}: {column} = {value:g} is not one of loads_mn "
                f"{record['loads']}; expected the load of an existing image"
            )


def check_enough_loads(sphere: str, record: Mapping, where: str) -> None:
    """A sphere needs at least MIN_LOADS loads: its load-area and intensity-pressure power
    laws are fitted with standard errors."""
    if len(record["loads"]) < MIN_LOADS:
        raise ConfigError(
            f"{where}, sphere {sphere}: loads_mn = {record['loads_mn']!r} holds "
            f"{len(record['loads'])} load(s); expected at least {MIN_LOADS}, since the "
            "load-area and intensity-pressure power laws are fitted with standard errors"
        )


def check_reference_load(reference_mn: float, spheres: Mapping[str, dict], source: str) -> None:
    """The load at which areas and friction are normalised must be one of every selected
    sphere's loads (the figures divide by the area and friction measured there)."""
    for sphere, record in spheres.items():
        if not any(abs(reference_mn - load) < 1e-9 for load in record["loads"]):
            raise ConfigError(
                f"{source}: load_area.reference_load_mn = {reference_mn:g} mN is not one of "
                f"sphere {sphere}'s loads_mn {record['loads']} mN; expected a load that every "
                "selected sphere was measured at"
            )


def read_sample_sheet(path: str | Path, schema: Mapping) -> dict[str, dict]:
    """Read and validate the sample sheet (TSV, one row per sphere): sphere id → its record,
    in the sheet's order, each value of its schema type.

    Adds ``loads``, each row's loads as a list of floats in mN. Standard library only, so
    that the workflow builds its DAG without the numerical stack.
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"materials_sheet = {str(path)!r}: no such file")
    sheet: dict[str, dict] = {}
    repeated = []
    for row in _sheet_rows(path):
        line = row.pop("_line")
        record = _row_record(row, schema)
        validate(record, schema, f"{path}, line {line} (sphere {record.get('sphere')!r})")
        record["loads"] = parse_loads_mn(record["loads_mn"], f"{path}, sphere {record['sphere']}")
        check_sheet_loads(record["sphere"], record, str(path))
        check_enough_loads(record["sphere"], record, str(path))
        if record["sphere"] in sheet:
            repeated.append(record["sphere"])
        sheet[record["sphere"]] = record
    if repeated:
        raise ConfigError(
            f"{path}: sphere ids must be unique; repeated: {', '.join(sorted(set(repeated)))}"
        )
    return sheet


def check_selected_materials(selected: Sequence[str], sheet: Mapping[str, dict], source: str):
    """Every material named in the config's ``materials`` must have a row in the sheet, and
    none may take the name of a workflow target."""
    known = sorted({record["material"] for record in sheet.values()})
    unknown = [m for m in selected if m not in known]
    if unknown:
        raise ConfigError(
            f"{source}: materials = {list(selected)} names unknown material(s) "
            f"{', '.join(repr(m) for m in unknown)}; allowed values (from the sample sheet): "
            f"{', '.join(known)}"
        )
    reserved = [m for m in selected if m in RESERVED_NAMES]
    if reserved:
        raise ConfigError(
            f"{source}: material(s) {', '.join(repr(m) for m in reserved)} take the name of a "
            f"workflow target; rename them in the sample sheet (reserved: "
            f"{', '.join(sorted(RESERVED_NAMES))})"
        )


def load_workflow_config(
    config: Mapping, config_schema: Mapping, sheet_schema: Mapping, source: str
) -> dict[str, dict]:
    """Validate a config mapping and its sample sheet; return the sheet records (sphere id →
    record) of the selected materials."""
    validate(config, config_schema, source)
    resolve_scene_presets(config, source)
    sheet = read_sample_sheet(config["materials_sheet"], sheet_schema)
    check_selected_materials(config["materials"], sheet, source)
    selected = {s: r for s, r in sheet.items() if r["material"] in config["materials"]}
    check_reference_load(config["load_area"]["reference_load_mn"], selected, source)
    check_scenes(config, selected, source)
    check_scans(config, selected, source)
    check_curvature_pairs(config, source)
    check_accuracy_study(config, sheet, source)
    return selected


def hertz_diameter_um(load_mn: float, diameter_mm: float, e_star_gpa: float) -> float:
    """Hertz contact diameter (µm) of a sphere at ``load_mn``: 2·(3FR/4E*)^(1/3).

    amontons.physics.hertz.contact_radius in config units: that module imports numpy, which
    the workflow's DAG helpers must not (tests/test_architecture.py)."""
    radius_m = diameter_mm * 0.5e-3
    return 2e6 * (3 * load_mn * 1e-3 * radius_m / (4 * e_star_gpa * 1e9)) ** (1 / 3)


def _scene_window_um(scene: Mapping, diameter_mm: float, e_star_gpa: float, loads) -> float:
    if scene["side_px"] is not None:
        return scene["side_px"] * scene["pixel_nm"] * 1e-3
    return scene["window_factor"] * hertz_diameter_um(max(loads), diameter_mm, e_star_gpa)


def solver_side_px(scene: Mapping, diameter_mm: float | None, e_star_gpa: float, loads) -> int:
    """The solver grid side (px, even) of a scene on a sphere of the sheet (or a synthetic
    one): amontons.simulate.scene's window and pixel in config units, for the DAG (the
    cluster resources of a solve grow with its grid)."""
    if scene["side_px"] is not None:
        n = int(scene["side_px"])
    else:
        window_um = _scene_window_um(scene, diameter_mm, e_star_gpa, loads)
        n = int(round(window_um / solver_pixel_um(scene, diameter_mm, e_star_gpa, loads)))
    return n + n % 2


def solver_pixel_um(scene: Mapping, diameter_mm: float | None, e_star_gpa: float, loads):
    """The solver pixel (µm) of a scene, as :func:`solver_side_px`: its pixel_nm, coarsened
    where the window would exceed max_side_px."""
    if scene["side_px"] is not None:
        return scene["pixel_nm"] * 1e-3
    window_um = _scene_window_um(scene, diameter_mm, e_star_gpa, loads)
    return max(scene["pixel_nm"] * 1e-3, window_um / scene["max_side_px"])


def _check_scene_window(name: str, scene: Mapping, spheres: Mapping[str, dict], source: str):
    """The window must hold the largest contact the sheet predicts: the Hertz contact at the
    largest load (a rough or hardened contact is larger still; the solver's free-boundary
    check catches what this cannot)."""
    for sphere, record in spheres.items():
        loads = record["loads"] if scene["loads"] == "measured" else scene["loads"]
        contact = hertz_diameter_um(max(loads), record["diameter_mm"], record["e_star_gpa"])
        window = _scene_window_um(scene, record["diameter_mm"], record["e_star_gpa"], loads)
        if window <= contact:
            key = "side_px" if scene["side_px"] is not None else "window_factor"
            raise ConfigError(
                f"{source}: scene {name}: the solver window ({key}) is {window:.1f} µm, smaller "
                f"than sphere {sphere}'s Hertz contact diameter {contact:.1f} µm at "
                f"{max(loads):g} mN; expected a window larger than the largest contact"
            )


def _check_scene_parameters(name: str, scene: Mapping, spheres: Mapping[str, dict], source):
    """Model parameters that are null must come from every sphere's sheet row."""
    needs = {
        "penetration_hardness": ("p_y_mpa", "hardness_mpa"),
        "hardening": ("k_mpa_per_nm", "hardening_k_mpa_per_nm"),
    }
    if scene["model"] not in needs or scene["surface"] == "synthetic":
        return
    key, column = needs[scene["model"]]
    if scene[key] is not None:
        return
    for sphere, record in spheres.items():
        if record.get(column) is None:
            raise ConfigError(
                f"{source}: scene {name}: {key} is null, and sphere {sphere} has no {column} in "
                f"the sheet; expected a value in one of them"
            )


def _check_one_scene(name: str, scene: Mapping, spheres: Mapping[str, dict], source: str):
    where = f"{source}: scene {name}"
    synthetic = scene["surface"] == "synthetic"
    if synthetic and scene["optics"] == "microscope":
        raise ConfigError(
            f"{where}: optics = 'microscope' on a synthetic surface; expected 'none' (there is "
            "no measured image of a synthetic surface to render like or compare with)"
        )
    if scene["model"] == "greenwood_tripp" and scene["optics"] == "microscope":
        raise ConfigError(
            f"{where}: optics = 'microscope' with model greenwood_tripp; expected 'none' "
            "(Greenwood-Tripp gives a mean area fraction, not a contact map to render)"
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
        radius = scene["synthetic"]["radius_mm"]
        record = {"diameter_mm": 2 * radius, "e_star_gpa": scene["synthetic"]["e_star_gpa"]}
        _check_scene_window(
            name, scene, {"(synthetic)": {**record, "loads": scene["loads"]}}, source
        )
    if synthetic and ("rms_slope" in scene["synthetic"]) == ("rms_height_nm" in scene["synthetic"]):
        raise ConfigError(f"{where}: synthetic needs exactly one of rms_slope and rms_height_nm")
    if not synthetic:
        _check_scene_window(name, scene, spheres, source)
        _check_scene_parameters(name, scene, spheres, source)


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


def check_scenes(config: Mapping, spheres: Mapping[str, dict], source: str) -> None:
    """Scenes that cannot run stop the run before any job: each message names the scene and
    the key (docs/simulate.md)."""
    unknown = [name for name in config["run_scenes"] if name not in config["scenes"]]
    if unknown:
        raise ConfigError(
            f"{source}: run_scenes names {', '.join(map(repr, unknown))}, not in scenes; "
            f"expected one of {', '.join(config['scenes'])}"
        )
    for name in config["run_scenes"]:
        _check_one_scene(name, config["scenes"][name], spheres, source)


SCAN_MODELS = {"p_y_mpa": "penetration_hardness", "k_mpa_per_nm": "hardening"}
SCAN_COLUMNS = {"p_y_mpa": "hardness_mpa", "k_mpa_per_nm": "hardening_k_mpa_per_nm"}


def _check_one_scan(name: str, scan: Mapping, config: Mapping, spheres, source: str) -> None:
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
    model = SCAN_MODELS[scan["parameter"]]
    if scene["model"] != model:
        raise ConfigError(
            f"{where}: parameter {scan['parameter']} belongs to model {model}, but base scene "
            f"{base} has model {scene['model']}; expected a {model} scene"
        )
    low, high = scan["range_factor"]
    if not low < high:
        raise ConfigError(f"{where}: range_factor = [{low:g}, {high:g}]; expected low < high")
    column = SCAN_COLUMNS[scan["parameter"]]
    for sphere, record in spheres.items():
        if record.get(column) is None:
            raise ConfigError(
                f"{where}: sphere {sphere} has no {column} in the sheet; expected a value (the "
                "scan's range is range_factor times it)"
            )


def check_scans(config: Mapping, spheres: Mapping[str, dict], source: str) -> None:
    """Scans that cannot run stop the run before any job (docs/study.md)."""
    unknown = [name for name in config["run_scans"] if name not in config["scans"]]
    if unknown:
        raise ConfigError(
            f"{source}: run_scans names {', '.join(map(repr, unknown))}, not in scans; "
            f"expected one of {', '.join(config['scans'])}"
        )
    for name in config["run_scans"]:
        _check_one_scan(name, config["scans"][name], config, spheres, source)


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


def merge_config(base: Mapping, overlay: Mapping) -> dict:
    """``base`` with ``overlay``'s keys merged over it, nested mappings key by key (lists and
    values replaced), as Snakemake merges ``--configfile`` over the Snakefile's configfile."""
    merged = dict(base)
    for key, value in overlay.items():
        if isinstance(value, Mapping) and isinstance(merged.get(key), Mapping):
            merged[key] = merge_config(merged[key], value)
        else:
            merged[key] = value
    return merged


def read_config(base: str | Path, *overlays: str | Path) -> dict:
    """The configuration a run sees: the YAML file ``base`` with each overlay merged over it
    in turn (e.g. config/config.yaml, then config/test.yaml)."""
    with open(base, encoding="utf-8") as stream:
        config = yaml.safe_load(stream)
    for overlay in overlays:
        with open(overlay, encoding="utf-8") as stream:
            config = merge_config(config, yaml.safe_load(stream) or {})
    return config


def check_accuracy_study(config: Mapping, sheet: Mapping[str, dict], source: str) -> None:
    """The accuracy study's sphere (null: the first sphere of the first selected material,
    set in place) must be a sphere of a selected material, and its grid and reference must
    make sense (amontons.accuracy.settings.check_accuracy)."""
    from amontons.accuracy.settings import check_accuracy  # it imports this module

    study = config["accuracy"]
    if study["sphere"] is None:
        # the first sphere of the first selected material: the study runs on any data set
        study["sphere"] = next(
            s for m in config["materials"] for s, r in sheet.items() if r["material"] == m
        )
    record = sheet.get(study["sphere"])
    if record is None or record["material"] not in config["materials"]:
        raise ConfigError(
            f"{source}: accuracy.sphere = {study['sphere']!r} is not a sphere of the selected "
            f"materials {list(config['materials'])}; expected one of "
            f"{', '.join(s for s, r in sheet.items() if r['material'] in config['materials'])}"
        )
    check_accuracy(study, source)
