# What accuracy costs in time (docs/accuracy.md): the same problems solved at every setting of
# the grid in config `accuracy`, each setting a job of its own, compared with a converged
# reference; the table, the error-versus-time figure with its Pareto fronts, the presets the
# fronts propose, and the timing model. Target: `snakemake accuracy`.


rule solve_accuracy_setting:
    input:
        unpack(RUN.accuracy.sphere_inputs),
    output:
        summary=PATHS.accuracy_setting(ACCURACY_SUMMARY, "{problem}", "{setting}"),
        fields=PATHS.accuracy_setting(ACCURACY_FIELDS, "{problem}", "{setting}"),
    log:
        f"{ACCURACY_LOGS}/{{problem}}/{{setting}}/solve_accuracy_setting.log",
    benchmark:
        f"{ACCURACY_LOGS}/{{problem}}/{{setting}}/solve_accuracy_setting.benchmark.tsv"
    wildcard_constraints:
        problem=names_pattern(config["accuracy"]["problems"]),
        setting=r"reference|px[0-9]+_tol[0-9e.+-]+(_w[0-9.]+)?_c2f[01]",
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("solve_accuracy_setting"),
        runtime=measured_runtime("solve_accuracy_setting"),
    params:
        # what a solve needs of the study (not the preset budgets: a new budget re-runs no solve)
        study=lambda wc: sorted_keys(
            {k: config["accuracy"][k] for k in ("grid", "reference", "periodic")}
        ),
        record=lambda wc: RUN.accuracy.sphere_record(),
        fluorescence_pixel_nm=pixel_nm(ACCURACY_SPHERE),
        otsu=OTSU,
    script:
        "../../scripts/solve_accuracy_setting.py"


rule solve_timing_point:
    input:
        levelled=RUN.accuracy.levelled_map(),
    output:
        summary=PATHS.timing_point("{point}"),
    log:
        f"{ACCURACY_LOGS}/timing/{{point}}/solve_timing_point.log",
    benchmark:
        f"{ACCURACY_LOGS}/timing/{{point}}/solve_timing_point.benchmark.tsv"
    wildcard_constraints:
        point=TIMING_POINT,
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("solve_timing_point"),
        runtime=measured_runtime("solve_timing_point"),
    params:
        study=lambda wc: sorted_keys(
            {"timing_points": config["accuracy"]["timing_points"]}
        ),
        record=lambda wc: RUN.accuracy.sphere_record(),
    script:
        "../../scripts/solve_timing_point.py"


rule tabulate_accuracy:
    input:
        summaries=RUN.accuracy.files(ACCURACY_SUMMARY),
        fields=RUN.accuracy.files(ACCURACY_FIELDS),
    output:
        table=f"{ACCURACY}/accuracy.csv",
        presets=f"{ACCURACY}/presets.json",
    log:
        f"{ACCURACY_LOGS}/tabulate_accuracy.log",
    benchmark:
        f"{ACCURACY_LOGS}/tabulate_accuracy.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("tabulate_accuracy"),
        runtime=measured_runtime("tabulate_accuracy"),
    params:
        budgets=config["accuracy"]["preset_budgets"],
        preset_problems=[
            p for p in config["accuracy"]["problems"] if p.endswith("_sphere")
        ],
    script:
        "../../scripts/tabulate_accuracy.py"


rule plot_accuracy:
    input:
        table=rules.tabulate_accuracy.output.table,
    output:
        png=report(
            f"{ACCURACY}/accuracy.png",
            caption="../report/accuracy.rst",
            category="Accuracy",
        ),
        pdf=f"{ACCURACY}/accuracy.pdf",
    log:
        f"{ACCURACY_LOGS}/plot_accuracy.log",
    benchmark:
        f"{ACCURACY_LOGS}/plot_accuracy.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_accuracy"),
        runtime=measured_runtime("plot_accuracy"),
    params:
        sphere=ACCURACY_SPHERE,
        data_label=data_label([ACCURACY_SPHERE]),
    script:
        "../../scripts/plot_accuracy.py"


rule fit_timing_model:
    input:
        summaries=RUN.accuracy.files(ACCURACY_SUMMARY),
        timing_points=RUN.accuracy.timing_point_files(),
    output:
        model=f"{ACCURACY}/timing_model.json",
    log:
        f"{ACCURACY_LOGS}/fit_timing_model.log",
    benchmark:
        f"{ACCURACY_LOGS}/fit_timing_model.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("fit_timing_model"),
        runtime=measured_runtime("fit_timing_model"),
    script:
        "../../scripts/fit_timing_model.py"


rule accuracy:
    input:
        rules.tabulate_accuracy.output.table,
        rules.tabulate_accuracy.output.presets,
        rules.plot_accuracy.output.png,
        rules.fit_timing_model.output.model,
    localrule: True
