# Scenes: each sphere's AFM map pressed by the solver under a contact model, rendered like the
# microscope sees it and compared with the measured contact (docs/simulate.md). Only what a
# scene names is scheduled: no rendering, PSF or comparison job for `optics: none`, nothing of
# the experiment for a synthetic surface.


rule level_afm_map:
    input:
        afm_before=lambda wc: afm_path(wc.sphere, "afm_before"),
    output:
        levelled=f"{MEASURED}/afm_before_levelled.h5",
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
            **afm_reading(),
            "pixel_nm": sheet_value(wc.sphere, "afm_pixel_nm"),
        },
    script:
        "../../scripts/level_afm_map.py"


rule simulate_scene:
    input:
        levelled=f"{MEASURED}/afm_before_levelled.h5",
    output:
        fields=f"{SCENE}/fields.h5",
        solve=f"{SCENE}/solve.json",
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
        mem_mb=solve_mem_mb("simulate_scene", lambda wc: (wc.scene, wc.sphere)),
        runtime=solve_runtime("simulate_scene", lambda wc: (wc.scene, wc.sphere)),
    params:
        scene=lambda wc: scene_config(wc.scene),
        sphere=lambda wc: wc.sphere,
        sphere_record=lambda wc: scene_sphere_record(wc.sphere),
    script:
        "../../scripts/simulate_scene.py"


rule simulate_greenwood_tripp:
    input:
        levelled=f"{MEASURED}/afm_before_levelled.h5",
    output:
        solve=f"{SCENE}/solve.json",
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
        fields=f"{SYNTHETIC_SCENE}/fields.h5",
        solve=f"{SYNTHETIC_SCENE}/solve.json",
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
        mem_mb=solve_mem_mb("simulate_synthetic_scene", lambda wc: (wc.scene, None)),
        runtime=solve_runtime("simulate_synthetic_scene", lambda wc: (wc.scene, None)),
    params:
        scene=lambda wc: scene_config(wc.scene),
        sphere=None,
        sphere_record=None,
    script:
        "../../scripts/simulate_scene.py"


rule render_scene:
    input:
        fields=f"{SCENE}/fields.h5",
        psf=f"{MEASURED}/psf.json",
    output:
        rendered=f"{SCENE}/rendered.h5",
        table=f"{SCENE}/render.csv",
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
        otsu=otsu_settings(),
    script:
        "../../scripts/render_scene.py"


rule compare_scene:
    input:
        rendered=f"{SCENE}/rendered.h5",
        solve=f"{SCENE}/solve.json",
        fluorescence=lambda wc: per_load_inputs(wc.sphere, "fluorescence"),
    output:
        table=f"{SCENE}/comparison.csv",
        registration=f"{SCENE}/registration.json",
        png=report(
            f"{SCENE}/comparison.png",
            caption="../report/scene_comparison.rst",
            category="Scenes",
            subcategory="{material}",
        ),
        pdf=f"{SCENE}/comparison.pdf",
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
        otsu=otsu_settings(),
        data_label=lambda wc: data_label([wc.sphere]),
    script:
        "../../scripts/compare_scene.py"


rule fit_scene:
    input:
        unpack(scene_fit_inputs),
    output:
        fit=f"{SCENE}/scene_fit.json",
    log:
        f"{SCENE_LOGS}/fit_scene.log",
    benchmark:
        f"{SCENE_LOGS}/fit_scene.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("fit_scene"),
        runtime=measured_runtime("fit_scene"),
    params:
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/fit_scene.py"


rule fit_synthetic_scene:
    input:
        solve=f"{SYNTHETIC_SCENE}/solve.json",
    output:
        fit=f"{SYNTHETIC_SCENE}/scene_fit.json",
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
        confidence=config["load_area"]["confidence"],
    script:
        "../../scripts/fit_scene.py"


rule tabulate_scenes:
    input:
        measured=lambda wc: material_results(wc.material, "load_area_fit.json"),
        scenes=lambda wc: [
            f"{scene_dir(wc.material, sphere, scene)}/scene_fit.json"
            for sphere in spheres_of(wc.material)
            for scene in scene_names(surface="afm_before")
        ],
    output:
        table=report(
            f"{MATERIAL}/scenes.csv",
            caption="../report/scenes_table.rst",
            category="Scenes",
            subcategory="{material}",
        ),
    log:
        f"{LOGS}/{{material}}/tabulate_scenes.log",
    benchmark:
        f"{LOGS}/{{material}}/tabulate_scenes.benchmark.tsv"
    conda:
        "../envs/amontons.yaml"
    threads: 1
    resources:
        mem_mb=measured_mem_mb("tabulate_scenes"),
        runtime=measured_runtime("tabulate_scenes"),
    params:
        spheres=lambda wc: spheres_of(wc.material),
        scenes=scene_names(surface="afm_before"),
        models={name: scene["model"] for name, scene in SCENES.items()},
    script:
        "../../scripts/tabulate_scenes.py"


rule scenes:
    """Target: every scene of every sphere, and the synthetic scenes."""
    input:
        scene_outputs(MATERIALS) + synthetic_scene_outputs(),
    localrule: True
