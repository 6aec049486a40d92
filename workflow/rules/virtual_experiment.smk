# The virtual experiment: raw data with known truth for spheres whose data_source is 'synthetic'.


rule generate_virtual_experiment:
    output:
        fluorescence=directory("resources/synthetic/{sphere}/fluorescence"),
        truth="resources/synthetic/{sphere}/truth.json",
    log:
        "logs/virtual_experiment/{sphere}.log",
    benchmark:
        "logs/virtual_experiment/{sphere}.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        sphere=lambda wc: wc.sphere,
        diameter_mm=lambda wc: float(sphere_row(wc.sphere)["diameter_mm"]),
        e_star_gpa=lambda wc: float(sphere_row(wc.sphere)["e_star_gpa"]),
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: float(sphere_row(wc.sphere)["fluorescence_pixel_nm"]),
        settings=config["virtual_experiment"],
        seed=config["seed"],
    script:
        "../../scripts/generate_virtual_experiment.py"


rule virtual_experiment:
    """Target: the virtual experiment of every synthetic sphere."""
    input:
        [
            f"resources/synthetic/{s}/truth.json"
            for s in SPHERES.index
            if is_synthetic(s)
        ],
    localrule: True
