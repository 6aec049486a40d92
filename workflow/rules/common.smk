# Helpers shared by the workflow files: validated config, the sample sheet and path lookups.
import os

from amontons.config import load_schema, load_workflow_config

SCHEMAS = os.path.join(workflow.basedir, "workflow", "schemas")
CONFIG_SOURCE = ", ".join(
    str(f) for f in (workflow.overwrite_configfiles or ["config/config.yaml"])
)
SPHERES = load_workflow_config(
    config,
    load_schema(os.path.join(SCHEMAS, "config.schema.yaml")),
    load_schema(os.path.join(SCHEMAS, "materials.schema.yaml")),
    CONFIG_SOURCE,
)
MATERIALS = list(config["materials"])


def sphere_row(sphere):
    return SPHERES.loc[sphere]


def spheres_of(material):
    return list(SPHERES.index[SPHERES["material"] == material])


def is_synthetic(sphere):
    return sphere_row(sphere)["data_source"] == "synthetic"


def raw_dir(sphere):
    """Folder of a sphere's raw data: the virtual experiment's, or the one the sheet names."""
    if is_synthetic(sphere):
        return f"resources/synthetic/{sphere}"
    return sphere_row(sphere)["data_source"]


def loads_mn(sphere):
    return list(sphere_row(sphere)["loads"])


def sphere_result(material, sphere, name):
    if sphere_row(sphere)["material"] != material:
        raise ValueError(
            f"sphere {sphere!r} is {sphere_row(sphere)['material']}, not {material}"
        )
    return f"results/{material}/{sphere}/{name}"


def material_results(material, name):
    """One file per sphere of ``material``."""
    return [sphere_result(material, s, name) for s in spheres_of(material)]


def data_label(spheres):
    """'synthetic data' if any of the spheres comes from the virtual experiment."""
    return (
        "synthetic data" if any(is_synthetic(s) for s in spheres) else "measured data"
    )


def material_outputs(materials):
    """The per-material deliverables: load-area table and figure."""
    return expand(
        "results/{material}/load_area.{ext}",
        material=materials,
        ext=["png", "pdf", "csv"],
    )
