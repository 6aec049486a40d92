"""A data folder checked before a run (README, "Your own data"): per sphere, every raw file
found with its format, shape and pixel size (from the file, else from the sheet), the loads
matched (for a file holding every load, which plane is which load), what the run will measure
and simulate, and what it cannot, and why.

    python -m amontons.check [--configfile config/mine.yaml ...] [--json]

It reads the config as Snakemake does (config/config.yaml, then each ``--configfile`` merged
over it), builds the same plan as the workflow (amontons.workflow) and opens each raw file
once. It writes nothing. Its exit status is 1 where the run would stop before any job (a bad
config, or fluorescence images that do not match the sheet's loads), else 0.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path

from amontons.config import ConfigError, read_config
from amontons.io.absorbance import read_absorbance_csv
from amontons.io.confocal import ImageChoice, LoadPlane, read_confocal
from amontons.io.export_map import ExportMap, export_maps
from amontons.io.heightmap import read_heights
from amontons.io.layout import PLANE_NOUN, RawDataError
from amontons.io.ptu import read_ptu_header
from amontons.io.rheometer_files import read_rheometer_file, reader_label
from amontons.io.tiff import read_tiff
from amontons.simulate.scan_grid import MIN_LOADS
from amontons.workflow.optional_inputs import AFM_AFTER, AFM_BEFORE, RHEOMETER
from amontons.workflow.params import image_choice
from amontons.workflow.run import WorkflowRun
from amontons.workflow.scenes import outside_scan_lines
from amontons.workflow.spheres import Spheres

# The workflow folder of a clone or an editable install (schemas, measured resources).
WORKFLOW_DIR = Path(__file__).resolve().parents[2] / "workflow"


def _tiff(path: str) -> dict:
    image = read_tiff(path)
    return {
        "shape": list(image.data.shape),
        "dtype": str(image.data.dtype),
        "pixel_nm": None if image.pixel_x_m is None else image.pixel_x_m * 1e9,
    }


def confocal_reader(choice: ImageChoice, sheet_pixel_nm: float | None) -> Callable[[str], dict]:
    """A reader for :func:`describe_file` of a confocal image: the plane ``choice`` picks
    (amontons.io.confocal), its format, shape, dtype and pixel with where it came from. A
    choice the file cannot meet, or a file and sheet pixel more than 1 % apart, is the
    reader's error."""
    sheet_pixel_m = None if sheet_pixel_nm is None else sheet_pixel_nm * 1e-9

    def read(path: str) -> dict:
        image = read_confocal(path, sheet_pixel_m, choice)
        return {
            "format": image.format,
            "shape": list(image.data.shape),
            "dtype": str(image.data.dtype),
            "pixel_nm": image.pixel_m * 1e9,
            "pixel_from": image.pixel_source,
        }

    return read


def _height_map(path: str) -> dict:
    raw = read_heights(path)
    return {
        "shape": list(raw.heights.shape),
        "pixel_nm": None if raw.pixel_x_m is None else raw.pixel_x_m * 1e9,
    }


def _ptu(path: str) -> dict:
    header = read_ptu_header(path)
    pixel_nm = None if header.pixel_m is None else header.pixel_m * 1e9
    return {"shape": list(header.shape), "pixel_nm": pixel_nm}


def flim_reader(path: str) -> Callable[[str], dict]:
    """A reader for :func:`describe_file` of the FLIM file: its photons' header (``.ptu``),
    else its map's TIFF tags."""
    return _ptu if Path(path).suffix.lower() == ".ptu" else _tiff


def rheometer_reader(maps: Mapping[str, ExportMap]) -> Callable[[str], dict]:
    """A reader for :func:`describe_file` of a rheometer file: which reader takes it (our
    CSV or an export map of ``maps``, amontons.io.rheometer_files) and its rows."""

    def read(path: str) -> dict:
        reader, trace = read_rheometer_file(path, maps)
        return {"reader": reader_label(reader), "rows": len(trace.time_s)}

    return read


def _absorbance(path: str) -> dict:
    wavelengths, _ = read_absorbance_csv(path)
    return {"rows": len(wavelengths)}


def describe_file(path: str, read: Callable[[str], dict], sheet_pixel_nm: float | None) -> dict:
    """One raw file: its format (suffix), what ``read`` finds in it, and its pixel size with
    where it comes from (the file, else the sheet); a file that cannot be read is reported
    with the reader's error, which names the file."""
    record = {"path": path, "format": Path(path).suffix.lstrip(".").lower() or "folder"}
    try:
        record.update(read(path))
    except (ValueError, OSError) as error:
        record["error"] = str(error)
        return record
    if "pixel_nm" in record and "pixel_from" not in record:
        if record["pixel_nm"] is None and sheet_pixel_nm is not None:
            record.update(pixel_nm=sheet_pixel_nm, pixel_from="sheet")
        elif record["pixel_nm"] is not None:
            record["pixel_from"] = "file"
    return record


