"""Rule scan_scene: one value of a parameter scan (docs/study.md). The base scene with its
parameter set to the value, solved over the measured loads, each load starting from the
neighbouring value's pressure at that load (the value before it in the scan's chain;
amontons.simulate.scan_start) or else from the previous load, rendered like the microscope
sees it, and compared with the measured contact under the base scene's registration. Its
own pressures are the next value's start."""

import logging
import os

if "snakemake" in globals():
    # The contact solve's BLAS calls spin OpenBLAS threads beyond the rule's (benchmarks/README)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", str(snakemake.threads))  # noqa: F821

from amontons.contact import FreeBoundaryError
from amontons.io.fields import write_load_series
from amontons.io.files import read_json, write_json
from amontons.io.rawdata import fluorescence_planes, read_fluorescence_series
from amontons.io.units import optional_nm_to_m
from amontons.measure.area import OtsuSettings, image_contact_area, image_pixel_m
from amontons.runlog import run_logged
from amontons.simulate.compare import compare_loads, sheet_load_index
from amontons.simulate.register import Registration
from amontons.simulate.render import render_load_series
from amontons.simulate.scan import log_area_distance, scene_config_at
from amontons.simulate.scan_start import read_scan_start, write_scan_start
from amontons.simulate.solve import solve_scene
from amontons.simulate.surface import afm_indenter, afm_scene, load_levelled_map

log = logging.getLogger(__name__)


