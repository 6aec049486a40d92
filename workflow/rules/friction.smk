# Friction from rheometer torque traces, and the deviation from Amontons' law (Fig. B.13).


rule measure_friction:
    input:
        rheometer=lambda wc: per_load_inputs(wc.sphere, "rheometer"),
    output:
        table="results/{material}/{sphere}/friction.csv",
    log:
        "logs/{material}/{sphere}/measure_friction.log",
    benchmark:
        "logs/{material}/{sphere}/measure_friction.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        rheometer_dir=lambda wc: per_load_dir(wc.sphere, "rheometer"),
        loads_mn=lambda wc: loads_mn(wc.sphere),
        friction=config["friction"],
    script:
        "../../scripts/measure_friction.py"


rule plot_amontons_deviation:
    input:
        areas=lambda wc: material_results(wc.material, "contact_area.csv"),
        friction=lambda wc: material_results(wc.material, "friction.csv"),
    output:
        table=report(
            "results/{material}/amontons.csv",
            caption="../report/amontons.rst",
            category="Amontons deviation",
            subcategory="{material}",
        ),
        png=report(
            "results/{material}/amontons.png",
            caption="../report/amontons.rst",
            category="Amontons deviation",
            subcategory="{material}",
        ),
        pdf="results/{material}/amontons.pdf",
    log:
        "logs/{material}/plot_amontons_deviation.log",
    benchmark:
        "logs/{material}/plot_amontons_deviation.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        spheres=lambda wc: spheres_of(wc.material),
        data_label=lambda wc: data_label(spheres_of(wc.material)),
        reference_load_mn=config["load_area"]["reference_load_mn"],
    script:
        "../../scripts/plot_amontons_deviation.py"


rule friction:
    """Target: friction of every sphere and the Amontons-deviation figure of every material."""
    input:
        friction_outputs(MATERIALS),
    localrule: True
