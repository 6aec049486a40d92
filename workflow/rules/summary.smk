# The study's answer (docs/study.md §6, amontons.workflow.summary): the verdict table of every
# material with scans, the headline numbers with the files they come from, and the report's
# first page, which shows the verdict with Figs. B.13 and B.12 (with scans).


rule tabulate_verdict:
    input:
        **SUMMARY.verdict_inputs(),
    output:
        table=report(
            SUMMARY.verdict,
            caption="../report/verdict.rst",
            category="Study",
            subcategory="all materials",
        ),
    log:
        f"{LOGS}/study/tabulate_verdict.log",
    benchmark:
        f"{LOGS}/study/tabulate_verdict.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("tabulate_verdict"),
        runtime=measured_runtime("tabulate_verdict"),
    params:
        tables=SUMMARY.verdict_inputs(),
    script:
        "../../scripts/tabulate_verdict.py"


rule summarise_study:
    input:
        [p for p in flat_files(SUMMARY.layout()) if p is not None],
    output:
        summary=report(
            SUMMARY.summary,
            caption="../report/summary.rst",
            category="Study",
            subcategory="all materials",
        ),
    log:
        f"{LOGS}/study/summarise_study.log",
    benchmark:
        f"{LOGS}/study/summarise_study.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("summarise_study"),
        runtime=measured_runtime("summarise_study"),
    params:
        layout=SUMMARY.layout(),
        run=config["run"],
        data_label=data_label(SPHERES),
        confidence=config["load_area"]["confidence"],
        left_out=RUN.left_out(),
        failed=RUN.failed(),
    script:
        "../../scripts/summarise_study.py"


rule write_report_page:
    input:
        verdict=SUMMARY.verdict,
        figures=list(SUMMARY.report_figures()),
    output:
        page=SUMMARY.report_page,
    log:
        f"{LOGS}/study/write_report_page.log",
    benchmark:
        f"{LOGS}/study/write_report_page.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("write_report_page"),
        runtime=measured_runtime("write_report_page"),
    params:
        figures=SUMMARY.report_figures(),
        sources=list(SUMMARY.verdict_inputs().values()),
        data_label=data_label(SPHERES),
        confidence=config["load_area"]["confidence"],
        left_out=RUN.left_out(),
        failed=RUN.failed(),
    script:
        "../../scripts/write_report_page.py"
