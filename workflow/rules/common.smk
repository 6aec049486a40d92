# Helpers shared by the workflow files: validated config, the sample sheet and path lookups.
# They import only amontons.config and amontons.io.layout (no numerical stack), so that
# building the DAG stays fast.
import json
import os

from amontons.config import load_schema, load_workflow_config
from amontons.io.layout import (
    FLUORESCENCE_DIR,
    RHEOMETER_DIR,
    AFM_SUFFIXES,
    afm_file,
    fluorescence_images,
    rheometer_files,
)

SCHEMAS = os.path.join(workflow.basedir, "workflow", "schemas")
CONFIG_SOURCE = ", ".join(
    str(f) for f in (workflow.overwrite_configfiles or ["config/config.yaml"])
)
SPHERES = load_workflow_config(
    config,
    load_schema(os.path.join(SCHEMAS, "config.schema.yaml")),
    load_schema(os.path.join(SCHEMAS, "materials.schema.yaml")),
    CONFIG_SOURCE,
)
MATERIALS = list(config["materials"])

# Every run writes under its own name, so that the small data set never overwrites the
# full reproduction: raw data of the virtual experiment, results and logs.
RUN = config["run"]
RESULTS = f"results/{RUN}"
SYNTHETIC = f"resources/synthetic/{RUN}"
LOGS = f"logs/{RUN}"
# One sphere's measurements, and one material's figures and tables.
MEASURED = f"results/{RUN}/{{material}}/{{sphere}}/measure"
MATERIAL = f"results/{RUN}/{{material}}"
SPHERE_LOGS = f"logs/{RUN}/{{material}}/{{sphere}}"


def sphere_row(sphere):
    return SPHERES[sphere]


def spheres_of(material):
    return [s for s, row in SPHERES.items() if row["material"] == material]


def is_synthetic(sphere):
    return sphere_row(sphere)["data_source"] == "synthetic"


def raw_dir(sphere):
    """Folder of a sphere's raw data: the virtual experiment's, or the one the sheet names."""
    if is_synthetic(sphere):
        return f"{SYNTHETIC}/{sphere}"
    return sphere_row(sphere)["data_source"]


def loads_mn(sphere):
    return list(sphere_row(sphere)["loads"])


def sheet_value(sphere, column):
    """A numeric sheet value, or None where the cell is empty."""
    value = sphere_row(sphere).get(column)
    return None if value is None else float(value)


def pixel_nm(sphere):
    return float(sphere_row(sphere)["fluorescence_pixel_nm"])


def per_load_inputs(sphere, kind):
    """The per-load raw files of a sphere, 'fluorescence' or 'rheometer', in load order.

    Measured data: each load's file, matched to the sheet's loads here (a folder that does not
    match them stops the run, naming it), so that a replaced file re-runs the jobs that read
    it and the script reads exactly these files. Synthetic data: the folder, which the virtual
    experiment writes whole and names by load (amontons.io.layout.per_load_files)."""
    folder = f"{raw_dir(sphere)}/{FLUORESCENCE_DIR if kind == 'fluorescence' else RHEOMETER_DIR}"
    if is_synthetic(sphere):
        return folder
    files = fluorescence_images if kind == "fluorescence" else rheometer_files
    return [str(path) for path in files(folder, loads_mn(sphere))]


def reflection_fluorescence(sphere):
    """The one fluorescence image the edge gap reads: the one at the reflection load (for
    synthetic data, the folder the virtual experiment writes it into)."""
    load = sheet_value(sphere, "reflection_load_mn")
    if is_synthetic(sphere):
        return per_load_inputs(sphere, "fluorescence")
    images = per_load_inputs(sphere, "fluorescence")
    return images[[abs(load - f) < 1e-9 for f in loads_mn(sphere)].index(True)]


def raw_file(sphere, name):
    """Path of one raw file of a sphere (e.g. 'bead.tif')."""
    return f"{raw_dir(sphere)}/{name}"


def afm_path(sphere, stem):
    """A sphere's AFM height map ``stem`` (afm_before / afm_after): the virtual experiment
    writes TIFF; measured data may be TIFF, .npy or a Gwyddion text export (two formats of
    one map stop the run, naming both). With none present the TIFF is named, so the missing
    input is reported by that name."""
    folder = raw_dir(sphere)
    present = [ext for ext in AFM_SUFFIXES if os.path.isfile(f"{folder}/{stem}{ext}")]
    if is_synthetic(sphere) or not present:
        return raw_file(sphere, f"{stem}.tif")
    return str(afm_file(folder, stem))