def fluorescence_files(
    spheres: Spheres, sphere: str, choice: ImageChoice, sheet_pixel_nm: float | None
) -> list[dict]:
    """A measured sphere's fluorescence images described (:func:`describe_file`): one per
    load, or for a file holding every load, that file once per load, with the load (mN) and
    the plane it is read from (``plane``, e.g. 'series 2'). RawDataError where the folder
    does not match the sheet's loads."""
    images = spheres.files.per_load_inputs(sphere, "fluorescence")
    plane_loads = spheres.series.plane_loads(sphere)
    if plane_loads is None:
        read = confocal_reader(choice, sheet_pixel_nm)
        return [describe_file(path, read, sheet_pixel_nm) for path in images]
    axis = spheres.series.config["axis"]
    records = []
    for load in spheres.rows.loads_mn(sphere):
        plane = LoadPlane(axis, tuple(plane_loads), load)
        read = confocal_reader(replace(choice, load=plane), sheet_pixel_nm)
        record = describe_file(images[0], read, sheet_pixel_nm)
        records.append({**record, "load_mn": load, "plane": f"{PLANE_NOUN[axis]} {plane.index}"})
    return records


def sphere_files(
    spheres: Spheres,
    sphere: str,
    choices: tuple[ImageChoice, ImageChoice],
    rheometer_maps: Mapping[str, ExportMap],
) -> tuple[list[dict], list[str]]:
    """Every raw file of a measured sphere that is there, described (confocal images through
    ``choices``: the fluorescence and bead one, the reflection one; rheometer files with the
    reader that takes each, among our CSV and ``rheometer_maps``), and the errors that would
    stop the run before any job."""
    files, errors = [], []
    fluorescence_pixel = spheres.rows.value(sphere, "fluorescence_pixel_nm")
    image = confocal_reader(choices[0], fluorescence_pixel)
    afm_pixel = spheres.rows.value(sphere, "afm_pixel_nm")
    try:
        files += fluorescence_files(spheres, sphere, choices[0], fluorescence_pixel)
    except RawDataError as error:
        errors.append(str(error))
    if spheres.inputs.has(sphere, RHEOMETER):
        try:
            files += [
                describe_file(path, rheometer_reader(rheometer_maps), None)
                for path in spheres.files.per_load_inputs(sphere, "rheometer")
            ]
        except RawDataError as error:
            files.append({"path": f"{spheres.rows.raw_dir(sphere)}/rheometer", "error": str(error)})
    singles = [
        (
            spheres.files.reflection_image(sphere),
            confocal_reader(choices[1], fluorescence_pixel),
            fluorescence_pixel,
        ),
        (spheres.files.bead_image(sphere), image, fluorescence_pixel),
        (spheres.files.absorbance_spectrum(sphere), _absorbance, None),
    ]
    try:
        flim = spheres.files.flim_path(sphere)
    except RawDataError as error:  # a flim.tif and a flim.ptu
        flim = None
        errors.append(str(error))
    if flim is not None:
        singles.append((flim, flim_reader(flim), fluorescence_pixel))
    files += [describe_file(p, read, pixel) for p, read, pixel in singles if Path(p).is_file()]
    for stem in (AFM_BEFORE, AFM_AFTER):
        if spheres.inputs.has(sphere, stem):
            files.append(
                describe_file(spheres.files.afm_path(sphere, stem), _height_map, afm_pixel)
            )
    return files, errors


def scan_side_um(files: list[dict], afm_before: str) -> float | None:
    """The shorter side (µm) of the sphere's ``afm_before`` scan, where the check read it."""
    record = next((f for f in files if f["path"] == afm_before), None)
    if record is None or "error" in record or record.get("pixel_nm") is None:
        return None
    return min(record["shape"]) * record["pixel_nm"] * 1e-3


def sphere_plan(run: WorkflowRun, sphere: str) -> dict:
    """What the run makes of one sphere and what it cannot, and why."""
    material = run.spheres.rows.material_of(sphere)
    folder = f"{run.paths.results}/{material}/{sphere}/"
    outputs = [p for p in run.targets.material([material]) if p.startswith(folder)]
    record = {
        "sphere": sphere,
        "material": material,
        "data": "virtual experiment" if run.spheres.rows.is_synthetic(sphere) else "measured",
        "folder": run.spheres.rows.raw_dir(sphere),
        "loads_mn": run.spheres.rows.loads_mn(sphere),
        "outputs": outputs,
        "left_out": run.spheres.inputs.left_out(sphere) + run.scenes.left_out(sphere),
        "failed": run.spheres.hold_outs.failed_lines(sphere),
        "files": [],
        "errors": [],
    }
    if not run.spheres.rows.is_synthetic(sphere):
        choices = tuple(
            ImageChoice(**image_choice(run.config, reflection)) for reflection in (False, True)
        )
        maps = export_maps(
            run.spheres.files.rheometer_export(sphere, run.config.get("rheometer_export"))
        )
        record["files"], record["errors"] = sphere_files(run.spheres, sphere, choices, maps)
    side_um = None
    if run.spheres.inputs.has(sphere, AFM_BEFORE):
        side_um = scan_side_um(record["files"], run.spheres.files.afm_path(sphere, AFM_BEFORE))
    record["scan_side_um"] = side_um
    record["scenes"] = {} if side_um is None else run.scenes.scan_coverage(sphere, side_um)
    record["undecided_scans"] = undecided_scans(run, sphere, record["scenes"])
    return record


