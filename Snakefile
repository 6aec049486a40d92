# amontons: multi-asperity contact experiments, from raw images to deviations from Amontons' law.
# Entry point; README.md says how to run it, config/README.md what every key means. It also runs
# as a Snakemake module from a folder of one's own, whose config then stands in for the
# configfile below (docs/deploy.md).
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"


wildcard_constraints:
    sphere="|".join(map(re.escape, SPHERES)),
    material="|".join(map(re.escape, MATERIALS)),
    scene=names_pattern(list(SCENES)),
    scan=names_pattern(list(SCANS)),


include: "workflow/rules/virtual_experiment.smk"
include: "workflow/rules/optics.smk"
include: "workflow/rules/load_area.smk"
include: "workflow/rules/friction.smk"
include: "workflow/rules/surface.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/study.smk"
include: "workflow/rules/accuracy.smk"
include: "workflow/rules/validation.smk"
include: "workflow/rules/summary.smk"


# A failed run names, per sphere, each step that failed and its error, and keeps them in
# results/<run>/failed_jobs.csv, which the next run reads to make the tables without the
# failed spheres (docs/workflow.md, "When a job fails"; amontons.workflow.ledger).
onerror:
    for line in record_failures(
        log, RUN.paths, RUN.data_stamp, RUN.spheres.held_out
    ):
        logger.error(line)


onsuccess:
    for line in settle_ledger(RUN.paths, RUN.spheres.held_out):
        logger.warning(line)


# Default target: every output of every selected material.
rule all:
    default_target: True
    input:
        TARGETS.material(MATERIALS)
        + RUN.study.overview_outputs()
        + RUN.summary.outputs(),
    localrule: True


# One wildcard-free target per material: `snakemake PS` builds only PS's jobs.
for _material in MATERIALS:

    rule:
        name:
            _material
        input:
            TARGETS.material([_material]),
        localrule: True
