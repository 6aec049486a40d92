# The study (docs/study.md): which contact model explains the experiment. Parameter scans of
# p_Y and k on each sphere's AFM map, one job per sphere and scan that solves its values in a
# chain, each value starting from the one before it (docs/cluster.md); the best value; the
# appendix's figures B.8-B.13 and the model-comparison table. Nothing here runs unless
# run_scans lists a scan.


rule scan_scene:
    input:
        levelled=rules.level_afm_map.output.levelled,
        psf=rules.measure_psf.output.psf,
        registration=RUN.scenes.scan_base_registration,
        # the sphere's elastic solve: the chain's first value starts from its pressures
        seed=RUN.scenes.scan_seed_fields,
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
        pixel_table=lambda wc: SPHERES.pixels.image_pixel_inputs(wc.sphere),
    output:
        # every value's result and rendered fields, a folder per value (the grid's and the
        # refinement's)
        values=directory(PATHS.scan_values()),
        # the model's error at the best value and the values refinement solved
        refinement=f"{SCAN}/{REFINEMENT}",
    log:
        f"{SCAN_LOGS}/scan_scene.log",
    benchmark:
        f"{SCAN_LOGS}/scan_scene.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        **SOLVE_GPU,
        mem_mb=solve_mem_mb(
            scan_solves(SCANS, RUN.scenes.scan_chain, SCAN_REFINED, SCAN_CHECK_FACTOR)
        ),
        runtime=solve_runtime(
            scan_solves(SCANS, RUN.scenes.scan_chain, SCAN_REFINED, SCAN_CHECK_FACTOR)
        ),
    params:
        **SOLVE_BACKEND,
        scan=lambda wc: RUN.scenes.scan_params(wc.sphere, wc.scan),
        # the values in the order they are solved, and where each one's files go
        chain=RUN.scenes.scan_value_files,
        base=lambda wc: scene_config(SCANS[wc.scan]["scene"]),
        sphere_record=lambda wc: scene_sphere_record(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=lambda wc: fluorescence_choice(wc.sphere),
        otsu=OTSU,
        judgement=SCAN_JUDGEMENT,
    script:
        "../../scripts/scan_scene.py"


rule best_scan_value:
    input:
        values=rules.scan_scene.output.values,
        refinement=rules.scan_scene.output.refinement,
    output:
        table=f"{SCAN}/{SCAN_TABLE}",
        best=f"{SCAN}/{BEST}",
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
        # every value's result, in the scan job's folder
        points=RUN.scenes.scan_points,
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/best_scan_value.py"


rule scans:
    """Target: every scan of every sphere, judged."""
    input:
        RUN.scenes.scan_outputs(MATERIALS),
    localrule: True


rule tabulate_models:
    input:
        lambda wc: flat_files(RUN.study.model_table_layout(wc.material)),
    output:
        table=report(
            f"{MATERIAL}/{MODELS_TABLE}",
            caption="../report/models_table.rst",
            category="Study",
            subcategory="{material}",
        ),
    log:
        f"{MATERIAL_LOGS}/tabulate_models.log",
    benchmark:
        f"{MATERIAL_LOGS}/tabulate_models.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("tabulate_models"),
        runtime=measured_runtime("tabulate_models"),
    params:
        layout=lambda wc: RUN.study.model_table_layout(wc.material),
        spheres=lambda wc: RUN.study.scanned(wc.material),
        models=RUN.scenes.models(),
        data_label=lambda wc: data_label(spheres_of(wc.material)),
    script:
        "../../scripts/tabulate_models.py"


rule plot_scan_maps:
    input:
        lambda wc: flat_files(list(RUN.study.scan_maps(wc).values())),
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
        scans=RUN.study.scan_maps,
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=lambda wc: fluorescence_choice(wc.sphere),
        otsu=OTSU,
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_scan_maps.py"


rule plot_load_series_maps:
    input:
        lambda wc: flat_files(RUN.study.load_series_layout(wc)),
        gt_solve=lambda wc: RUN.study.load_series_layout(wc)["gt_solve"],
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
        elastic=RUN.study.load_series_elastic,
        k_scan=RUN.study.k_scan,
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=lambda wc: fluorescence_choice(wc.sphere),
        otsu=OTSU,
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_load_series_maps.py"


rule plot_flattening_maps:
    input:
        lambda wc: flat_files(RUN.study.k_scan(wc)),
        before=lambda wc: afm_path(wc.sphere, "afm_before"),
        after=lambda wc: afm_path(wc.sphere, "afm_after"),
        # the scans' sphere fits: the maps are levelled again without fitting
        fits=f"{MEASURED}/{SPHERE_FITS}",
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
        k_scan=RUN.study.k_scan,
        afm=lambda wc: {
            **AFM_READING,
            "pixel_nm": sheet_value(wc.sphere, "afm_pixel_nm"),
        },
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_flattening_maps.py"


rule plot_model_curves:
    input:
        lambda wc: flat_files(RUN.study.model_curve_layout(wc)),
        measured=rules.measure_contact_area.output.table,
        measured_fit=rules.fit_load_area.output.fit,
    output:
        table=f"{STUDY}/{B12_FIGURE}.csv",
        png=report(
            f"{STUDY}/{B12_FIGURE}.png",
            caption="../report/study_b12.rst",
            category="Study",
            subcategory="{material}",
        ),
        pdf=f"{STUDY}/{B12_FIGURE}.pdf",
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
        scenes=lambda wc: RUN.study.model_curve_layout(wc)["scenes"],
        scans=lambda wc: RUN.study.model_curve_layout(wc)["scans"],
        confidence=config["load_area"]["confidence"],
        label=lambda wc: f"{wc.sphere} ({data_label([wc.sphere])})",
    script:
        "../../scripts/plot_model_curves.py"


rule plot_curvature_study:
    input:
        solves=list(RUN.study.curvature_files(SOLVE).values()),
        fits=list(RUN.study.curvature_files(SCENE_FITS).values()),
    output:
        table=f"{STUDY_RESULTS}/{B10_FIGURE}.csv",
        png=report(
            f"{STUDY_RESULTS}/{B10_FIGURE}.png",
            caption="../report/study_b10.rst",
            category="Study",
            subcategory="synthetic surfaces",
        ),
        pdf=f"{STUDY_RESULTS}/{B10_FIGURE}.pdf",
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
        solves=RUN.study.curvature_files(SOLVE),
        fits=RUN.study.curvature_files(SCENE_FITS),
    script:
        "../../scripts/plot_curvature_study.py"


rule plot_amontons_study:
    input:
        amontons=expand(
            rules.plot_amontons_deviation.output.table,
            material=SPHERES.materials_with(MATERIALS, RHEOMETER),
        ),
        bests=list(RUN.study.k_bests(MATERIALS).values()),
    output:
        table=f"{STUDY_RESULTS}/{B13_FIGURE}.csv",
        png=report(
            f"{STUDY_RESULTS}/{B13_FIGURE}.png",
            caption="../report/study_b13.rst",
            category="Study",
            subcategory="all materials",
        ),
        pdf=f"{STUDY_RESULTS}/{B13_FIGURE}.pdf",
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
        bests=RUN.study.k_bests(MATERIALS),
        reference_load_mn=config["load_area"]["reference_load_mn"],
        data_label=data_label(SPHERES),
    script:
        "../../scripts/plot_amontons_study.py"


rule study:
    """Target: the scans, the study's figures and model tables."""
    input:
        RUN.scenes.scan_outputs(MATERIALS)
        + RUN.study.outputs(MATERIALS)
        + RUN.study.overview_outputs(),
    localrule: True