def undecided_scans(run: WorkflowRun, sphere: str, coverage: dict) -> dict[str, str]:
    """The sphere's parameter scans that will have nothing or too little to judge, each with
    why: their scene keeps no load inside the AFM scan (``coverage``:
    :meth:`Scenes.scan_coverage`), so no value is solved, or fewer loads than the criterion
    needs (:data:`MIN_LOADS`); their best.json will say 'not decided' (docs/study.md §6)."""
    undecided = {}
    for scan, spec in run.scenes.scans.items():
        if scan not in run.scenes.runnable_scans(sphere) or spec["scene"] not in coverage:
            continue
        held = coverage[spec["scene"]]["simulated_mn"]
        if not held:
            undecided[scan] = (
                f"scan {scan}: not decided (its scene {spec['scene']} keeps no load inside the "
                "AFM scan, so no value is solved)"
            )
        elif len(held) < MIN_LOADS:
            loads = ", ".join(f"{f:g}" for f in held)
            undecided[scan] = (
                f"scan {scan}: not decided (its scene {spec['scene']} keeps {len(held)} loads "
                f"inside the AFM scan, {loads} mN; the criterion needs at least {MIN_LOADS})"
            )
    return undecided


def check(configfiles: list[str], workflow_dir: Path = WORKFLOW_DIR) -> list[dict]:
    """Every selected sphere's plan (:func:`sphere_plan`), from the config in the working
    directory (config/config.yaml with ``configfiles`` merged over it)."""
    base = "config/config.yaml"
    config = read_config(base, *configfiles)
    run = WorkflowRun.from_config(config, workflow_dir, ", ".join([base, *configfiles]))
    return [sphere_plan(run, sphere) for sphere in run.spheres]


def _file_line(record: dict) -> str:
    path = record["path"]
    if "plane" in record:
        path += f" {record['plane']} = {record['load_mn']:g} mN"
    if "error" in record:
        return f"    {path}: UNREADABLE: {record['error']}"
    details = []
    if "shape" in record:
        details.append("×".join(map(str, record["shape"])) + " px")
    if record.get("pixel_nm") is not None:
        details.append(f"pixel {record['pixel_nm']:.4g} nm ({record['pixel_from']})")
    elif "pixel_nm" in record:
        details.append("NO PIXEL SIZE (neither the file nor the sheet gives one)")
    if "reader" in record:
        details.append(f"read as {record['reader']}")
    if "rows" in record:
        details.append(f"{record['rows']} rows")
    return f"    {path} [{record['format']}]: {', '.join(details)}"


def report(plans: list[dict]) -> str:
    """The plans as text, a block per sphere."""
    lines = []
    for plan in plans:
        lines.append(f"{plan['sphere']} ({plan['material']}, {plan['data']}): {plan['folder']}")
        lines.append(f"  loads (mN): {', '.join(f'{f:g}' for f in plan['loads_mn'])}")
        if plan["files"]:
            lines.append("  files:")
            lines += [_file_line(record) for record in plan["files"]]
        lines += [f"  STOPS THE RUN: {error}" for error in plan["errors"]]
        lines.append(f"  will make {len(plan['outputs'])} files:")
        lines += [f"    {path}" for path in plan["outputs"]]
        lines += [f"  will not make: {line}" for line in plan["left_out"]]
        lines += [f"  held out: {line}" for line in plan["failed"]]
        for scene, coverage in plan["scenes"].items():
            lines += [
                f"  {line}" for line in outside_scan_lines(scene, coverage, plan["scan_side_um"])
            ]
        lines += [f"  {line}" for line in plan["undecided_scans"].values()]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configfile", action="append", default=[], help="config overlay(s)")
    parser.add_argument("--workflow-dir", type=Path, default=WORKFLOW_DIR)
    parser.add_argument("--json", action="store_true", help="print the plans as JSON")
    args = parser.parse_args(argv)
    try:
        plans = check(args.configfile, args.workflow_dir)
    except (ConfigError, RawDataError) as error:
        print(f"the run would stop before any job: {error}", file=sys.stderr)
        return 1
    print(json.dumps(plans, indent=1) if args.json else report(plans))
    return 1 if any(plan["errors"] for plan in plans) else 0


if __name__ == "__main__":
    sys.exit(main())