def has_flim(sphere):
    """Synthetic spheres get a FLIM map where the sheet gives flim_load_mn; measured spheres
    have one where their folder holds flim.tif."""
    if is_synthetic(sphere):
        return sheet_value(sphere, "flim_load_mn") is not None
    return os.path.isfile(raw_file(sphere, "flim.tif"))


def flim_spheres_pattern(with_flim):
    """Regex matching the synthetic spheres with (or without) a FLIM map; never empty-match."""
    names = [s for s in SPHERES if is_synthetic(s) and has_flim(s) == with_flim]
    return "|".join(map(re.escape, names)) or "(?!)"


def measured(material, sphere, name):
    """A measurement of one sphere: results/<run>/<material>/<sphere>/measure/<name>."""
    if sphere_row(sphere)["material"] != material:
        raise ValueError(
            f"sphere {sphere!r} is {sphere_row(sphere)['material']}, not {material}"
        )
    return f"{MEASURED.format(material=material, sphere=sphere)}/{name}"


def material_results(material, name):
    """One measurement file per sphere of ``material``."""
    return [measured(material, s, name) for s in spheres_of(material)]


def sorted_keys(mapping):
    """``mapping`` with its keys (and those of nested mappings) in sorted order. Snakemake
    compares a job's params as written, key order included: sorted, a config overlay that
    lists its keys in another order re-runs nothing."""
    return {
        key: sorted_keys(value) if isinstance(value, dict) else value
        for key, value in sorted(mapping.items())
    }


def config_slice(*keys):
    """The config section at ``keys`` (e.g. "optics", "psf"), as a rule's params: only the
    slice the rule uses, so that a changed value re-runs exactly the jobs that use it.
    """
    section = config
    for key in keys:
        section = section[key]
    return sorted_keys(section)


def otsu_settings():
    """The optics keys that decide where a contact is and whether there is one."""
    return sorted_keys(
        {
            key: config["optics"][key]
            for key in ("otsu_bins", "min_separation", "min_contrast", "min_patch_px")
        }
    )


def ring_optics():
    """The light and the medium of the reflection image: the measurement and the virtual
    experiment read the same two keys."""
    rings = config["optics"]["newton_rings"]
    return sorted_keys(
        {key: rings[key] for key in ("wavelength_nm", "refractive_index")}
    )


def data_label(spheres):
    """'synthetic data' if any of the spheres comes from the virtual experiment."""
    return (
        "synthetic data" if any(is_synthetic(s) for s in spheres) else "measured data"
    )


# Per-sphere results of each stage; lifetime only where a FLIM map exists.
OPTICS_RESULTS = [
    "contact_area.csv",
    "contact_area.png",
    "contact_area.pdf",
    "psf.json",
    "psf.png",
    "psf.pdf",
    "grafting_density.json",
    "absorbance.png",
    "absorbance.pdf",
    "edge_gap.json",
    "edge_gap.png",
    "edge_gap.pdf",
    "intensity_pressure.csv",
    "intensity_pressure_fit.json",
    "intensity_pressure.png",
    "intensity_pressure.pdf",
    "hertz_check.csv",
]
FRICTION_RESULTS = ["friction.csv"]
SURFACE_RESULTS = ["topography.json", "topography.png", "topography.pdf"]
FIT_RESULTS = ["load_area_fit.json"]


def sphere_outputs(material, names):
    return [measured(material, s, n) for s in spheres_of(material) for n in names]


def material_figures(materials, names):
    """Per-material figures and tables ``names`` (PNG, PDF and CSV each)."""
    return [
        f"{MATERIAL.format(material=m)}/{name}.{ext}"
        for m in materials
        for name in names
        for ext in ("png", "pdf", "csv")
    ]


def optics_outputs(materials):
    """Every optical measurement of every sphere of ``materials``."""
    out = []
    for material in materials:
        out += sphere_outputs(material, OPTICS_RESULTS)
        out += [
            measured(material, s, "lifetime.json")
            for s in spheres_of(material)
            if has_flim(s)
        ]
    return out


def friction_outputs(materials):
    """Friction per sphere and the Amontons-deviation figure and table per material."""
    out = [f for m in materials for f in sphere_outputs(m, FRICTION_RESULTS)]
    return out + material_figures(materials, ["amontons"])


