# Measurements from optical images and spectra: contact area, PSF, grafting density, Newton-ring
# gap at the contact edge, intensity versus pressure, fluorescence lifetime, Hertz check.


rule measure_contact_area:
    input:
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        table="results/{material}/{sphere}/contact_area.csv",
        png=report(
            "results/{material}/{sphere}/contact_area.png",
            caption="../report/contact_area.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf="results/{material}/{sphere}/contact_area.pdf",
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
        fluorescence_dir=lambda wc: per_load_dir(wc.sphere, "fluorescence"),
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=otsu_settings(),
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_contact_area.py"


rule measure_psf:
    input:
        bead=lambda wc: raw_file(wc.sphere, "bead.tif"),
    output:
        psf="results/{material}/{sphere}/psf.json",
        png=report(
            "results/{material}/{sphere}/psf.png",
            caption="../report/psf.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf="results/{material}/{sphere}/psf.pdf",
    log:
        "logs/{material}/{sphere}/measure_psf.log",
    benchmark:
        "logs/{material}/{sphere}/measure_psf.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        psf=config["optics"]["psf"],
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_psf.py"


rule measure_grafting_density:
    input:
        absorbance=lambda wc: raw_file(wc.sphere, "absorbance.csv"),
    output:
        density="results/{material}/{sphere}/grafting_density.json",
        png=report(
            "results/{material}/{sphere}/absorbance.png",
            caption="../report/absorbance.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf="results/{material}/{sphere}/absorbance.pdf",
    log:
        "logs/{material}/{sphere}/measure_grafting_density.log",
    benchmark:
        "logs/{material}/{sphere}/measure_grafting_density.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        absorbance=config["optics"]["absorbance"],
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_grafting_density.py"


rule measure_edge_gap:
    input:
        reflection=lambda wc: raw_file(wc.sphere, "reflection.tif"),
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        gap="results/{material}/{sphere}/edge_gap.json",
        png=report(
            "results/{material}/{sphere}/edge_gap.png",
            caption="../report/edge_gap.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf="results/{material}/{sphere}/edge_gap.pdf",
    log:
        "logs/{material}/{sphere}/measure_edge_gap.log",
    benchmark:
        "logs/{material}/{sphere}/measure_edge_gap.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        fluorescence_dir=lambda wc: per_load_dir(wc.sphere, "fluorescence"),
        reflection_load_mn=lambda wc: sheet_value(wc.sphere, "reflection_load_mn"),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=otsu_settings(),
        newton_rings=config["optics"]["newton_rings"],
        data_label=lambda wc: data_label([wc.sphere]),
        diameter_mm=lambda wc: float(sphere_row(wc.sphere)["diameter_mm"]),
        e_star_gpa=lambda wc: float(sphere_row(wc.sphere)["e_star_gpa"]),
    script:
        "../../scripts/measure_edge_gap.py"


rule measure_intensity_pressure:
    input:
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        table="results/{material}/{sphere}/intensity_pressure.csv",
        fit="results/{material}/{sphere}/intensity_pressure_fit.json",
        png=report(
            "results/{material}/{sphere}/intensity_pressure.png",
            caption="../report/intensity_pressure.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf="results/{material}/{sphere}/intensity_pressure.pdf",
    log:
        "logs/{material}/{sphere}/measure_intensity_pressure.log",
    benchmark:
        "logs/{material}/{sphere}/measure_intensity_pressure.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        fluorescence_dir=lambda wc: per_load_dir(wc.sphere, "fluorescence"),
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=otsu_settings(),
        intensity=config["optics"]["intensity"],
        confidence=config["load_area"]["confidence"],
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_intensity_pressure.py"


rule measure_lifetime:
    input:
        flim=lambda wc: raw_file(wc.sphere, "flim.tif"),
    output:
        lifetime="results/{material}/{sphere}/lifetime.json",
    log:
        "logs/{material}/{sphere}/measure_lifetime.log",
    benchmark:
        "logs/{material}/{sphere}/measure_lifetime.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=otsu_settings(),
        lifetime=config["optics"]["lifetime"],
    script:
        "../../scripts/measure_lifetime.py"


rule check_hertz:
    input:
        table="results/{material}/{sphere}/contact_area.csv",
    output:
        table="results/{material}/{sphere}/hertz_check.csv",
    log:
        "logs/{material}/{sphere}/check_hertz.log",
    benchmark:
        "logs/{material}/{sphere}/check_hertz.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        diameter_mm=lambda wc: float(sphere_row(wc.sphere)["diameter_mm"]),
        e_star_gpa=lambda wc: float(sphere_row(wc.sphere)["e_star_gpa"]),
    script:
        "../../scripts/check_hertz.py"


rule optics:
    """Target: every optical measurement of every sphere."""
    input:
        optics_outputs(MATERIALS),
    localrule: True
