# Measurements from optical images.


rule measure_contact_area:
    input:
        fluorescence=lambda wc: f"{raw_dir(wc.sphere)}/fluorescence",
    output:
        table="results/{material}/{sphere}/contact_area.csv",
    log:
        "logs/{material}/{sphere}/measure_contact_area.log",
    benchmark:
        "logs/{material}/{sphere}/measure_contact_area.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: float(sphere_row(wc.sphere)["fluorescence_pixel_nm"]),
        optics=config["optics"],
    script:
        "../../scripts/measure_contact_area.py"


rule optics:
    """Target: contact areas of every sphere."""
    input:
        [material_results(m, "contact_area.csv") for m in MATERIALS],
    localrule: True