def figure_outputs(materials):
    """The per-material figures and tables: load-area and Amontons deviation."""
    return material_figures(materials, ["load_area", "amontons"])


def material_outputs(materials):
    """Everything a material's target builds: every measurement, fit, figure and table."""
    fits = [f for m in materials for f in sphere_outputs(m, FIT_RESULTS)]
    surface = [f for m in materials for f in sphere_outputs(m, SURFACE_RESULTS)]
    everything = (
        optics_outputs(materials)
        + surface
        + friction_outputs(materials)
        + fits
        + figure_outputs(materials)
        + scene_outputs(materials)
        + scan_outputs(materials)
        + study_outputs(materials)
    )
    return list(dict.fromkeys(everything))  # once each, in order


# Scenes (workflow/rules/simulate.smk): a scene on a sphere's AFM map runs for every sphere of
# every selected material; a synthetic scene runs once and reads nothing of the experiment.
SCENES = {name: config["scenes"][name] for name in config["run_scenes"]}
SCENE = f"results/{RUN}/{{material}}/{{sphere}}/scenes/{{scene}}"
SCENE_LOGS = f"logs/{RUN}/{{material}}/{{sphere}}/scenes/{{scene}}"
SYNTHETIC_SCENE = f"results/{RUN}/synthetic/scenes/{{scene}}"
SYNTHETIC_SCENE_LOGS = f"logs/{RUN}/synthetic/scenes/{{scene}}"


def scene_names(surface=None, model=None, optics=None, field=None):
    """Names of the scenes with the given surface, model and optics; ``field``: True for
    the scenes whose solver gives fields (every model but Greenwood-Tripp), False for GT.
    """
    names = []
    for name, scene in SCENES.items():
        if surface is not None and scene["surface"] != surface:
            continue
        if model is not None and scene["model"] != model:
            continue
        if optics is not None and scene["optics"] != optics:
            continue
        if field is not None and (scene["model"] != "greenwood_tripp") != field:
            continue
        names.append(name)
    return names


def names_pattern(names):
    """Regex matching exactly ``names``; never empty-match."""
    return "|".join(map(re.escape, names)) or "(?!)"


def scene_config(scene):
    """A scene's config entry, as a rule's params (a changed scene re-runs only its jobs)."""
    return sorted_keys(SCENES[scene])


def scene_sphere_record(sphere):
    """The sheet values a scene takes from its sphere."""
    row = sphere_row(sphere)
    keys = (
        "diameter_mm",
        "e_star_gpa",
        "loads",
        "hardness_mpa",
        "hardening_k_mpa_per_nm",
    )
    return {key: row.get(key) for key in keys}


def afm_reading():
    """How the AFM maps are read: the surface keys the topography step uses too."""
    return sorted_keys(
        {
            "nan_policy": config["surface"]["afm_nan_policy"],
            "channel": config["surface"]["afm_channel"],
            "line_levelling": config["surface"]["line_levelling"],
        }
    )


def scene_dir(material, sphere, scene):
    return SCENE.format(material=material, sphere=sphere, scene=scene)


def sphere_scene_outputs(material, sphere, scene):
    """What a scene of one sphere delivers: its fit and, with optics, its comparison."""
    folder = scene_dir(material, sphere, scene)
    out = [f"{folder}/scene_fit.json"]
    if SCENES[scene]["optics"] == "microscope":
        out += [
            f"{folder}/comparison.csv",
            f"{folder}/registration.json",
            f"{folder}/comparison.png",
            f"{folder}/comparison.pdf",
        ]
    return out


def scene_outputs(materials):
    """Every AFM scene of every sphere of ``materials`` and each material's scene table."""
    out = []
    for material in materials:
        for sphere in spheres_of(material):
            for scene in scene_names(surface="afm_before"):
                out += sphere_scene_outputs(material, sphere, scene)
        if scene_names(surface="afm_before"):
            out.append(f"{MATERIAL.format(material=material)}/scenes.csv")
    return out


def synthetic_scene_outputs():
    return [
        f"{SYNTHETIC_SCENE.format(scene=s)}/scene_fit.json"
        for s in scene_names(surface="synthetic")
    ]


