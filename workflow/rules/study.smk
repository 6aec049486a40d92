# The study (docs/study.md): which contact model explains the experiment. Parameter scans of
# p_Y and k on each sphere's AFM map, each value a job of its own; the best value per sphere;
# the appendix's figures B.8-B.13 and the model-comparison table. Nothing here runs unless
# run_scans lists a scan.


rule scan_scene:
    input:
        levelled=f"{MEASURED}/afm_before_levelled.h5",
        psf=f"{MEASURED}/psf.json",
        registration=lambda wc: f"{scene_dir(wc.material, wc.sphere, SCANS[wc.scan]['scene'])}/registration.json",
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        point=f"{SCAN}/{{value}}/scan_point.json",
        fields=f"{SCAN}/{{value}}/rendered.h5",
    log:
        f"{SCAN_LOGS}/{{value}}/scan_scene.log",
    benchmark:
        f"{SCAN_LOGS}/{{value}}/scan_scene.benchmark.tsv"
    wildcard_constraints:
        value=r"[0-9][0-9.e+-]*",
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=solve_mem_mb("scan_scene", scan_solve),
        runtime=solve_runtime("scan_scene", scan_solve),
    params:
        scan=lambda wc: sorted_keys(SCANS[wc.scan]),
        base=lambda wc: scene_config(SCANS[wc.scan]["scene"]),
        sphere_record=lambda wc: scene_sphere_record(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=otsu_settings(),
    script:
        "../../scripts/scan_scene.py"


rule best_scan_value:
    input:
        points=scan_points,
    output:
        table=f"{SCAN}/scan.csv",
        best=f"{SCAN}/best.json",
    log:
        f"{SCAN_LOGS}/best_scan_value.log",
    benchmark:
        f"{SCAN_LOGS}/best_scan_value.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("best_scan_value"),
        runtime=measured_runtime("best_scan_value"),
    params:
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/best_scan_value.py"


rule scans:
    """Target: every scan of every sphere, judged."""
    input:
        scan_outputs(MATERIALS),
    localrule: True


rule tabulate_models:
    input:
        lambda wc: flat_files(model_table_layout(wc.material)),
    output:
        table=report(
            f"{MATERIAL}/models.csv",
            caption="../report/models_table.rst",
            category="Study",
            subcategory="{material}",
        ),
    log:
        f"{LOGS}/{{material}}/tabulate_models.log",
    benchmark:
        f"{LOGS}/{{material}}/tabulate_models.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("tabulate_models"),
        runtime=measured_runtime("tabulate_models"),
    params:
        layout=lambda wc: model_table_layout(wc.material),
        spheres=lambda wc: spheres_of(wc.material),
        models={name: scene["model"] for name, scene in SCENES.items()},
        data_label=lambda wc: data_label(spheres_of(wc.material)),
    script:
        "../../scripts/tabulate_models.py"


rule plot_scan_maps:
    input:
        lambda wc: flat_files(
            [scan_files(wc.material, wc.sphere, scan) for scan in SCANS]
        ),
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        table=f"{STUDY}/B8_scans.csv",
        png=report(
            f"{STUDY}/B8_scans.png",
            caption="../report/study_b8.rst",
            category="Study",
            subcategory="{material}",
        ),
        pdf=f"{STUDY}/B8_scans.pdf",
    log:
        f"{STUDY_LOGS}/plot_scan_maps.log",
    benchmark:
        f"{STUDY_LOGS}/plot_scan_maps.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_scan_maps"),
        runtime=measured_runtime("plot_scan_maps"),
    params:
        scans=lambda wc: {
            scan: scan_files(wc.material, wc.sphere, scan) for scan in SCANS
        },
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=otsu_settings(),
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_scan_maps.py"


rule plot_load_series_maps:
    input:
        lambda wc: flat_files(load_series_layout(wc)),
        gt_solve=lambda wc: load_series_layout(wc)["gt_solve"],
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        table=f"{STUDY}/B11_load_series.csv",
        png=report(
            f"{STUDY}/B11_load_series.png",
            caption="../report/study_b11.rst",
            category="Study",
            subcategory="{material}",
        ),
        pdf=f"{STUDY}/B11_load_series.pdf",
    log:
        f"{STUDY_LOGS}/plot_load_series_maps.log",
    benchmark:
        f"{STUDY_LOGS}/plot_load_series_maps.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_load_series_maps"),
        runtime=measured_runtime("plot_load_series_maps"),
    params:
        elastic=lambda wc: load_series_layout(wc)["elastic"],
        k_scan=study_k_scan,
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        otsu=otsu_settings(),
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_load_series_maps.py"


