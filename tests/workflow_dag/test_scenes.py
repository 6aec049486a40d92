"""The expansion of scenes, scans and the study into the files the DAG schedules, on the
shipped small config: only what a scene names, one job per sphere and scan that solves its
values in a chain."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import tifffile

from amontons.io.tiff import write_image
from amontons.models import parameter_named
from amontons.simulate.scan_grid import scan_values, value_label
from amontons.workflow.paths import FIELDS, RENDERED, SCAN_POINT


def _wildcards(**values):
    return SimpleNamespace(**values)


def test_only_microscope_scenes_deliver_a_comparison(small):
    scenes = small.scenes
    with_optics = scenes.names(surface="afm_before", optics="microscope")
    without = scenes.names(surface="afm_before", optics="none")
    assert with_optics and without
    sphere = next(iter(small.spheres))
    material = small.spheres.rows.material_of(sphere)
    assert scenes.sphere_scene_outputs(material, sphere, without[0]) == []
    outputs = scenes.sphere_scene_outputs(material, sphere, with_optics[0])
    names = sorted(path.rsplit("/", 1)[1] for path in outputs)
    assert names == ["comparison.csv", "comparison.pdf", "comparison.png", "registration.json"]


def test_a_spheres_scenes_are_fitted_in_one_file_reading_renders_only_with_optics(small):
    """One fits file per sphere, beside its scenes' folders, delivered with them; each scene
    reads its solve and, with optics only, its rendered areas."""
    scenes = small.scenes
    sphere = next(iter(small.spheres))
    material = small.spheres.rows.material_of(sphere)
    layout = scenes.fit_layout(material, sphere)
    assert list(layout) == scenes.runnable(sphere) and len(layout) > 1
    for name, inputs in layout.items():
        assert inputs["solve"].endswith(f"/{sphere}/scenes/{name}/solve.json")
        assert ("render" in inputs) == scenes.has_optics(name)
    fits = scenes.fits_file(material, sphere)
    assert fits.endswith(f"/{material}/{sphere}/scenes/scene_fits.json")
    assert fits in scenes.outputs([material])
    assert scenes.table_layout(material)[sphere] == fits


def test_greenwood_tripp_is_the_one_model_without_fields(small):
    scenes = small.scenes
    fields = set(scenes.names(field=True))
    gt = set(scenes.names(field=False))
    assert fields.isdisjoint(gt) and fields | gt == set(scenes.scenes)
    assert all(scenes.scenes[name]["model"] == "greenwood_tripp" for name in gt)


def test_a_scan_has_one_point_per_value_around_the_sheets_prior(small):
    scenes = small.scenes
    assert scenes.scans
    sphere = next(iter(small.spheres))
    for scan, spec in scenes.scans.items():
        prior = small.spheres.rows.row(sphere)[parameter_named(spec["parameter"]).sheet_column]
        expected = scan_values(prior, spec["range_factor"], spec["steps"], spec["spacing"])
        labels = scenes.scan_value_labels(sphere, scan)
        assert labels == [value_label(v) for v in expected]
        assert len(labels) == spec["steps"]
        wildcards = _wildcards(
            material=small.spheres.rows.material_of(sphere), sphere=sphere, scan=scan
        )
        points = scenes.scan_points(wildcards)
        assert [p.split("/")[-2] for p in points] == labels


def test_a_scans_values_run_as_one_chain_each_from_the_one_before(small):
    """A sphere's scan job solves every value once, in its parameter's chain order (from the largest
    value down, or the smallest up), and writes each value's files into a folder of its own
    inside the job's output folder, where best_scan_value reads the results."""
    scenes = small.scenes
    sphere = next(iter(small.spheres))
    material = small.spheres.rows.material_of(sphere)
    for scan, spec in scenes.scans.items():
        wildcards = _wildcards(material=material, sphere=sphere, scan=scan)
        chain = scenes.scan_chain(sphere, scan)
        assert sorted(chain, key=float) == sorted(scenes.scan_value_labels(sphere, scan), key=float)
        descending = parameter_named(spec["parameter"]).chain_order < 0
        assert [float(v) for v in chain] == sorted(map(float, chain), reverse=descending)
        value_files = scenes.scan_value_files(wildcards)
        assert [entry["value"] for entry in value_files] == chain
        folder = scenes.scan_values_folder(wildcards)
        for entry in value_files:
            assert entry["point"] == f"{folder}/{entry['value']}/{SCAN_POINT}"
            assert entry["rendered"] == f"{folder}/{entry['value']}/{RENDERED}"
        assert sorted(scenes.scan_points(wildcards)) == sorted(e["point"] for e in value_files)


