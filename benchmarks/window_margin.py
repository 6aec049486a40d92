"""How close a rough sphere's contact may come to the solver window's edge before its area
changes: the margin a window clipped to a small AFM scan must keep (docs/simulate.md,
"Window and grid").

A scene's window is ``window_factor`` × the Hertz contact diameter at its largest load; a
window clipped to the scan holds less. With the accuracy study's problems and solves
(amontons.accuracy.problems), each load is solved as the largest of its series (the series up
to it: contact hardening carries the plastic history of the loads before) on windows of
``--factors`` × its own Hertz diameter, and its true contact area (pixels in contact) is
compared with the same series solved on the widest window the map holds about the apex
(``--reference`` × the Hertz diameter at the sphere's largest load). A contact that reaches
the window's edge is refused by the solver (FreeBoundaryError) and counts as over every
budget. The margin for a budget is the smallest window / Hertz diameter from which on every
load of both models changed its area by no more than the budget.

    python benchmarks/window_margin.py --levelled results/small/PS/PS/measure/afm_before_levelled.h5

The levelled map is the pipeline's (rule level_afm_map); ``--sphere`` names its sheet row.
Prints one row per (model, factor, load) and the margin per budget. Wall times are not the
point here; the solves run on one thread.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
from pathlib import Path

import numpy as np

from amontons.accuracy.problems import solve_problem, sphere_problem
from amontons.accuracy.settings import Setting
from amontons.config.schema import load_schema
from amontons.config.sheet import read_sample_sheet
from amontons.contact import FreeBoundaryError
from amontons.physics.hertz import contact_radius
from amontons.simulate.surface import load_levelled_map
from amontons.workflow.sheet_rows import SCENE_COLUMNS

REPO = Path(__file__).resolve().parents[1]
PROBLEMS = ("elastic_sphere", "hardening_sphere")


def contact_areas_m2(results, pixel_m: float) -> list[float]:
    """Each load's true contact area (m²): the pixels that carry pressure."""
    return [float(np.count_nonzero(r.pressure > 0)) * pixel_m**2 for r in results]


def solve_areas(problem_name, factor, args, levelled, record):
    """The series' areas (m²) on a window of ``factor`` × the Hertz diameter at its largest
    load, and the problem; None for the areas where the contact reaches the window's edge."""
    setting = Setting(args.pixel_factor, args.tol, factor, False)
    problem = sphere_problem(problem_name, setting, levelled, record, str(args.levelled))
    try:
        results, _ = solve_problem(problem, setting)
    except FreeBoundaryError:
        return None, problem
    return contact_areas_m2(results, problem.pixel_m), problem


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levelled", type=Path, required=True)
    parser.add_argument("--sheet", type=Path, default=REPO / "config" / "materials.tsv")
    parser.add_argument("--sphere", default="PS")
    parser.add_argument("--pixel-factor", type=int, default=4, help="× the AFM map's pixel")
    parser.add_argument("--tol", type=float, default=1e-6)
    parser.add_argument(
        "--factors", type=float, nargs="+", default=[1.0, 1.05, 1.1, 1.15, 1.2, 1.3, 1.5]
    )
    parser.add_argument("--reference", type=float, default=1.8)
    parser.add_argument("--budgets", type=float, nargs="+", default=[0.01, 0.02, 0.05])
    args = parser.parse_args()

    schema = load_schema(REPO / "workflow" / "schemas" / "materials.schema.yaml")
    row = read_sample_sheet(args.sheet, schema)[args.sphere]
    record = {**{key: row.get(key) for key in SCENE_COLUMNS}, "sphere": args.sphere}
    levelled = load_levelled_map(args.levelled)
    print(
        f"# {datetime.date.today()} {platform.node()} ({os.cpu_count()} cores, load "
        f"{os.getloadavg()[0]:.2f}); sphere {args.sphere}, map {args.levelled}, pixel "
        f"{args.pixel_factor} × {levelled.pixel_m * 1e9:.1f} nm, tol {args.tol:g}, reference "
        f"window factor {args.reference:g}"
    )
    print("model | load mN | window / its Hertz diameter | area change against the reference")
    radius = record["diameter_mm"] * 0.5e-3
    e_star = record["e_star_gpa"] * 1e9
    loads = list(record["loads"])
    largest = 2 * contact_radius(max(loads) * 1e-3, radius, e_star)
    points = []  # (window / Hertz diameter, |area change| or inf)
    for name in PROBLEMS:
        for k, load in enumerate(loads):
            series = {**record, "loads": loads[: k + 1]}
            diameter = 2 * contact_radius(load * 1e-3, radius, e_star)
            reference, _ = solve_areas(name, args.reference * largest / diameter, args,
                                       levelled, series)  # fmt: skip
            if reference is None:
                raise SystemExit(f"{name}: {load:g} mN reaches the reference window's edge")
            for factor in args.factors:
                areas, _ = solve_areas(name, factor, args, levelled, series)
                if areas is None:
                    change, text = float("inf"), "reaches the edge"
                else:
                    change = abs(areas[-1] / reference[-1] - 1.0)
                    text = f"{areas[-1] / reference[-1] - 1.0:+.2e}"
                points.append((factor, change))
                print(f"{name} | {load:g} | {factor:g} | {text}")
    points.sort()
    for budget in args.budgets:
        over = [ratio for ratio, change in points if change > budget]
        margin = next((r for r, _ in points if not over or r > max(over)), None)
        print(f"budget {budget:.0%}: margin (window / Hertz diameter) {margin}")


if __name__ == "__main__":
    main()
