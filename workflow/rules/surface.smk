# The sphere's AFM topography: levelling, roughness statistics, and the plastic flattening.


rule measure_topography:
    input:
        before=lambda wc: afm_path(wc.sphere, "afm_before"),
        after=lambda wc: afm_path(wc.sphere, "afm_after"),
        # the before scan's sphere fit, as level_afm_map found it: not fitted twice
        before_fit=f"{MEASURED}/{BEFORE_FIT}",
    output:
        topography=f"{MEASURED}/topography.json",
        fits=f"{MEASURED}/{SPHERE_FITS}",
        png=report(
            f"{MEASURED}/topography.png",
            caption="../report/topography.rst",
            category="Surface",
            subcategory="{material}",
        ),
        pdf=f"{MEASURED}/topography.pdf",
    log:
        f"{SPHERE_LOGS}/measure_topography.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_topography.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_topography"),
        runtime=measured_runtime("measure_topography"),
    params:
        afm_pixel_nm=lambda wc: sheet_value(wc.sphere, "afm_pixel_nm"),
        nan_policy=config["surface"]["afm_nan_policy"],
        channel=config["surface"]["afm_channel"],
        line_levelling=config["surface"]["line_levelling"],
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_topography.py"


rule surface:
    """Target: the AFM topography of every sphere."""
    input:
        TARGETS.surface(MATERIALS),
    localrule: True