def scene_fit_inputs(wildcards):
    """A scene's solve and, with optics, its rendered areas."""
    folder = scene_dir(wildcards.material, wildcards.sphere, wildcards.scene)
    inputs = {"solve": f"{folder}/solve.json"}
    if SCENES[wildcards.scene]["optics"] == "microscope":
        inputs["render"] = f"{folder}/render.csv"
    return inputs


# Parameter scans and the study (workflow/rules/study.smk): each scan value of each sphere is
# a job of its own; the study's figures and model table run with the scans.
from amontons.simulate.scan_grid import scan_values, value_label

SCANS = {name: config["scans"][name] for name in config["run_scans"]}
SCAN = f"results/{RUN}/{{material}}/{{sphere}}/scans/{{scan}}"
SCAN_LOGS = f"logs/{RUN}/{{material}}/{{sphere}}/scans/{{scan}}"
STUDY = f"results/{RUN}/{{material}}/{{sphere}}/study"
STUDY_LOGS = f"logs/{RUN}/{{material}}/{{sphere}}/study"
SCAN_COLUMNS = {"p_y_mpa": "hardness_mpa", "k_mpa_per_nm": "hardening_k_mpa_per_nm"}


def scan_value_labels(sphere, scan):
    """The folder names of a scan's values for one sphere (range_factor x its sheet value)."""
    spec = SCANS[scan]
    centre = sphere_row(sphere)[SCAN_COLUMNS[spec["parameter"]]]
    values = scan_values(centre, spec["range_factor"], spec["steps"], spec["spacing"])
    return [value_label(v) for v in values]


def scan_dir(material, sphere, scan):
    return SCAN.format(material=material, sphere=sphere, scan=scan)


def scan_points(wildcards):
    """Every value's result of one sphere's scan."""
    folder = scan_dir(wildcards.material, wildcards.sphere, wildcards.scan)
    return [
        f"{folder}/{value}/scan_point.json"
        for value in scan_value_labels(wildcards.sphere, wildcards.scan)
    ]


def scan_outputs(materials):
    """Every scan of every sphere of ``materials``: its table and best value."""
    return [
        f"{scan_dir(material, sphere, scan)}/{name}"
        for material in materials
        for sphere in spheres_of(material)
        for scan in SCANS
        for name in ("scan.csv", "best.json")
    ]


def scans_of(parameter):
    """The running scans of ``parameter`` (p_y_mpa or k_mpa_per_nm)."""
    return [name for name, spec in SCANS.items() if spec["parameter"] == parameter]


def first_scene(model, optics=None):
    """The first running AFM scene of ``model`` (and ``optics``), or None."""
    names = scene_names(surface="afm_before", model=model, optics=optics)
    return names[0] if names else None


def scan_files(material, sphere, scan):
    """What the study's figures read of one sphere's scan: its judgement, every value's
    rendered fields and its base scene's registration."""
    folder = scan_dir(material, sphere, scan)
    base = scene_dir(material, sphere, SCANS[scan]["scene"])
    return {
        "best": f"{folder}/best.json",
        "table": f"{folder}/scan.csv",
        "rendered": [
            f"{folder}/{v}/rendered.h5" for v in scan_value_labels(sphere, scan)
        ],
        "registration": f"{base}/registration.json",
    }


def flat_files(layout):
    """Every path in a nested dict/list layout, once each."""
    if isinstance(layout, dict):
        return [p for value in layout.values() for p in flat_files(value)]
    if isinstance(layout, list):
        return [p for value in layout for p in flat_files(value)]
    return [layout]


def study_k_scan(wildcards):
    """The files of the sphere's first k scan (figures B.9 and B.11)."""
    return scan_files(wildcards.material, wildcards.sphere, scans_of("k_mpa_per_nm")[0])


def load_series_layout(wildcards):
    """Fig. B.11's inputs: the elastic scene's rendered loads and registration, the
    Greenwood-Tripp solve and the k scan."""
    elastic = scene_dir(
        wildcards.material, wildcards.sphere, first_scene("elastic", "microscope")
    )
    gt = scene_dir(wildcards.material, wildcards.sphere, first_scene("greenwood_tripp"))
    return {
        "elastic": {
            "rendered": f"{elastic}/rendered.h5",
            "registration": f"{elastic}/registration.json",
        },
        "gt_solve": f"{gt}/solve.json",
        "k_scan": study_k_scan(wildcards),
    }


