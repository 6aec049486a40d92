"""A whole parameter scan on the GPU against the same scan on the CPU (issue 50).

Two steps, because the device machine has the solver's dependencies but not Snakemake:

``prepare`` (here, in a finished run's folder): the jobs of one sphere's scan as the
workflow builds them (``amontons.workflow``: the same params and inputs as rule
scan_scene), with every input file copied into a bundle folder and the paths rewritten
into it, written as ``jobs.json``;

``run`` (on the device): every value of the bundle's scan in its chain order, each
starting from the one before as in a run, through ``scripts/scan_scene.py``'s own
``solve_value`` once with ``solver_backend: cupy`` and once on the CPU solver with
``--threads``, then the best value of each (``amontons.simulate.scan_best``, as rule
best_scan_value). Prints per value its wall time in the scan job and the solves'
(``wall_time_s``), the criterion D
of both and their difference, the totals, their ratio and the two best values.

    python benchmarks/bench_gpu_scan.py prepare --run-dir /path/to/a/full/run \\
        --sphere PS --scan p_y --out .scan_bundle
    python benchmarks/bench_gpu_scan.py run --bundle .scan_bundle --threads 16 \\
        --backends cupy cpu
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shutil
import statistics
import time
from pathlib import Path
from types import SimpleNamespace

import yaml

from amontons.simulate import solve
from amontons.simulate.scan_best import ScanPoint, best_scan_value, log_area_scatter

# numpy-array: the GPU route's code on numpy, to try this script on a machine without a GPU
# (the workflow's config offers cpu and cupy only)
TRY_BACKEND = "numpy-array"

REPO = Path(__file__).resolve().parents[1]


def _scan_script():
    """``scripts/scan_scene.py`` as a module (its ``main`` is what rule scan_scene runs)."""
    spec = importlib.util.spec_from_file_location("scan_scene", REPO / "scripts/scan_scene.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def prepare(run_dir: Path, sphere: str, scan: str, out: Path) -> None:
    """Write ``out/jobs.json`` and ``out/files/``: the scan's jobs as the workflow builds them
    in ``run_dir`` (a run of config/config.yaml), inputs copied."""
    from amontons.workflow.params import image_choice, otsu_settings
    from amontons.workflow.run import WorkflowRun

    os.chdir(run_dir)
    config = yaml.safe_load(Path("config/config.yaml").read_text())
    run = WorkflowRun.from_config(config, REPO / "workflow", "config/config.yaml")
    spheres, scenes, paths = run.spheres, run.scenes, run.paths
    material = spheres.rows.material_of(sphere)
    base_scene = scenes.scans[scan]["scene"]
    wildcards = SimpleNamespace(material=material, sphere=sphere, scan=scan)
    registration_scene = scenes.registration_scene(sphere, scan)
    inputs = {
        "levelled": paths.measured("afm_before_levelled.h5", material, sphere),
        "psf": paths.measured("psf.json", material, sphere),
        "registration": paths.scene("registration.json", material, sphere, registration_scene),
        "fluorescence": spheres.per_load_inputs(sphere, "fluorescence"),
        "pixel_table": spheres.image_pixel_inputs(sphere),
    }
    if out.exists():
        shutil.rmtree(out)
    (out / "files").mkdir(parents=True)
    copied = {key: _copy_into(value, out / "files") for key, value in inputs.items()}
    job = {
        "scan": scenes.scan_params(sphere, scan),
        "base_config": scenes.config(base_scene),
        "sphere": sphere,
        "sphere_record": spheres.scene_record(sphere),
        "pixel_nm": spheres.pixel_nm(sphere),
        "images": spheres.fluorescence_choice(sphere, image_choice(config)),
        "otsu": otsu_settings(config),
    }
    judge = {"confidence": config["load_area"]["confidence"]}
    chain = scenes.scan_chain(wildcards.sphere, scan)
    record = {"inputs": copied, "job": job, "judge": judge, "chain": chain}
    (out / "jobs.json").write_text(json.dumps(record, indent=1, default=_plain))
    print(f"{sphere} {scan}: {len(chain)} values {chain}; bundle {out}")


def _plain(value):
    """JSON for the config's non-JSON leaves (numpy scalars)."""
    return value.item() if hasattr(value, "item") else str(value)


def _copy_into(value, folder: Path):
    """Copy a path (or a list of them, or a folder) into ``folder``; the copy's path
    relative to the bundle."""
    if isinstance(value, list):
        return [_copy_into(v, folder) for v in value]
    source = Path(value)
    target = folder / source.as_posix().replace("/", "__")
    if source.is_dir():
        shutil.copytree(source, target)
    else:
        shutil.copy2(source, target)
    return str(target.relative_to(folder.parent))


def _in_bundle(value, bundle: Path):
    if isinstance(value, list):
        return [_in_bundle(v, bundle) for v in value]
    return str(bundle / value)


