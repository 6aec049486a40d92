# The virtual experiment: raw data with known truth for spheres whose data_source is 'synthetic'.
# Spheres with a FLIM map (flim_load_mn in the sheet) use the second rule, which also writes
# flim.tif; a rule's outputs cannot vary per sphere.


rule generate_virtual_experiment:
    output:
        fluorescence=directory("resources/synthetic/{sphere}/fluorescence"),
        rheometer=directory("resources/synthetic/{sphere}/rheometer"),
        reflection="resources/synthetic/{sphere}/reflection.tif",
        bead="resources/synthetic/{sphere}/bead.tif",
        absorbance="resources/synthetic/{sphere}/absorbance.csv",
        afm_before="resources/synthetic/{sphere}/afm_before.tif",
        afm_after="resources/synthetic/{sphere}/afm_after.tif",
        truth="resources/synthetic/{sphere}/truth.json",
    log:
        "logs/virtual_experiment/{sphere}.log",
    benchmark:
        "logs/virtual_experiment/{sphere}.benchmark.tsv"
    wildcard_constraints:
        sphere=flim_spheres_pattern(with_flim=False),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=4000,
        runtime=20,
    params:
        sphere=lambda wc: wc.sphere,
        diameter_mm=lambda wc: float(sphere_row(wc.sphere)["diameter_mm"]),
        e_star_gpa=lambda wc: float(sphere_row(wc.sphere)["e_star_gpa"]),
        roughness_rms_nm=lambda wc: sheet_value(wc.sphere, "roughness_rms_nm"),
        hardening_k_mpa_per_nm=lambda wc: sheet_value(
            wc.sphere, "hardening_k_mpa_per_nm"
        ),
        loads_mn=lambda wc: loads_mn(wc.sphere),
        reflection_load_mn=lambda wc: sheet_value(wc.sphere, "reflection_load_mn"),
        flim_load_mn=lambda wc: sheet_value(wc.sphere, "flim_load_mn"),
        shear_strength_mpa=lambda wc: sheet_value(wc.sphere, "shear_strength_mpa"),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        settings=config["virtual_experiment"],
        seed=config["seed"],
    script:
        "../../scripts/generate_virtual_experiment.py"


use rule generate_virtual_experiment as generate_virtual_experiment_with_flim with:
    output:
        fluorescence=directory("resources/synthetic/{sphere}/fluorescence"),
        rheometer=directory("resources/synthetic/{sphere}/rheometer"),
        reflection="resources/synthetic/{sphere}/reflection.tif",
        bead="resources/synthetic/{sphere}/bead.tif",
        absorbance="resources/synthetic/{sphere}/absorbance.csv",
        afm_before="resources/synthetic/{sphere}/afm_before.tif",
        afm_after="resources/synthetic/{sphere}/afm_after.tif",
        flim="resources/synthetic/{sphere}/flim.tif",
        truth="resources/synthetic/{sphere}/truth.json",
    wildcard_constraints:
        sphere=flim_spheres_pattern(with_flim=True),


rule virtual_experiment:
    """Target: the virtual experiment of every synthetic sphere."""
    input:
        [
            f"resources/synthetic/{s}/truth.json"
            for s in SPHERES.index
            if is_synthetic(s)
        ],
    localrule: True
