# Load-area power laws and the deviation from Amontons' law.


rule fit_load_area:
    input:
        table=rules.measure_contact_area.output.table,
    output:
        fit=f"{MEASURED}/{LOAD_AREA_FIT}",
    log:
        f"{SPHERE_LOGS}/fit_load_area.log",
    benchmark:
        f"{SPHERE_LOGS}/fit_load_area.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("fit_load_area"),
        runtime=measured_runtime("fit_load_area"),
    params:
        load_area=config_slice("load_area"),
    script:
        "../../scripts/fit_load_area.py"


rule plot_load_area:
    input:
        tables=lambda wc: per_sphere(wc.material, CONTACT_AREA),
        fits=lambda wc: per_sphere(wc.material, LOAD_AREA_FIT),
    output:
        table=f"{MATERIAL}/load_area.csv",
        png=report(
            f"{MATERIAL}/load_area.png",
            caption="../report/load_area.rst",
            category="Load-area",
            subcategory="{material}",
        ),
        pdf=f"{MATERIAL}/load_area.pdf",
    log:
        f"{MATERIAL_LOGS}/plot_load_area.log",
    benchmark:
        f"{MATERIAL_LOGS}/plot_load_area.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_load_area"),
        runtime=measured_runtime("plot_load_area"),
    params:
        spheres=lambda wc: spheres_of(wc.material),
        data_label=lambda wc: data_label(spheres_of(wc.material)),
        reference_load_mn=config["load_area"]["reference_load_mn"],
    script:
        "../../scripts/plot_load_area.py"


rule fits:
    """Target: load-area fits of every sphere."""
    input:
        TARGETS.fits(MATERIALS),
    localrule: True


rule figures:
    """Target: load-area and Amontons-deviation figures and tables of every material."""
    input:
        TARGETS.figures(MATERIALS),
    localrule: True
