# The study's answer (docs/study.md §6): the verdict table of every material (with scans),
# the headline numbers with the files they come from, and the report's first page, which
# shows the verdict with Figs. B.13 and B.12 (with scans).
SUMMARY = f"{RESULTS}/summary.md"
VERDICT = f"{RESULTS}/verdict.csv"
REPORT_PAGE = f"{RESULTS}/report_first_page.rst"
# Each selected material's model table (models.csv), by material.
VERDICT_INPUTS = {m: f"{MATERIAL.format(material=m)}/models.csv" for m in MATERIALS}
# What summary.md reads: per sphere its load-area fit and its scans' best values, per
# material its Amontons table, the verdict and the model tables it copies (with scans), and
# Fig. B.10's table (with curvature pairs).
SUMMARY_LAYOUT = {
    "fits": {
        s: measured(m, s, "load_area_fit.json")
        for m in MATERIALS
        for s in spheres_of(m)
    },
    "bests": {
        s: {scan: f"{scan_dir(m, s, scan)}/best.json" for scan in SCANS}
        for m in MATERIALS
        for s in spheres_of(m)
    },
    "amontons": {m: f"{MATERIAL.format(material=m)}/amontons.csv" for m in MATERIALS},
    "verdict": VERDICT if SCANS else None,
    "models": VERDICT_INPUTS if SCANS else {},
    "curvature": f"{STUDY_RESULTS}/B10_curvature.csv" if CURVATURE_PAIRS else None,
}
# The figures the report's first page shows, in order, with their captions: Fig. B.13,
# then each sphere's Fig. B.12.
REPORT_PAGE_FIGURES = {
    f"{STUDY_RESULTS}/B13_amontons.png": "Fig. B.13, every material",
    **{
        f"{STUDY.format(material=m, sphere=s)}/B12_models.png": f"Fig. B.12, {s}"
        for m in MATERIALS
        for s in spheres_of(m)
    },
}
# What `all` builds of this file: the summary always, the verdict and the report's first
# page with scans.
SUMMARY_OUTPUTS = [SUMMARY] + ([VERDICT, REPORT_PAGE] if SCANS else [])


rule tabulate_verdict:
    input:
        **VERDICT_INPUTS,
    output:
        table=report(
            VERDICT,
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
        tables=VERDICT_INPUTS,
    script:
        "../../scripts/tabulate_verdict.py"


rule summarise_study:
    input:
        [p for p in flat_files(SUMMARY_LAYOUT) if p is not None],
    output:
        summary=report(
            SUMMARY,
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
        layout=SUMMARY_LAYOUT,
        run=RUN,
        data_label=data_label(SPHERES),
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/summarise_study.py"


rule write_report_page:
    input:
        verdict=VERDICT,
        figures=list(REPORT_PAGE_FIGURES),
    output:
        page=REPORT_PAGE,
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
        figures=REPORT_PAGE_FIGURES,
        sources=list(VERDICT_INPUTS.values()),
        data_label=data_label(SPHERES),
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/write_report_page.py"
