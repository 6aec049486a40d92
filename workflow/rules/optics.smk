# Measurements from optical images and spectra: contact area, PSF, grafting density, Newton-ring
# gap at the contact edge, intensity versus pressure, fluorescence lifetime, Hertz check.


rule measure_contact_area:
    input:
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        table=f"{MEASURED}/{CONTACT_AREA}",
        png=report(
            f"{MEASURED}/contact_area.png",
            caption="../report/contact_area.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf=f"{MEASURED}/contact_area.pdf",
    log:
        f"{SPHERE_LOGS}/measure_contact_area.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_contact_area.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_contact_area"),
        runtime=measured_runtime("measure_contact_area"),
    params:
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=lambda wc: fluorescence_choice(wc.sphere),
        otsu=OTSU,
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_contact_area.py"


rule measure_psf:
    input:
        bead=lambda wc: SPHERES.files.bead_image(wc.sphere),
    output:
        psf=f"{MEASURED}/{PSF}",
        png=report(
            f"{MEASURED}/psf.png",
            caption="../report/psf.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf=f"{MEASURED}/psf.pdf",
    log:
        f"{SPHERE_LOGS}/measure_psf.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_psf.benchmark.tsv"
    wildcard_constraints:
        sphere=SPHERES.inputs.psf_pattern("bead"),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_psf"),
        runtime=measured_runtime("measure_psf"),
    params:
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=IMAGES,
        # the bead's fit only: a changed stand-in re-runs no measured PSF
        psf=sorted_keys(
            {
                key: config["optics"]["psf"][key]
                for key in ("profile_radius_nm", "centroid_radius_nm")
            }
        ),
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_psf.py"


# A sphere without a bead image takes the config's PSF (optics.psf.stand_in), recorded as such.
rule stand_in_psf:
    output:
        psf=f"{MEASURED}/{PSF}",
    log:
        f"{SPHERE_LOGS}/stand_in_psf.log",
    benchmark:
        f"{SPHERE_LOGS}/stand_in_psf.benchmark.tsv"
    wildcard_constraints:
        sphere=SPHERES.inputs.psf_pattern("stand_in"),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("stand_in_psf"),
        runtime=measured_runtime("stand_in_psf"),
    params:
        stand_in=config["optics"]["psf"].get("stand_in"),
        looked_for=lambda wc: SPHERES.inputs.missing(wc.sphere)["bead"],
    script:
        "../../scripts/stand_in_psf.py"


rule measure_grafting_density:
    input:
        absorbance=lambda wc: SPHERES.files.absorbance_spectrum(wc.sphere),
    output:
        density=f"{MEASURED}/grafting_density.json",
        png=report(
            f"{MEASURED}/absorbance.png",
            caption="../report/absorbance.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf=f"{MEASURED}/absorbance.pdf",
    log:
        f"{SPHERE_LOGS}/measure_grafting_density.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_grafting_density.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_grafting_density"),
        runtime=measured_runtime("measure_grafting_density"),
    params:
        absorbance=config_slice("optics", "absorbance"),
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_grafting_density.py"


rule measure_edge_gap:
    input:
        reflection=lambda wc: reflection_image(wc.sphere),
        fluorescence=lambda wc: reflection_fluorescence(wc.sphere),
    output:
        gap=f"{MEASURED}/edge_gap.json",
        png=report(
            f"{MEASURED}/edge_gap.png",
            caption="../report/edge_gap.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf=f"{MEASURED}/edge_gap.pdf",
    log:
        f"{SPHERE_LOGS}/measure_edge_gap.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_edge_gap.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_edge_gap"),
        runtime=measured_runtime("measure_edge_gap"),
    params:
        reflection_load_mn=lambda wc: sheet_value(wc.sphere, "reflection_load_mn"),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=lambda wc: fluorescence_choice(wc.sphere),
        reflection_images=REFLECTION_IMAGES,
        otsu=OTSU,
        newton_rings=config_slice("optics", "newton_rings"),
        data_label=lambda wc: data_label([wc.sphere]),
        diameter_mm=lambda wc: float(sphere_row(wc.sphere)["diameter_mm"]),
        e_star_gpa=lambda wc: float(sphere_row(wc.sphere)["e_star_gpa"]),
    script:
        "../../scripts/measure_edge_gap.py"


rule measure_intensity_pressure:
    input:
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        table=f"{MEASURED}/intensity_pressure.csv",
        fit=f"{MEASURED}/intensity_pressure_fit.json",
        png=report(
            f"{MEASURED}/intensity_pressure.png",
            caption="../report/intensity_pressure.rst",
            category="Optics",
            subcategory="{material}",
        ),
        pdf=f"{MEASURED}/intensity_pressure.pdf",
    log:
        f"{SPHERE_LOGS}/measure_intensity_pressure.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_intensity_pressure.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_intensity_pressure"),
        runtime=measured_runtime("measure_intensity_pressure"),
    params:
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=lambda wc: fluorescence_choice(wc.sphere),
        otsu=OTSU,
        intensity=config_slice("optics", "intensity"),
        confidence=config["load_area"]["confidence"],
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/measure_intensity_pressure.py"


rule measure_lifetime:
    input:
        flim=lambda wc: SPHERES.files.flim_path(wc.sphere),
    output:
        lifetime=f"{MEASURED}/{LIFETIME}",
    log:
        f"{SPHERE_LOGS}/measure_lifetime.log",
    benchmark:
        f"{SPHERE_LOGS}/measure_lifetime.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("measure_lifetime"),
        runtime=measured_runtime("measure_lifetime"),
    params:
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=OTSU,
        lifetime=config_slice("optics", "lifetime"),
    script:
        "../../scripts/measure_lifetime.py"


rule check_hertz:
    input:
        table=rules.measure_contact_area.output.table,
    output:
        table=f"{MEASURED}/hertz_check.csv",
    log:
        f"{SPHERE_LOGS}/check_hertz.log",
    benchmark:
        f"{SPHERE_LOGS}/check_hertz.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("check_hertz"),
        runtime=measured_runtime("check_hertz"),
    params:
        diameter_mm=lambda wc: float(sphere_row(wc.sphere)["diameter_mm"]),
        e_star_gpa=lambda wc: float(sphere_row(wc.sphere)["e_star_gpa"]),
    script:
        "../../scripts/check_hertz.py"


rule optics:
    """Target: every optical measurement of every sphere."""
    input:
        TARGETS.optics(MATERIALS),
    localrule: True