def model_curve_layout(wildcards):
    """Fig. B.12's inputs: each AFM scene's areas and each scan's best value."""
    scenes = {}
    for scene in scene_names(surface="afm_before"):
        folder = scene_dir(wildcards.material, wildcards.sphere, scene)
        files = {"solve": f"{folder}/solve.json"}
        if SCENES[scene]["optics"] == "microscope":
            files["render"] = f"{folder}/render.csv"
        scenes[scene] = files
    scans = {
        scan: f"{scan_dir(wildcards.material, wildcards.sphere, scan)}/best.json"
        for scan in SCANS
    }
    return {"scenes": scenes, "scans": scans}


def model_table_layout(material):
    """The model table's inputs per sphere: measured fit, scenes, scans' best values."""
    layout = {}
    for sphere in spheres_of(material):
        scenes = {}
        for scene in scene_names(surface="afm_before"):
            folder = scene_dir(material, sphere, scene)
            files = {"fit": f"{folder}/scene_fit.json", "solve": f"{folder}/solve.json"}
            if SCENES[scene]["optics"] == "microscope":
                files["comparison"] = f"{folder}/comparison.csv"
            scenes[scene] = files
        layout[sphere] = {
            "measured": measured(material, sphere, "load_area_fit.json"),
            "scenes": scenes,
            "scans": {s: f"{scan_dir(material, sphere, s)}/best.json" for s in SCANS},
        }
    return layout


CURVATURE_PAIRS = {
    name: config["study"]["curvature_pairs"][name]
    for name in config["study"]["run_curvature_pairs"]
}
STUDY_RESULTS = f"results/{RUN}/study"


def sphere_study_figures(material, sphere):
    """The study's figures of one sphere that its scans and scenes allow (docs/study.md)."""
    folder = STUDY.format(material=material, sphere=sphere)
    names = []
    if SCANS:
        names += ["B8_scans", "B12_models"]
    if scans_of("k_mpa_per_nm"):
        names.append("B9_flattening")
        if first_scene("elastic", "microscope") and first_scene("greenwood_tripp"):
            names.append("B11_load_series")
    return [f"{folder}/{name}.{ext}" for name in names for ext in ("png", "pdf", "csv")]


def study_outputs(materials):
    """The study's outputs of ``materials``: per-sphere figures and each material's model
    table (with scans)."""
    out = []
    if SCANS:
        for material in materials:
            for sphere in spheres_of(material):
                out += sphere_study_figures(material, sphere)
            out.append(f"{MATERIAL.format(material=material)}/models.csv")
    return out


def study_overview_outputs():
    """The study's figures across materials: Fig. B.13 (with scans) and Fig. B.10 (with
    curvature pairs); built by `all` and `study`, not by a material's target."""
    out = []
    if SCANS:
        out += [f"{STUDY_RESULTS}/B13_amontons.{ext}" for ext in ("png", "pdf", "csv")]
    if CURVATURE_PAIRS:
        out += [f"{STUDY_RESULTS}/B10_curvature.{ext}" for ext in ("png", "pdf", "csv")]
    return out


# Cluster resources (README, "On a cluster"): each rule's measured wall time and peak memory,
# and for the solves a model in their FFT grid and loads (amontons.resources), from
# workflow/resources.json (benchmarks/fit_job_resources.py).
from amontons.config import hertz_diameter_um, solver_pixel_um, solver_side_px
from amontons.accuracy.timing import plastic_ratio, predict
from amontons.resources import JobResources, mem_mb_of, runtime_min

# The accuracy study's timing model (workflow/timing_model.json, a copy of
# results/full/accuracy/timing_model.json): what a solve costs, from its grid and tolerance.
with open(os.path.join(workflow.basedir, "workflow", "timing_model.json")) as _stream:
    TIMING_MODEL = json.load(_stream)

RESOURCES = JobResources.from_file(
    os.path.join(workflow.basedir, "workflow", "resources.json")
)


def measured_runtime(rule):
    return RESOURCES.runtime_min(rule)


def measured_mem_mb(rule):
    return RESOURCES.mem_mb(rule)


