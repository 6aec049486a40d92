# Scenes: each sphere's AFM map pressed by the solver under a contact model, rendered like the
# microscope sees it and compared with the measured contact (docs/simulate.md). Only what a
# scene names is scheduled: no rendering, PSF or comparison job for `optics: none`, nothing of
# the experiment for a synthetic surface.


rule level_afm_map:
    input:
        afm_before=lambda wc: afm_path(wc.sphere, "afm_before"),
    output:
        levelled=f"{MEASURED}/{LEVELLED_MAP}",
        fit=f"{MEASURED}/{BEFORE_FIT}",
    log:
        f"{SPHERE_LOGS}/level_afm_map.log",
    benchmark:
        f"{SPHERE_LOGS}/level_afm_map.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("level_afm_map"),
        runtime=measured_runtime("level_afm_map"),
    params:
        afm=lambda wc: {
            **AFM_READING,
            "pixel_nm": sheet_value(wc.sphere, "afm_pixel_nm"),
        },
    script:
        "../../scripts/level_afm_map.py"


rule simulate_scene:
    input:
        levelled=rules.level_afm_map.output.levelled,
    output:
        fields=f"{SCENE}/{FIELDS}",
        solve=f"{SCENE}/{SOLVE}",
    log:
        f"{SCENE_LOGS}/simulate_scene.log",
    benchmark:
        f"{SCENE_LOGS}/simulate_scene.benchmark.tsv"
    wildcard_constraints:
        scene=names_pattern(scene_names(surface="afm_before", field=True)),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        **SOLVE_GPU,
        mem_mb=solve_mem_mb(lambda wc: [(wc.scene, wc.sphere)]),
        runtime=solve_runtime(lambda wc: [(wc.scene, wc.sphere)]),
    params:
        **SOLVE_BACKEND,
        scene=lambda wc: scene_config(wc.scene),
        sphere=lambda wc: wc.sphere,
        sphere_record=lambda wc: scene_sphere_record(wc.sphere),
    script:
        "../../scripts/simulate_scene.py"


rule simulate_greenwood_tripp:
    input:
        levelled=rules.level_afm_map.output.levelled,
    output:
        solve=f"{SCENE}/{SOLVE}",
    log:
        f"{SCENE_LOGS}/simulate_greenwood_tripp.log",
    benchmark:
        f"{SCENE_LOGS}/simulate_greenwood_tripp.benchmark.tsv"
    wildcard_constraints:
        scene=names_pattern(scene_names(surface="afm_before", field=False)),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("simulate_greenwood_tripp"),
        runtime=measured_runtime("simulate_greenwood_tripp"),
    params:
        scene=lambda wc: scene_config(wc.scene),
        sphere=lambda wc: wc.sphere,
        sphere_record=lambda wc: scene_sphere_record(wc.sphere),
    script:
        "../../scripts/simulate_greenwood_tripp.py"


rule simulate_synthetic_scene:
    output:
        fields=f"{SYNTHETIC_SCENE}/{FIELDS}",
        solve=f"{SYNTHETIC_SCENE}/{SOLVE}",
    log:
        f"{SYNTHETIC_SCENE_LOGS}/simulate_scene.log",
    benchmark:
        f"{SYNTHETIC_SCENE_LOGS}/simulate_scene.benchmark.tsv"
    wildcard_constraints:
        scene=names_pattern(scene_names(surface="synthetic")),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        **SOLVE_GPU,
        mem_mb=solve_mem_mb(lambda wc: [(wc.scene, None)]),
        runtime=solve_runtime(lambda wc: [(wc.scene, None)]),
    params:
        **SOLVE_BACKEND,
        scene=lambda wc: scene_config(wc.scene),
        sphere=None,
        sphere_record=None,
    script:
        "../../scripts/simulate_scene.py"


rule render_scene:
    input:
        fields=rules.simulate_scene.output.fields,
        psf=rules.measure_psf.output.psf,
        pixel_table=lambda wc: SPHERES.pixels.image_pixel_inputs(wc.sphere),
    output:
        rendered=f"{SCENE}/{RENDERED}",
        table=f"{SCENE}/{RENDER_TABLE}",
    log:
        f"{SCENE_LOGS}/render_scene.log",
    benchmark:
        f"{SCENE_LOGS}/render_scene.benchmark.tsv"
    wildcard_constraints:
        scene=names_pattern(scene_names(surface="afm_before", optics="microscope")),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("render_scene"),
        runtime=measured_runtime("render_scene"),
    params:
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        rendering=lambda wc: SCENES[wc.scene]["rendering"],
        confinement_floor_mpa=lambda wc: SCENES[wc.scene]["confinement_floor_mpa"],
        otsu=OTSU,
    script:
        "../../scripts/render_scene.py"