def main(
    levelled_path: str,
    psf_path: str,
    registration_path: str,
    fluorescence,
    neighbour_path: str | None,
    fields_path: str,
    point_path: str,
    start_path: str,
    scan: dict,
    base_config: dict,
    value: float,
    sphere: str,
    sphere_record: dict,
    pixel_nm: float | None,
    pixel_table: list[str],
    images: dict,
    otsu: dict,
    threads: int,
    solver_backend: str = "cpu",
) -> None:
    config = scene_config_at(base_config, scan["parameter"], value)
    levelled = load_levelled_map(levelled_path)
    scene, coverage = afm_scene(scan["scene"], config, sphere, sphere_record, levelled)
    covered = coverage.to_record()
    record = {
        "sphere": sphere,
        "scene": scan["scene"],
        "parameter": scan["parameter"],
        "value": value,
        "outside_scan": covered["outside_scan"],
    }
    if "window_clipped" in covered:  # the scan clipped the window: say by how much
        record["window_clipped"] = covered["window_clipped"]
    if scene is None:
        # The window does not depend on the scanned parameter: no value has a load to solve,
        # and best_scan_value says so.
        log.warning("%s = %g: the AFM scan holds no load's window", scan["parameter"], value)
        write_load_series(fields_path, [], [], record)
        write_scan_start(start_path, [], [], None, value)
        # the scan's size and the largest window in it: what best_scan_value says why with
        write_json(point_path, {**record, **covered, "log_area_distance": None,
                                "outside_window": None, "loads": []})  # fmt: skip
        return
    indenter = afm_indenter(levelled, scene, levelled_path)
    starts = None
    if neighbour_path is not None:
        starts, started = read_scan_start(
            neighbour_path, scene.loads_n, indenter.heights.shape, indenter.spacing_m
        )
        log.info("%s = %g: %d of %d loads start from the neighbouring value", scan["parameter"],
                 value, started, len(scene.loads_n))  # fmt: skip
    try:
        solution = solve_scene(
            scene, indenter, threads=threads, backend=solver_backend, warm_starts=starts
        )
    except FreeBoundaryError as error:
        # A value so soft that the contact outgrows the base scene's window (which holds the
        # measured contact with room to spare) matches the measurement worse than any value
        # whose contact fits: recorded, never best, and the run goes on.
        log.warning("%s = %g: %s", scan["parameter"], value, error)
        write_load_series(fields_path, [], [], {**scene.to_record(), **record})
        write_scan_start(start_path, [], [], None, value)
        write_json(point_path, {**record, "log_area_distance": None, "outside_window": str(error)})
        return
    write_scan_start(
        start_path,
        scene.loads_n,
        [f["pressure"] for f in solution.fields],
        indenter.spacing_m,
        value,
    )
    settings = OtsuSettings.from_config(otsu)
    pixel_m = image_pixel_m(pixel_nm, pixel_table)
    rendered = render_load_series(
        solution.fields,
        scene.pixel_m,
        pixel_m=pixel_m,
        psf_fwhm_m=read_json(psf_path)["fwhm_nm"]["estimate"] * 1e-9,
        rendering=config["rendering"],
        confinement_floor_pa=config["confinement_floor_mpa"] * 1e6,
        otsu=settings,
    )
    sheet_mn = [float(f) for f in sphere_record["loads"]]  # the files are named by these
    simulated = [sheet_load_index(sheet_mn, f * 1e3) for f in scene.loads_n]
    loads_mn = [sheet_mn[i] for i in simulated]
    files, choices = fluorescence_planes(fluorescence, sheet_mn, images)
    images = read_fluorescence_series(
        [files[i] for i in simulated],
        optional_nm_to_m(pixel_nm),
        [choices[i] for i in simulated],
    )
    measured = [image_contact_area(image, settings) for image in images]
    rows = compare_loads(
        [f * 1e-3 for f in loads_mn],
        rendered,
        measured,
        [row["area_um2"] * 1e-12 for row in solution.per_load],
        Registration.from_record(read_json(registration_path)),
        pixel_m,
    )
    used = [row for row in rows if row.measured_found]
    distance = log_area_distance(
        [row.simulated_area_m2 for row in used], [row.measured_area_m2 for row in used]
    )
    log.info("%s = %g: D = %.4f over %d loads", scan["parameter"], value, distance, len(used))
    last = solution.fields[-1]
    fields = [{"image": r.image} for r in rendered]
    fields[-1] |= {
        "plastic_displacement": last["plastic_displacement"].astype("float32"),
        "deformed_heights": last["deformed_heights"].astype("float32"),
    }
    write_load_series(
        fields_path,
        fields,
        [
            {"load_mn": f, "otsu_threshold": r.otsu.threshold}
            for f, r in zip(loads_mn, rendered, strict=True)
        ],
        {
            **scene.to_record(),
            "parameter": scan["parameter"],
            "value": value,
            "image_pixel_nm": pixel_m * 1e9,
            "window_centre_in_scan_um": [c * 1e6 for c in indenter.centre_in_scan_m],
        },
    )
    write_json(
        point_path,
        {
            **record,
            "log_area_distance": distance,
            "outside_window": None,
            "loads_used": len(used),
            "iou_largest": rows[-1].iou,
            "area_ratio_largest": rows[-1].area_ratio,
            "wall_time_s": solution.wall_time_s,
            "loads": [
                {
                    **row.to_record(),
                    **{k: info[k] for k in ("iterations", "outer_iterations", "convolutions")},
                }
                for row, info in zip(rows, solution.per_load, strict=True)
            ],
        },
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        levelled_path=sm.input.levelled,
        psf_path=sm.input.psf,
        registration_path=sm.input.registration,
        fluorescence=sm.input.fluorescence,
        neighbour_path=sm.input.warm_start[0] if sm.input.warm_start else None,
        fields_path=sm.output.fields,
        point_path=sm.output.point,
        start_path=sm.output.start,
        scan=sm.params.scan,
        base_config=sm.params.base,
        value=float(sm.wildcards.value),
        sphere=sm.wildcards.sphere,
        sphere_record=sm.params.sphere_record,
        pixel_nm=sm.params.pixel_nm,
        pixel_table=list(sm.input.pixel_table),
        images=sm.params.images,
        otsu=sm.params.otsu,
        threads=sm.threads,
        solver_backend=sm.params.get("solver_backend", "cpu"),
    )
