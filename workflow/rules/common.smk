# Helpers shared by the workflow files: validated config, the sample sheet and path lookups.
import os

import pandas as pd

from amontons.config import load_schema, load_workflow_config
from amontons.measurements import afm_file
from amontons.rawdata import AFM_SUFFIXES, fluorescence_images, rheometer_files

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


def check_sheet_loads(spheres):
    """The reflection and FLIM loads of each sphere must be among its loads_mn."""
    for sphere, row in spheres.iterrows():
        for column in ("reflection_load_mn", "flim_load_mn"):
            value = row.get(column)
            if value is None or pd.isna(value):
                continue
            if not any(abs(float(value) - load) < 1e-9 for load in row["loads"]):
                raise ValueError(
                    f"{config['materials_sheet']}, sphere {sphere}: {column} = {value:g} is not "
                    f"one of loads_mn {row['loads']}; expected the load of an existing image"
                )


check_sheet_loads(SPHERES)


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


def sheet_value(sphere, column):
    """A numeric sheet value, or None where the cell is empty."""
    value = sphere_row(sphere).get(column)
    return None if value is None or pd.isna(value) else float(value)


def pixel_nm(sphere):
    return float(sphere_row(sphere)["fluorescence_pixel_nm"])


def per_load_dir(sphere, kind):
    """A sphere's folder of per-load raw files: 'fluorescence' or 'rheometer'."""
    return f"{raw_dir(sphere)}/{kind}"


def per_load_inputs(sphere, kind):
    """Inputs of a per-load folder. Measured data: each load's file, so that a replaced file
    re-runs the jobs that read it (a folder's time does not change when a file in it is
    overwritten); a folder that does not match the loads stops the run here, naming it.
    Synthetic data: the folder, which the virtual experiment writes whole."""
    folder = per_load_dir(sphere, kind)
    if is_synthetic(sphere):
        return folder
    files = fluorescence_images if kind == "fluorescence" else rheometer_files
    return [str(path) for path in files(folder, loads_mn(sphere))]


def raw_file(sphere, name):
    """Path of one raw file of a sphere (e.g. 'bead.tif')."""
    return f"{raw_dir(sphere)}/{name}"


def afm_path(sphere, stem):
    """A sphere's AFM height map ``stem`` (afm_before / afm_after): the virtual experiment
    writes TIFF; measured data may be TIFF, .npy or a Gwyddion text export (two formats of
    one map stop the run, naming both). With none present the TIFF is named, so the missing
    input is reported by that name."""
    folder = raw_dir(sphere)
    present = [ext for ext in AFM_SUFFIXES if os.path.isfile(f"{folder}/{stem}{ext}")]
    if is_synthetic(sphere) or not present:
        return raw_file(sphere, f"{stem}.tif")
    return str(afm_file(folder, stem))


def reflection_fluorescence(sphere):
    """The fluorescence image recorded at the sphere's reflection load."""
    load = sheet_value(sphere, "reflection_load_mn")
    return f"{raw_dir(sphere)}/fluorescence/{load:g}.tif"


def has_flim(sphere):
    """Synthetic spheres get a FLIM map where the sheet gives flim_load_mn; measured spheres
    have one where their folder holds flim.tif."""
    if is_synthetic(sphere):
        return sheet_value(sphere, "flim_load_mn") is not None
    return os.path.isfile(raw_file(sphere, "flim.tif"))


def flim_spheres_pattern(with_flim):
    """Regex matching the synthetic spheres with (or without) a FLIM map; never empty-match."""
    names = [s for s in SPHERES.index if is_synthetic(s) and has_flim(s) == with_flim]
    return "|".join(map(re.escape, names)) or "(?!)"


def sphere_result(material, sphere, name):
    if sphere_row(sphere)["material"] != material:
        raise ValueError(
            f"sphere {sphere!r} is {sphere_row(sphere)['material']}, not {material}"
        )
    return f"results/{material}/{sphere}/{name}"


def material_results(material, name):
    """One file per sphere of ``material``."""
    return [sphere_result(material, s, name) for s in spheres_of(material)]


def otsu_settings():
    """The optics keys that decide where a contact is and whether there is one."""
    return {
        key: config["optics"][key]
        for key in ("otsu_bins", "min_separation", "min_contrast", "min_patch_px")
    }


def data_label(spheres):
    """'synthetic data' if any of the spheres comes from the virtual experiment."""
    return (
        "synthetic data" if any(is_synthetic(s) for s in spheres) else "measured data"
    )


# Per-sphere results of each stage; lifetime only where a FLIM map exists.
OPTICS_RESULTS = [
    "contact_area.csv",
    "contact_area.png",
    "contact_area.pdf",
    "psf.json",
    "psf.png",
    "psf.pdf",
    "grafting_density.json",
    "absorbance.png",
    "absorbance.pdf",
    "edge_gap.json",
    "edge_gap.png",
    "edge_gap.pdf",
    "intensity_pressure.csv",
    "intensity_pressure_fit.json",
    "intensity_pressure.png",
    "intensity_pressure.pdf",
    "hertz_check.csv",
]
FRICTION_RESULTS = ["friction.csv"]
SURFACE_RESULTS = ["topography.json", "topography.png", "topography.pdf"]
FIT_RESULTS = ["load_area_fit.json"]


def sphere_outputs(material, names):
    return [sphere_result(material, s, n) for s in spheres_of(material) for n in names]


def optics_outputs(materials):
    """Every optical measurement of every sphere of ``materials``."""
    out = []
    for material in materials:
        out += sphere_outputs(material, OPTICS_RESULTS)
        out += [
            sphere_result(material, s, "lifetime.json")
            for s in spheres_of(material)
            if has_flim(s)
        ]
    return out


def friction_outputs(materials):
    """Friction per sphere and the Amontons-deviation figure and table per material."""
    out = [f for m in materials for f in sphere_outputs(m, FRICTION_RESULTS)]
    return out + expand(
        "results/{material}/amontons.{ext}",
        material=materials,
        ext=["png", "pdf", "csv"],
    )


def figure_outputs(materials):
    """The per-material figures and tables: load-area and Amontons deviation."""
    return expand(
        "results/{material}/{name}.{ext}",
        material=materials,
        name=["load_area", "amontons"],
        ext=["png", "pdf", "csv"],
    )


def material_outputs(materials):
    """Everything a material's target builds: every measurement, fit, figure and table."""
    fits = [f for m in materials for f in sphere_outputs(m, FIT_RESULTS)]
    surface = [f for m in materials for f in sphere_outputs(m, SURFACE_RESULTS)]
    everything = (
        optics_outputs(materials)
        + surface
        + friction_outputs(materials)
        + fits
        + figure_outputs(materials)
    )
    return list(dict.fromkeys(everything))  # once each, in order