rule compare_scene:
    input:
        rendered=rules.render_scene.output.rendered,
        solve=rules.simulate_scene.output.solve,
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
        # the sphere's registration, found once on its first microscope scene
        sphere_registration=RUN.scenes.sphere_registration,
    output:
        table=f"{SCENE}/{COMPARISON}",
        registration=f"{SCENE}/{REGISTRATION}",
        png=report(
            f"{SCENE}/{COMPARISON_FIGURE}.png",
            caption="../report/scene_comparison.rst",
            category="Scenes",
            subcategory="{material}",
        ),
        pdf=f"{SCENE}/{COMPARISON_FIGURE}.pdf",
    log:
        f"{SCENE_LOGS}/compare_scene.log",
    benchmark:
        f"{SCENE_LOGS}/compare_scene.benchmark.tsv"
    wildcard_constraints:
        scene=names_pattern(scene_names(surface="afm_before", optics="microscope")),
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("compare_scene"),
        runtime=measured_runtime("compare_scene"),
    params:
        loads_mn=lambda wc: loads_mn(wc.sphere),
        pixel_nm=lambda wc: pixel_nm(wc.sphere),
        images=lambda wc: fluorescence_choice(wc.sphere),
        otsu=OTSU,
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/compare_scene.py"


# A sphere's scenes are fitted in one job: each fit takes milliseconds, a job's start and
# imports seconds (docs/study.md §5). A changed scene re-runs its sphere's fits, which only
# its material's scene and model tables read (and they read every scene of the material).
rule fit_sphere_scenes:
    input:
        lambda wc: flat_files(RUN.scenes.fit_layout(wc.material, wc.sphere)),
    output:
        fits=f"{SPHERE_SCENES}/{SCENE_FITS}",
    log:
        f"{SPHERE_SCENES_LOGS}/fit_sphere_scenes.log",
    benchmark:
        f"{SPHERE_SCENES_LOGS}/fit_sphere_scenes.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("fit_sphere_scenes"),
        runtime=measured_runtime("fit_sphere_scenes"),
    params:
        layout=lambda wc: RUN.scenes.fit_layout(wc.material, wc.sphere),
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/fit_scenes.py"


rule fit_synthetic_scene:
    input:
        solve=rules.simulate_synthetic_scene.output.solve,
    output:
        fits=f"{SYNTHETIC_SCENE}/{SCENE_FITS}",
    log:
        f"{SYNTHETIC_SCENE_LOGS}/fit_scene.log",
    benchmark:
        f"{SYNTHETIC_SCENE_LOGS}/fit_scene.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("fit_synthetic_scene"),
        runtime=measured_runtime("fit_synthetic_scene"),
    params:
        layout=lambda wc: RUN.scenes.synthetic_fit_layout(wc.scene),
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/fit_scenes.py"


rule tabulate_scenes:
    input:
        measured=lambda wc: [
            PATHS.measured(LOAD_AREA_FIT, wc.material, sphere)
            for sphere in RUN.scenes.table_layout(wc.material)
        ],
        scenes=lambda wc: flat_files(RUN.scenes.table_layout(wc.material)),
    output:
        table=report(
            f"{MATERIAL}/scenes.csv",
            caption="../report/scenes_table.rst",
            category="Scenes",
            subcategory="{material}",
        ),
    log:
        f"{MATERIAL_LOGS}/tabulate_scenes.log",
    benchmark:
        f"{MATERIAL_LOGS}/tabulate_scenes.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("tabulate_scenes"),
        runtime=measured_runtime("tabulate_scenes"),
    params:
        layout=lambda wc: RUN.scenes.table_layout(wc.material),
        models=RUN.scenes.models(),
    script:
        "../../scripts/tabulate_scenes.py"


rule scenes:
    """Target: every scene of every sphere, and the synthetic scenes."""
    input:
        RUN.scenes.outputs(MATERIALS) + RUN.scenes.synthetic_outputs(),
    localrule: True
