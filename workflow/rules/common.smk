# Wiring only: the run is checked and built once by amontons.workflow (importable, tested
# without Snakemake in tests/workflow_dag/), and the names the rules use are bound to it here.
# amontons.workflow loads no numerical stack, so that building the DAG stays fast.
from functools import partial

from snakemake.logging import logger

from amontons.workflow.ledger import record_failures, settle_ledger
from amontons.workflow.params import (
    afm_reading,
    config_slice as _config_slice,
    image_choice,
    otsu_settings,
    ring_optics,
    sorted_keys,
)
from amontons.workflow.paths import (
    AMONTONS_FIGURE,
    B10_FIGURE,
    B12_FIGURE,
    B13_FIGURE,
    MODELS_TABLE,
    BEFORE_FIT,
    BEST,
    COMPARISON,
    COMPARISON_FIGURE,
    CONTACT_AREA,
    FIELDS,
    FRICTION,
    LEVELLED_MAP,
    LIFETIME,
    LOAD_AREA_FIT,
    PSF,
    REGISTRATION,
    REFINEMENT,
    RENDERED,
    RENDER_TABLE,
    SPHERE_FITS,
    SCAN_TABLE,
    SCENE_FITS,
    SOLVE,
    TRUTH,
    ACCURACY_FIELDS,
    ACCURACY_SUMMARY,
    flat_files,
)
from amontons.workflow.resources import scan_solves
from amontons.workflow.accuracy import TIMING_POINT
from amontons.workflow.run import WorkflowRun
from amontons.workflow.optional_inputs import RHEOMETER
from amontons.workflow.validation import (
    left_out_validation_spheres,
    validation_case_records,
    validation_case_settings,
    validation_cases,
    validation_sphere_cases,
    validation_sphere_record,
)
from amontons.workflow.wildcards import names_pattern

CONFIG_SOURCE = ", ".join(
    str(f) for f in (workflow.overwrite_configfiles or ["config/config.yaml"])
)
# The workflow's own files (schemas, measured resources, timing model) are located from this
# file, not from workflow.basedir: that is the folder of the Snakefile Snakemake runs, a user's
# own one when this workflow is a module there (docs/deploy.md).
RUN = WorkflowRun.from_config(
    config, lambda name: workflow.source_path(f"../{name}"), CONFIG_SOURCE
)
MATERIALS = RUN.materials
# A sphere's missing optional file removes only what needs it: say so before any job.
for _line in RUN.left_out():
    logger.warning(_line)
# ... and the loads an AFM scan too small for them leaves out, where its header gives its size.
for _line in RUN.outside_scan():
    logger.warning(_line)
# A sphere whose job failed in an earlier run is held out of the tables: say so, and why.
for _line in RUN.failed():
    logger.warning(_line)

# Folders of the run (amontons.workflow.paths): patterns with their wildcards.
PATHS = RUN.paths
LOGS = PATHS.logs
SYNTHETIC_SPHERE = PATHS.synthetic_sphere()
MEASURED = PATHS.measured()
SPHERE_LOGS = PATHS.sphere_logs()
MATERIAL = PATHS.material()
MATERIAL_LOGS = PATHS.material_logs()
SCENE = PATHS.scene()
SCENE_LOGS = PATHS.scene_logs()
SPHERE_SCENES = PATHS.sphere_scenes()
SPHERE_SCENES_LOGS = PATHS.sphere_scenes_logs()
SYNTHETIC_SCENE = PATHS.synthetic_scene()
SYNTHETIC_SCENE_LOGS = PATHS.synthetic_scene_logs()
SCAN = PATHS.scan()
SCAN_LOGS = PATHS.scan_logs()
STUDY = PATHS.study()
STUDY_LOGS = PATHS.study_logs()
STUDY_RESULTS = PATHS.study_results
ACCURACY = PATHS.accuracy
ACCURACY_LOGS = PATHS.accuracy_logs

# The selected spheres (amontons.workflow.spheres).
SPHERES = RUN.spheres
sphere_row = SPHERES.rows.row
spheres_of = SPHERES.of
loads_mn = SPHERES.rows.loads_mn
sheet_value = SPHERES.rows.value
pixel_nm = SPHERES.rows.pixel_nm
raw_file = SPHERES.rows.raw_file
reflection_image = SPHERES.files.reflection_image
# The suffix of the virtual experiment's confocal images (virtual_experiment.formats.images).
SYNTHETIC_IMAGE = SPHERES.files.synthetic_images
afm_path = SPHERES.files.afm_path
per_load_inputs = SPHERES.files.per_load_inputs
reflection_fluorescence = SPHERES.files.reflection_fluorescence
data_label = SPHERES.rows.data_label
scene_sphere_record = SPHERES.rows.scene_record

# Config slices as params (amontons.workflow.params).
config_slice = partial(_config_slice, config)
OTSU = otsu_settings(config)
# How a scan is judged beyond its grid (docs/study.md §1): the model's error and the
# refinement, at the load-area fits' confidence.
SCAN_JUDGEMENT = {
    **config["scan_judgement"],
    "confidence": config["load_area"]["confidence"],
}
SCAN_REFINED = SCAN_JUDGEMENT["refine_max_values"]
SCAN_CHECK_FACTOR = SCAN_JUDGEMENT["model_error_pixel_factor"]
# The validation study's cases (docs/study.md §7): one job each.
VALIDATION_CASES = validation_cases(config)
# ... and on the materials sheet's spheres (docs/study.md §7, target validation_spheres); the
# spheres it names but cannot run on are named in its summary.
VALIDATION_SPHERE_CASES = validation_sphere_cases(config, SPHERES.rows.records)
VALIDATION_SPHERES_LEFT_OUT = left_out_validation_spheres(config, SPHERES.rows.records)
VALIDATION_CASE_RECORDS = validation_case_records(config)
validation_sphere = partial(validation_sphere_record, SPHERES.rows.records)
VALIDATION_SETTINGS = validation_case_settings(config)
RING_OPTICS = ring_optics(config)
AFM_READING = afm_reading(config)
# Which plane of a confocal file is the image: the fluorescence and bead one, the reflection one.
IMAGES = image_choice(config)
REFLECTION_IMAGES = image_choice(config, reflection=True)
# A sphere's fluorescence plane choice: IMAGES, and which plane is which load where one file
# holds them all (config/README.md, "A load series in one file").
fluorescence_choice = partial(SPHERES.series.fluorescence_choice, images=IMAGES)

# Scenes, scans and the study (amontons.workflow.scenes, amontons.workflow.study).
SCENES = RUN.scenes.scenes
SCANS = RUN.scenes.scans
scene_names = RUN.scenes.names
scene_config = RUN.scenes.config
CURVATURE_PAIRS = RUN.study.curvature_pairs

# Targets (amontons.workflow.targets).
TARGETS = RUN.targets
per_sphere = TARGETS.per_sphere

# Cluster resources (docs/cluster.md): measured per rule, predicted per solve.
measured_runtime = RUN.resources.runtime
measured_mem_mb = RUN.resources.mem_mb
solve_runtime = RUN.resources.solve_runtime
solve_mem_mb = RUN.resources.solve_mem_mb
# The solver's engine (config solver_backend): empty for cpu, else the GPU resource of the
# solve rules and the param their scripts pass to the solver.
SOLVE_GPU = RUN.resources.backend.resources
SOLVE_BACKEND = RUN.resources.backend.params

# The run's answer (amontons.workflow.summary, docs/study.md §6).
SUMMARY = RUN.summary

# The accuracy study (docs/accuracy.md).
ACCURACY_SPHERE = RUN.accuracy.sphere
