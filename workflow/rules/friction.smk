# Friction from rheometer torque traces, and the deviation from Amontons' law (Fig. B.13).


rule measure_friction:
    input:
        rheometer=lambda wc: per_load_inputs(wc.sphere, "rheometer"),
    output:
        table=f"{MEASURED}/{FRICTION}",
    log:
        f"{SPHERE_LOGS}/measure_friction.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_friction.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_friction"),
        runtime=measured_runtime("measure_friction"),
    params:
        loads_mn=lambda wc: loads_mn(wc.sphere),
        friction=config_slice("friction"),
        export=lambda wc: SPHERES.files.rheometer_export(
            wc.sphere, config.get("rheometer_export")
        ),
        virtual_format=lambda wc: (
            config["virtual_experiment"]["formats"]["rheometer"]
            if SPHERES.rows.is_synthetic(wc.sphere)
            else None
        ),
    script:
        "../../scripts/measure_friction.py"


rule plot_amontons_deviation:
    input:
        areas=lambda wc: TARGETS.per_sphere(wc.material, CONTACT_AREA, having=RHEOMETER),
        friction=lambda wc: TARGETS.per_sphere(wc.material, FRICTION, having=RHEOMETER),
    output:
        table=report(
            f"{MATERIAL}/{AMONTONS_FIGURE}.csv",
            caption="../report/amontons.rst",
            category="Amontons deviation",
            subcategory="{material}",
        ),
        png=report(
            f"{MATERIAL}/{AMONTONS_FIGURE}.png",
            caption="../report/amontons.rst",
            category="Amontons deviation",
            subcategory="{material}",
        ),
        pdf=f"{MATERIAL}/{AMONTONS_FIGURE}.pdf",
    log:
        f"{MATERIAL_LOGS}/plot_amontons_deviation.log",
    benchmark:
        f"{MATERIAL_LOGS}/plot_amontons_deviation.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_amontons_deviation"),
        runtime=measured_runtime("plot_amontons_deviation"),
    params:
        spheres=lambda wc: TARGETS.friction_spheres(wc.material),
        data_label=lambda wc: data_label(spheres_of(wc.material)),
        reference_load_mn=config["load_area"]["reference_load_mn"],
    script:
        "../../scripts/plot_amontons_deviation.py"


rule friction:
    """Target: friction of every sphere and the Amontons-deviation figure of every material."""
    input:
        TARGETS.friction(MATERIALS),
    localrule: True