def test_a_chain_from_the_elastic_end_starts_from_the_spheres_elastic_solve(small):
    """A scan whose chain starts at its largest value, where the model tends to the elastic
    contact, reads the sphere's elastic scene's fields (its first value's start); one that
    starts at the other end reads nothing more. The elastic scene's comparison registers the
    sphere, and the scan's own registration waits for it: the seed adds no wait."""
    scenes = small.scenes
    sphere = next(iter(small.spheres))
    material = small.spheres.rows.material_of(sphere)
    elastic = [s for s in scenes.runnable(sphere) if scenes.scenes[s]["model"] == "elastic"]
    assert elastic and scenes.sphere_registration_scene(sphere) == elastic[0]
    for scan, spec in scenes.scans.items():
        wildcards = _wildcards(material=material, sphere=sphere, scan=scan)
        seed = scenes.scan_seed_fields(wildcards)
        if parameter_named(spec["parameter"]).chain_order < 0:
            assert seed == [small.paths.scene(FIELDS, material, sphere, elastic[0])]
        else:
            assert seed == []


def test_a_sphere_without_an_elastic_scene_starts_its_scans_from_nothing(make_run):
    def drop_elastic(config):
        scenes = config["scenes"]
        config["run_scenes"] = [
            s
            for s in config["run_scenes"]
            if (scenes[s]["model"], scenes[s]["surface"]) != ("elastic", "afm_before")
        ]

    run = make_run(edit=drop_elastic)
    sphere = next(iter(run.spheres))
    for scan in run.scenes.scans:
        assert run.scenes.scan_seed_scene(sphere, scan) is None


def test_without_scans_there_is_no_scan_and_no_study_output(make_run):

    def drop_scans(config):
        config["run_scans"] = []

    run = make_run(edit=drop_scans)
    assert run.scenes.scan_outputs(run.materials) == []
    assert run.study.outputs(run.materials) == []
    assert run.study.k_bests(run.materials) == {}
    assert not any("B13" in path for path in run.study.overview_outputs())


def test_the_study_figures_of_a_sphere_follow_its_scans_and_scenes(small):
    sphere = next(iter(small.spheres))
    material = small.spheres.rows.material_of(sphere)
    names = {
        p.rsplit("/", 1)[1].split(".")[0] for p in small.study.sphere_figures(material, sphere)
    }
    expected = {"B8_scans", "B12_models", "B9_flattening"}
    if small.scenes.first("elastic", "microscope") and small.scenes.first("greenwood_tripp"):
        expected.add("B11_load_series")
    assert names == expected


def test_a_material_target_holds_lifetime_only_where_a_flim_map_exists(small):
    targets = small.targets.material(small.materials)
    for sphere in small.spheres:
        lifetime = small.paths.measured(
            "lifetime.json", small.spheres.rows.material_of(sphere), sphere
        )
        assert (lifetime in targets) == small.spheres.files.has_flim(sphere)
    assert len(targets) == len(set(targets))


def test_a_measurement_of_a_sphere_under_another_material_is_refused(small):
    sphere = next(iter(small.spheres))
    others = [m for m in small.materials if m != small.spheres.rows.material_of(sphere)]
    with pytest.raises(ValueError, match=f"sphere '{sphere}' is"):
        small.targets.measured(others[0], sphere, "psf.json")