rule plot_flattening_maps:
    input:
        lambda wc: flat_files(study_k_scan(wc)),
        before=lambda wc: afm_path(wc.sphere, "afm_before"),
        after=lambda wc: afm_path(wc.sphere, "afm_after"),
    output:
        table=f"{STUDY}/B9_flattening.csv",
        png=report(
            f"{STUDY}/B9_flattening.png",
            caption="../report/study_b9.rst",
            category="Study",
            subcategory="{material}",
        ),
        pdf=f"{STUDY}/B9_flattening.pdf",
    log:
        f"{STUDY_LOGS}/plot_flattening_maps.log",
    benchmark:
        f"{STUDY_LOGS}/plot_flattening_maps.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_flattening_maps"),
        runtime=measured_runtime("plot_flattening_maps"),
    params:
        k_scan=study_k_scan,
        afm=lambda wc: {
            **afm_reading(),
            "pixel_nm": sheet_value(wc.sphere, "afm_pixel_nm"),
        },
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_flattening_maps.py"


rule plot_model_curves:
    input:
        lambda wc: flat_files(model_curve_layout(wc)),
        measured=f"{MEASURED}/contact_area.csv",
        measured_fit=f"{MEASURED}/load_area_fit.json",
    output:
        table=f"{STUDY}/B12_models.csv",
        png=report(
            f"{STUDY}/B12_models.png",
            caption="../report/study_b12.rst",
            category="Study",
            subcategory="{material}",
        ),
        pdf=f"{STUDY}/B12_models.pdf",
    log:
        f"{STUDY_LOGS}/plot_model_curves.log",
    benchmark:
        f"{STUDY_LOGS}/plot_model_curves.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_model_curves"),
        runtime=measured_runtime("plot_model_curves"),
    params:
        scenes=lambda wc: model_curve_layout(wc)["scenes"],
        scans=lambda wc: model_curve_layout(wc)["scans"],
        confidence=config["load_area"]["confidence"],
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_model_curves.py"


rule plot_curvature_study:
    input:
        [
            f"{SYNTHETIC_SCENE.format(scene=scene)}/{name}"
            for pair in CURVATURE_PAIRS.values()
            for scene in pair
            for name in ("solve.json", "scene_fit.json")
        ],
    output:
        table=f"{STUDY_RESULTS}/B10_curvature.csv",
        png=report(
            f"{STUDY_RESULTS}/B10_curvature.png",
            caption="../report/study_b10.rst",
            category="Study",
            subcategory="synthetic surfaces",
        ),
        pdf=f"{STUDY_RESULTS}/B10_curvature.pdf",
    log:
        f"{LOGS}/study/plot_curvature_study.log",
    benchmark:
        f"{LOGS}/study/plot_curvature_study.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_curvature_study"),
        runtime=measured_runtime("plot_curvature_study"),
    params:
        pairs=CURVATURE_PAIRS,
        solves={
            scene: f"{SYNTHETIC_SCENE.format(scene=scene)}/solve.json"
            for pair in CURVATURE_PAIRS.values()
            for scene in pair
        },
        fits={
            scene: f"{SYNTHETIC_SCENE.format(scene=scene)}/scene_fit.json"
            for pair in CURVATURE_PAIRS.values()
            for scene in pair
        },
    script:
        "../../scripts/plot_curvature_study.py"


rule plot_amontons_study:
    input:
        amontons=[f"{MATERIAL.format(material=m)}/amontons.csv" for m in MATERIALS],
        bests=(
            [
                f"{scan_dir(m, s, scans_of('k_mpa_per_nm')[0])}/best.json"
                for m in MATERIALS
                for s in spheres_of(m)
            ]
            if scans_of("k_mpa_per_nm")
            else []
        ),
    output:
        table=f"{STUDY_RESULTS}/B13_amontons.csv",
        png=report(
            f"{STUDY_RESULTS}/B13_amontons.png",
            caption="../report/study_b13.rst",
            category="Study",
            subcategory="all materials",
        ),
        pdf=f"{STUDY_RESULTS}/B13_amontons.pdf",
    log:
        f"{LOGS}/study/plot_amontons_study.log",
    benchmark:
        f"{LOGS}/study/plot_amontons_study.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("plot_amontons_study"),
        runtime=measured_runtime("plot_amontons_study"),
    params:
        bests=(
            {
                s: f"{scan_dir(m, s, scans_of('k_mpa_per_nm')[0])}/best.json"
                for m in MATERIALS
                for s in spheres_of(m)
            }
            if scans_of("k_mpa_per_nm")
            else {}
        ),
        reference_load_mn=config["load_area"]["reference_load_mn"],
        data_label=data_label(SPHERES),
    script:
        "../../scripts/plot_amontons_study.py"


rule study:
    """Target: the scans, the study's figures and model tables."""
    input:
        scan_outputs(MATERIALS) + study_outputs(MATERIALS) + study_overview_outputs(),
    localrule: True
