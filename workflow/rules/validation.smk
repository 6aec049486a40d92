# The validation study (docs/study.md §7): virtual spheres whose truth is each contact model,
# solved truth_pixel_ratio times finer than the run's solver preset, judged by the study's own
# scans and decision; the coverage of its intervals, its verdicts against the truths, the cost.
# Targets (not part of `all`): `snakemake validation`, its small sphere; `snakemake
# validation_spheres`, the materials sheet's spheres that validation.spheres.run names, each at
# the pixel the run's preset solves it at.


rule validate_case:
    output:
        record=PATHS.validation_case("{case}"),
    log:
        f"{PATHS.validation_logs}/{{case}}/validate_case.log",
    benchmark:
        f"{PATHS.validation_logs}/{{case}}/validate_case.benchmark.tsv"
    wildcard_constraints:
        case=names_pattern(VALIDATION_CASES + VALIDATION_SPHERE_CASES),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("validate_case"),
        runtime=measured_runtime("validate_case"),
    params:
        case=lambda wildcards: VALIDATION_CASE_RECORDS[wildcards.case],
        validation=VALIDATION_SETTINGS,
        virtual=config_slice("virtual_experiment"),
        sphere=lambda wildcards: validation_sphere(
            VALIDATION_CASE_RECORDS[wildcards.case]
        ),
        scans=config_slice("scans"),
        judgement=SCAN_JUDGEMENT,
        preset=config["solver_presets"][config["solver_preset"]],
        otsu=OTSU,
    script:
        "../../scripts/validate_case.py"


rule tabulate_validation:
    input:
        records=[PATHS.validation_case(case) for case in VALIDATION_CASES],
    output:
        cases=f"{PATHS.validation}/cases.csv",
        coverage=report(
            f"{PATHS.validation}/coverage.csv",
            caption="../report/validation.rst",
            category="Validation",
        ),
        confusion=report(
            f"{PATHS.validation}/confusion.csv",
            caption="../report/validation.rst",
            category="Validation",
        ),
        cost=f"{PATHS.validation}/cost.csv",
        checks=f"{PATHS.validation}/checks.csv",
        summary=report(
            f"{PATHS.validation}/validation.md",
            caption="../report/validation.rst",
            category="Validation",
        ),
        figure=report(
            f"{PATHS.validation}/intervals.png",
            caption="../report/validation.rst",
            category="Validation",
        ),
    log:
        f"{PATHS.validation_logs}/tabulate_validation.log",
    benchmark:
        f"{PATHS.validation_logs}/tabulate_validation.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("tabulate_validation"),
        runtime=measured_runtime("tabulate_validation"),
    params:
        ratio=config["validation"]["truth_pixel_ratio"],
        confidence=SCAN_JUDGEMENT["confidence"],
        left_out=[],
    script:
        "../../scripts/tabulate_validation.py"


rule validation:
    """Target: the validation study."""
    input:
        rules.tabulate_validation.output,
    localrule: True


use rule tabulate_validation as tabulate_validation_spheres with:
    input:
        records=[PATHS.validation_case(case) for case in VALIDATION_SPHERE_CASES],
    output:
        cases=f"{PATHS.validation}/spheres/cases.csv",
        coverage=report(
            f"{PATHS.validation}/spheres/coverage.csv",
            caption="../report/validation.rst",
            category="Validation",
        ),
        confusion=report(
            f"{PATHS.validation}/spheres/confusion.csv",
            caption="../report/validation.rst",
            category="Validation",
        ),
        cost=f"{PATHS.validation}/spheres/cost.csv",
        checks=f"{PATHS.validation}/spheres/checks.csv",
        summary=report(
            f"{PATHS.validation}/spheres/validation.md",
            caption="../report/validation.rst",
            category="Validation",
        ),
        figure=report(
            f"{PATHS.validation}/spheres/intervals.png",
            caption="../report/validation.rst",
            category="Validation",
        ),
    log:
        f"{PATHS.validation_logs}/tabulate_validation_spheres.log",
    benchmark:
        f"{PATHS.validation_logs}/tabulate_validation_spheres.benchmark.tsv"
    resources:
        mem_mb=measured_mem_mb("tabulate_validation"),
        runtime=measured_runtime("tabulate_validation"),
    params:
        ratio=config["validation"]["spheres"]["ratio"],
        confidence=SCAN_JUDGEMENT["confidence"],
        left_out=VALIDATION_SPHERES_LEFT_OUT,


rule validation_spheres:
    """Target: the validation study on the materials sheet's spheres."""
    input:
        rules.tabulate_validation_spheres.output,
    localrule: True