def solve_size(scene, sphere=None, scan=None, value=None):
    """What the timing model needs of a scene's solve on ``sphere`` (None: synthetic), with
    the scan parameter ``scan`` (p_y_mpa or k_mpa_per_nm) at ``value`` if given: model and
    the keyword arguments of amontons.accuracy.timing.predict."""
    spec = config["scenes"][scene]
    if sphere is None:
        synthetic = spec["synthetic"]
        diameter = 2 * synthetic.get("radius_mm", 0.0) or None
        e_star, loads = synthetic["e_star_gpa"], spec["loads"]
        slope = synthetic.get("rms_slope")
        law = spec
    else:
        row = sphere_row(sphere)
        diameter, e_star = row["diameter_mm"], row["e_star_gpa"]
        loads = row["loads"] if spec["loads"] == "measured" else spec["loads"]
        slope = None  # the map's slope is known only once it is levelled
        law = {
            "p_y_mpa": spec["p_y_mpa"] or row.get("hardness_mpa"),
            "k_mpa_per_nm": spec["k_mpa_per_nm"] or row.get("hardening_k_mpa_per_nm"),
        }
    if scan is not None:
        law = {**law, scan: float(value)}
    periodic = spec["geometry"] == "flat_periodic"
    pixel_um = solver_pixel_um(spec, diameter, e_star, loads)
    contact_px = None
    if diameter is not None:
        contact_px = hertz_diameter_um(max(loads), diameter, e_star) / pixel_um
    ratio = plastic_ratio(
        spec["model"],
        pixel_m=pixel_um * 1e-6,
        e_star_pa=e_star * 1e9,
        k_pa_per_m=(law.get("k_mpa_per_nm") or 0.0) * 1e15,
        p_y_pa=(law.get("p_y_mpa") or 0.0) * 1e6,
        slope_rms=slope,
    )
    return spec["model"], {
        "side_px": solver_side_px(spec, diameter, e_star, loads),
        "periodic": periodic,
        "loads": len(loads),
        "tol": spec["tol"],
        "contact_px": contact_px,
        "ratio": ratio,
    }


def scan_solve(wildcards):
    """A scan job's solve for the timing model: its scene on its sphere at its value."""
    scan = SCANS[wildcards.scan]
    return scan["scene"], wildcards.sphere, scan["parameter"], wildcards.value


def predicted_solve(scene_of, wildcards):
    """(wall time s, peak memory MB) the timing model predicts for a scene's solve."""
    model, size = solve_size(*scene_of(wildcards))
    return predict(TIMING_MODEL, model, **size)


def solve_runtime(rule, scene_of):
    """Runtime (min) of a solve job: ``scene_of(wildcards)`` gives (scene, sphere or None[,
    scan parameter, value]);
    the timing model's prediction (docs/accuracy.md) with the resources' safety factor.
    """

    def runtime(wildcards):
        return runtime_min(predicted_solve(scene_of, wildcards)[0])

    return runtime


def solve_mem_mb(rule, scene_of):
    """Memory (MB) of a solve job, as :func:`solve_runtime`."""

    def mem_mb(wildcards):
        return mem_mb_of(predicted_solve(scene_of, wildcards)[1])

    return mem_mb


# The accuracy study (docs/accuracy.md): its problems and settings by name.
from amontons.accuracy.settings import problem_kind, settings_by_name, timing_points

ACCURACY_SPHERE = config["accuracy"]["sphere"]


def accuracy_sphere_inputs(wildcards):
    """The AFM map a rough-sphere problem presses and the PSF every problem is rendered with."""
    sphere = ACCURACY_SPHERE
    inputs = {"psf": measured(sphere_row(sphere)["material"], sphere, "psf.json")}
    if accuracy_geometry(wildcards.problem) == "sphere":
        inputs["levelled"] = accuracy_levelled_map()
    return inputs


def accuracy_levelled_map():
    """The levelled AFM map of the accuracy study's sphere."""
    sphere = ACCURACY_SPHERE
    return measured(sphere_row(sphere)["material"], sphere, "afm_before_levelled.h5")


def accuracy_geometry(problem):
    return problem_kind(problem)[1]


def timing_point_files():
    """The summary of every timing point of the accuracy study."""
    return [
        f"{RESULTS}/accuracy/timing/{point}/summary.json"
        for point in timing_points(config["accuracy"])
    ]


def accuracy_files(name):
    """``name`` of every problem at every setting (the reference included)."""
    study = config["accuracy"]
    return [
        f"{RESULTS}/accuracy/{problem}/{setting}/{name}"
        for problem in study["problems"]
        for setting in settings_by_name(problem, study)
    ]