def test_a_scan_without_a_prior_runs_over_its_dimensionless_range(make_run, tmp_path):
    sheet = tmp_path / "sheet.tsv"
    lines = Path("config/materials.tsv").read_text().splitlines()
    header = lines[0].split("\t")
    rows = [line.split("\t") for line in lines[1:]]
    for row in rows:
        if row[0] == "PS":
            row[header.index("hardening_k_mpa_per_nm")] = ""
            row[header.index("hardness_mpa")] = ""
            row[header.index("data_source")] = str(tmp_path)  # measured: no virtual truth needed
    sheet.write_text("\n".join("\t".join(r) for r in [header, *rows]) + "\n")
    for name in ("reflection.tif", "bead.tif", "absorbance.csv", "afm_before.tif", "afm_after.tif"):
        (tmp_path / name).write_text("")  # found, never read: the DAG only looks for them
    (tmp_path / "rheometer").mkdir()
    run = make_run(edit=lambda config: config.update(materials_sheet=str(sheet)))
    with_prior = make_run()
    e_star_mpa = 3.7e3
    for scan, spec in run.scenes.scans.items():
        low, high = spec["prior_free_range"]
        scale = run.scenes.prior_free_scale("PS", scan)
        values = [float(v) for v in run.scenes.scan_value_labels("PS", scan)]
        assert len(values) == spec["prior_free_steps"]
        assert values[0] == pytest.approx(low * scale, rel=1e-3)
        assert values[-1] == pytest.approx(high * scale, rel=1e-3)
        prior = [float(v) for v in with_prior.scenes.scan_value_labels("PS", scan)]
        # the prior-free range holds the range about the prior
        assert values[0] < prior[0] and prior[-1] < values[-1]
        params = run.scenes.scan_params("PS", scan)
        assert "prior_free_range" in params and "range_factor" not in params
        assert "prior_free_range" not in with_prior.scenes.scan_params("PS", scan)
    assert run.scenes.prior_free_scale("PS", "p_y") == pytest.approx(e_star_mpa)
    # k's scale is E*/Δx, Δx the hardening scene's solver pixel on PS
    hardening = with_prior.resources.solve_size("hardening", "PS")[1]
    assert hardening["side_px"] > 0
    # the scans register on the elastic scene, the first microscope scene PS still runs
    assert run.scenes.registration_scene("PS", "k") == "elastic"
    assert with_prior.scenes.registration_scene("PS", "k") == "hardening"
    # the sphere's registration is found on that scene, and every other scene reads it
    assert run.scenes.sphere_registration_scene("PS") == "elastic"
    where = {"material": "PS", "sphere": "PS"}
    assert run.scenes.sphere_registration(SimpleNamespace(scene="elastic", **where)) == []
    assert run.scenes.sphere_registration(SimpleNamespace(scene="hardening", **where)) == [
        run.paths.scene("registration.json", "PS", "PS", "elastic")
    ]
    lines = [line for line in run.left_out() if line.startswith("sphere PS ")]
    assert any(
        "scan k runs over its prior-free range (k·Δx/E* 0.01 to 100" in line for line in lines
    )
    assert any("scene hardening (k_mpa_per_nm null" in line for line in lines)


def test_the_dag_reads_a_tiff_scans_size_and_names_the_loads_it_leaves_out(measured_ps, tmp_path):
    """A 50 µm TIFF scan of the PS sphere (the size of test_own_data's cut scan): the dry run's
    lines are the loads whose window exceeds the scan, the same as the check command's
    coverage of that side (apex at the centre); a scan that holds every load names none, and
    a map whose header gives no pixel (nor the sheet) is left to its job."""
    afm = tmp_path / "lab" / "PS" / "afm_before.tif"
    write_image(afm, np.zeros((1250, 1250), dtype=np.float32), 40e-9)  # 50 µm
    run = measured_ps()
    assert run.scenes.header_scan_side_um("PS") == pytest.approx(50.0, rel=1e-12)
    coverage = run.scenes.scan_coverage("PS", 50.0)
    left_out = {s: [r["load_mn"] for r in c["outside_scan"]] for s, c in coverage.items()}
    assert left_out["elastic"] and coverage["elastic"]["simulated_mn"]  # some out, some kept
    for scene, entry in coverage.items():
        assert all(row["window_um"] > 50.0 for row in entry["outside_scan"]), scene
    lines = run.outside_scan()
    outside = [line for line in lines if "mN outside_scan" in line]
    clipped = [line for line in lines if "window clipped from" in line]
    assert len(outside) == sum(map(len, left_out.values()))
    assert len(outside) + len(clipped) == len(lines)
    for line in outside:
        assert line.startswith("sphere PS (PS): scene ") and "µm exceeds the 50.0 µm scan" in line
    # a scene whose kept loads' own window exceeds the scan says it will be clipped
    # hardening's window is 1.5 × the Hertz diameter: 100 mN's 55 µm is clipped to the scan
    assert coverage["hardening"]["clipped_from_um"] > 50.0
    assert len(clipped) == sum(c["clipped_from_um"] is not None for c in coverage.values())
    for line in clipped:
        assert line.startswith("sphere PS (PS): scene ") and "to the 50.0 µm scan for" in line
    assert any(
        line.startswith("sphere PS (PS): scene elastic: 300 mN outside_scan") for line in lines
    )
    write_image(afm, np.zeros((5000, 5000), dtype=np.float32), 40e-9)  # 200 µm
    assert measured_ps().outside_scan() == []
    tifffile.imwrite(afm, np.zeros((1250, 1250), dtype=np.float32))  # no pixel stated
    assert measured_ps().scenes.header_scan_side_um("PS") is None