def run_scan(bundle: Path, backend: str, threads: int, work: Path) -> list[dict]:
    """Every value of the bundle's scan on ``backend`` (``cpu`` or ``cupy``), in chain
    order, as the scan job solves them (its inputs read once, each value from the one
    before); each value's wall time (s) and its point record."""
    spec = json.loads((bundle / "jobs.json").read_text())
    inputs = {k: _in_bundle(v, bundle) for k, v in spec["inputs"].items()}
    script = _scan_script()
    context = script.ScanContext(
        levelled_path=inputs["levelled"],
        psf_path=inputs["psf"],
        registration_path=inputs["registration"],
        fluorescence=inputs["fluorescence"],
        pixel_table=inputs["pixel_table"],
        threads=threads,
        solver_backend=backend,
        **spec["job"],
    )
    rows, previous = [], script.ScanStart()
    for value in spec["chain"]:
        folder = work / backend / value
        folder.mkdir(parents=True, exist_ok=True)
        start = time.perf_counter()
        previous = script.solve_value(
            context,
            float(value),
            str(folder / "scan_point.json"),
            str(folder / "rendered.h5"),
            previous,
        )
        wall = time.perf_counter() - start
        point = json.loads((folder / "scan_point.json").read_text())
        rows.append({"value": value, "value_s": wall, "point": point, "path": folder})
        print(f"{backend} {value}: value {wall:.2f} s, solves {point.get('wall_time_s')} s, "
              f"D {point['log_area_distance']}", flush=True)  # fmt: skip
    return rows


def best_value(rows: list[dict], confidence: float) -> dict:
    """The scan's grid best and refined estimate, as rule best_scan_value finds them."""
    records = sorted((row["point"] for row in rows), key=lambda r: r["value"])
    solved = [r for r in records if r["outside_window"] is None]
    measured = [row for row in solved[0]["loads"] if row["measured_contact_found"]]
    scatter = log_area_scatter(
        [row["load_mn"] for row in measured], [row["measured_area_um2"] for row in measured]
    )
    points = [
        ScanPoint(r["value"], r["log_area_distance"], r["iou_largest"], r["area_ratio_largest"])
        if r["outside_window"] is None
        else ScanPoint(r["value"], float("inf"), 0.0, float("inf"))
        for r in records
    ]
    best = best_scan_value(points, scatter, len(measured), confidence)
    return {"grid best": best.value, "refined": best.refined}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("prepare", help="write a scan's jobs and inputs into a bundle (here)")
    p.add_argument("--run-dir", type=Path, required=True, help="a finished run's folder")
    p.add_argument("--sphere", default="PS")
    p.add_argument("--scan", default="p_y")
    p.add_argument("--out", type=Path, default=REPO / ".scan_bundle")
    r = sub.add_parser("run", help="the bundle's scan on each backend (on the device)")
    r.add_argument("--bundle", type=Path, default=REPO / ".scan_bundle")
    r.add_argument("--backends", nargs="+", default=["cupy", "cpu"])
    r.add_argument("--threads", type=int, default=os.cpu_count(), help="the CPU solver's")
    r.add_argument("--work", type=Path, default=Path("/tmp/gpu-scan"))
    r.add_argument(
        "--rounds", type=int, default=2, help="scans per backend, alternating; the last counts"
    )
    args = ap.parse_args()
    if args.command == "prepare":
        prepare(args.run_dir.resolve(), args.sphere, args.scan, args.out.resolve())
        return
    bundle = args.bundle.resolve()
    if TRY_BACKEND in args.backends:
        solve.SOLVER_BACKENDS[TRY_BACKEND] = TRY_BACKEND
    spec = json.loads((bundle / "jobs.json").read_text())
    totals = {}
    results = {}
    # the first round compiles the kernels and plans the transforms; the last is reported
    for _ in range(args.rounds):
        for backend in args.backends:
            results[backend] = run_scan(bundle, backend, args.threads, args.work)
    for backend, rows in results.items():
        totals[backend] = {
            "values s": sum(row["value_s"] for row in rows),
            "solves s": sum(row["point"].get("wall_time_s") or 0.0 for row in rows),
            "median value s": statistics.median(row["value_s"] for row in rows),
            "best": best_value(rows, spec["judge"]["confidence"]),
        }
    print("\nvalue | " + " | ".join(f"{b} value s | {b} solves s | {b} D" for b in results))
    for i, value in enumerate(spec["chain"]):
        cells = []
        for rows in results.values():
            point = rows[i]["point"]
            cells += [f"{rows[i]['value_s']:.2f}", str(point.get("wall_time_s")),
                      str(point["log_area_distance"])]  # fmt: skip
        print(f"{value} | " + " | ".join(cells))
    for backend, total in totals.items():
        print(backend, json.dumps(total))
    if len(results) == 2:
        (a, ra), (b, rb) = results.items()
        diffs = [
            abs(x["point"]["log_area_distance"] - y["point"]["log_area_distance"])
            for x, y in zip(ra, rb, strict=True)
            if x["point"]["log_area_distance"] is not None
            and y["point"]["log_area_distance"] is not None
        ]
        print(f"largest |D {a} - D {b}|: {max(diffs) if diffs else None}")
        jobs = totals[b]["values s"] / totals[a]["jobs s"]
        solves = totals[b]["solves s"] / max(totals[a]["solves s"], 1e-9)
        print(f"jobs {b} / {a}: {jobs:.2f}; solves {b} / {a}: {solves:.2f}")
        same = totals[a]["best"]["grid best"] == totals[b]["best"]["grid best"]
        print(f"same best value: {same} ({totals[a]['best']} and {totals[b]['best']})")


if __name__ == "__main__":
    main()
