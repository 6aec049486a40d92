"""Time the scenes' load-area fits as the workflow runs them: one process per sphere
(rule fit_sphere_scenes) against one process per scene (the rule it replaced), alternating.

Each process is a job's: a fresh interpreter that imports scripts/fit_scenes.py and fits its
scenes from a run's solve.json and render.csv files. A fit takes milliseconds; the rest is
the process's start and its imports (statsmodels, pandas), which the per-scene jobs pay once
a scene and the per-sphere jobs once a sphere (docs/study.md §5). The per-scene side runs the
same script with one scene a process: what the rule it replaced imported and fitted.
Snakemake's own start of each job is not included. The two sides alternate, per-scene first.

It reads a run made with rule fit_sphere_scenes: the spheres' scene_fits.json name their
scenes. The confidence is 0.95, config/config.yaml's load_area.confidence.

    python benchmarks/bench_fit_jobs.py --results results/full --repeats 3
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
# A job's script, run in a fresh interpreter: the layout in, the fits written to a scratch file.
JOB = (
    "import json, runpy, sys; "
    "main = runpy.run_path(sys.argv[1])['main']; "
    "main(json.loads(sys.argv[2]), sys.argv[3], 0.95)"
)


def sphere_layouts(results: Path) -> dict[str, dict[str, dict[str, str]]]:
    """Each sphere's scenes with their files, from the fits files of a run (sphere folder →
    scene → {"solve", "render" where the scene was rendered})."""
    layouts = {}
    for fits in sorted(results.glob("*/*/scenes/scene_fits.json")):
        folder = fits.parent
        layout = {}
        for scene in json.loads(fits.read_text()):
            layout[scene] = {"solve": str(folder / scene / "solve.json")}
            render = folder / scene / "render.csv"
            if render.exists():
                layout[scene]["render"] = str(render)
        layouts[str(folder)] = layout
    if not layouts:
        raise SystemExit(f"{results}: no <material>/<sphere>/scenes/scene_fits.json to time")
    return layouts


def run_jobs(layouts: list[dict], out: str) -> float:
    """Wall time (s) of one process per layout, one after the other."""
    script = str(REPO / "scripts" / "fit_scenes.py")
    start = time.perf_counter()
    for layout in layouts:
        subprocess.run(
            [sys.executable, "-c", JOB, script, json.dumps(layout), out],
            check=True,
            capture_output=True,
        )
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--results", default="results/full", help="a run's results folder")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    spheres = sphere_layouts(Path(args.results))
    per_sphere = list(spheres.values())
    per_scene = [{scene: files} for layout in per_sphere for scene, files in layout.items()]
    print(f"{len(per_sphere)} spheres, {len(per_scene)} scenes; load {os.getloadavg()[0]:.2f}")
    times = {"per scene": [], "per sphere": []}
    with tempfile.TemporaryDirectory() as scratch:
        out = f"{scratch}/scene_fits.json"
        for round_ in range(args.repeats):
            for name, jobs in (("per scene", per_scene), ("per sphere", per_sphere)):
                times[name].append(run_jobs(jobs, out))
                print(f"round {round_}: {len(jobs):3d} jobs {name}: {times[name][-1]:.1f} s")
    scene, sphere = (statistics.median(times[k]) for k in ("per scene", "per sphere"))
    print(f"median: per scene {scene:.1f} s, per sphere {sphere:.1f} s ({scene / sphere:.1f}x);"
          f" load {os.getloadavg()[0]:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
