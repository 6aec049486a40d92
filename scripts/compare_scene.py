"""Rule compare_scene: a scene's rendered contact registered on the sphere's measured
fluorescence images, and compared load by load (amontons.study.scene_comparison)."""

from amontons.runlog import run_logged
from amontons.study.scene_comparison import Outputs, compare_scene


def main(table_path: str, registration_path: str, figure_paths: list[str], **comparison) -> None:
    """The comparison (:func:`compare_scene`'s other arguments) into its outputs."""
    compare_scene(outputs=Outputs(table_path, registration_path, figure_paths), **comparison)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        rendered_path=sm.input.rendered,
        solve_path=sm.input.solve,
        fluorescence=sm.input.fluorescence,
        sphere_registration_path=(
            sm.input.sphere_registration[0] if sm.input.sphere_registration else None
        ),
        table_path=sm.output.table,
        registration_path=sm.output.registration,
        figure_paths=[sm.output.png, sm.output.pdf],
        loads_mn=sm.params.loads_mn,
        pixel_nm=sm.params.pixel_nm,
        images=sm.params.images,
        otsu=sm.params.otsu,
        data_label=sm.params.data_label,
        scene=sm.wildcards.scene,
        label=f"{sm.wildcards.sphere}, scene {sm.wildcards.scene}",
    )
