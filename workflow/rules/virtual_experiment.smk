# The virtual experiment: raw data with known truth for spheres whose data_source is 'synthetic'.
# Spheres with a FLIM map (flim_load_mn in the sheet) use the second rule, which also writes
# flim.tif; a rule's outputs cannot vary per sphere.


rule generate_virtual_experiment:
    output:
        fluorescence=directory(f"{SYNTHETIC_SPHERE}/fluorescence"),
        rheometer=directory(f"{SYNTHETIC_SPHERE}/rheometer"),
        reflection=f"{SYNTHETIC_SPHERE}/reflection{SYNTHETIC_IMAGE}",
        bead=f"{SYNTHETIC_SPHERE}/bead{SYNTHETIC_IMAGE}",
        absorbance=f"{SYNTHETIC_SPHERE}/absorbance.csv",
        afm_before=f"{SYNTHETIC_SPHERE}/afm_before.tif",
        afm_after=f"{SYNTHETIC_SPHERE}/afm_after.tif",
        truth=f"{SYNTHETIC_SPHERE}/{TRUTH}",
    log:
        f"{LOGS}/virtual_experiment/{{sphere}}.log",
    benchmark:
        f"{LOGS}/virtual_experiment/{{sphere}}.benchmark.tsv"
    wildcard_constraints:
        sphere=SPHERES.files.synthetic_pattern(with_flim=False),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("generate_virtual_experiment"),
        runtime=measured_runtime("generate_virtual_experiment"),
    params:
        sphere=lambda wc: wc.sphere,
        diameter_mm=lambda wc: float(sphere_row(wc.sphere)["diameter_mm"]),
        e_star_gpa=lambda wc: float(sphere_row(wc.sphere)["e_star_gpa"]),
        roughness_rms_nm=lambda wc: sheet_value(wc.sphere, "roughness_rms_nm"),
        true_model=lambda wc: SPHERES.rows.true_model(wc.sphere),
        true_value=lambda wc: SPHERES.rows.true_value(wc.sphere),
        loads_mn=lambda wc: loads_mn(wc.sphere),
        reflection_load_mn=lambda wc: sheet_value(wc.sphere, "reflection_load_mn"),
        flim_load_mn=lambda wc: sheet_value(wc.sphere, "flim_load_mn"),
        shear_strength_mpa=lambda wc: sheet_value(wc.sphere, "shear_strength_mpa"),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        settings=config_slice("virtual_experiment"),
        newton_rings=RING_OPTICS,
        seed=config["seed"],
    script:
        "../../scripts/generate_virtual_experiment.py"


use rule generate_virtual_experiment as generate_virtual_experiment_with_flim with:
    output:
        fluorescence=directory(f"{SYNTHETIC_SPHERE}/fluorescence"),
        rheometer=directory(f"{SYNTHETIC_SPHERE}/rheometer"),
        reflection=f"{SYNTHETIC_SPHERE}/reflection{SYNTHETIC_IMAGE}",
        bead=f"{SYNTHETIC_SPHERE}/bead{SYNTHETIC_IMAGE}",
        absorbance=f"{SYNTHETIC_SPHERE}/absorbance.csv",
        afm_before=f"{SYNTHETIC_SPHERE}/afm_before.tif",
        afm_after=f"{SYNTHETIC_SPHERE}/afm_after.tif",
        flim=f"{SYNTHETIC_SPHERE}/flim.{config['virtual_experiment']['formats']['flim']}",
        truth=f"{SYNTHETIC_SPHERE}/{TRUTH}",
    wildcard_constraints:
        sphere=SPHERES.files.synthetic_pattern(with_flim=True),


rule virtual_experiment:
    """Target: the virtual experiment of every synthetic sphere."""
    input:
        TARGETS.virtual_experiment(),
    localrule: True
