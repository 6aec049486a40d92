"""The validation study on the materials sheet's spheres (docs/study.md §7, issue 76): which
cases it runs, the sphere each is on as the virtual experiment makes it, the pixel the run's
preset solves it at, its priors, and the spheres a run cannot validate on, named. The solves
run in the small run (tests/workflow/test_validation_run.py)."""

import copy
from pathlib import Path

import pytest

from amontons import models
from amontons.config import read_config
from amontons.config.schema import load_schema
from amontons.config.sheet import read_sample_sheet
from amontons.contact.options import ITERATIONS
from amontons.validation.cases import Case, case_named, sphere_case_names, sphere_cases
from amontons.validation.study import sheet_priors
from amontons.validation.truth import Sphere, study_pixel_m
from amontons.workflow.validation import (
    left_out_validation_spheres,
    runnable_validation_spheres,
    validation_case_records,
    validation_case_settings,
    validation_sphere_record,
)

REPO = Path(__file__).resolve().parents[2]

SPHERES = {
    "run": ["PS", "PTFE"],
    "values": {
        "PS": {"p_y_mpa": 110.0, "k_mpa_per_nm": 5.0},
        "PTFE": {"p_y_mpa": 10.0, "k_mpa_per_nm": 0.5},
        "other": {"p_y_mpa": 1.0, "k_mpa_per_nm": 1.0},
    },
    "seeds": 2,
    "first_seed": 7,
    "ratio": 2.0,
    "comparison_ratios": [4.0],
    "comparison_models": ["hardening"],
    "window_factor": 1.2,
    "truth_iteration": "preconditioned",
}
VALIDATION = {
    "run_truths": ["elastic"],
    "truths": {"elastic": {"model": "elastic", "signal": "none"}},
    "seeds": 1,
    "first_seed": 1,
    "truth_pixel_ratio": 4.0,
    "comparison_truths": [],
    "comparison_ratios": [],
    "spheres": SPHERES,
}


@pytest.fixture(scope="module")
def full_config():
    return read_config(REPO / "config" / "config.yaml")


def _sheet_record(name, diameter_mm, e_star_gpa, **extra):
    return {
        "material": name,
        "diameter_mm": diameter_mm,
        "e_star_gpa": e_star_gpa,
        "loads": [25.0, 50.0, 100.0, 200.0, 300.0],
        "roughness_rms_nm": 60.0,
        "fluorescence_pixel_nm": 200.0,
        "hardness_mpa": 30.0,
        "hardening_k_mpa_per_nm": 0.5,
        **extra,
    }


def test_each_run_sphere_has_an_elastic_truth_and_each_plastic_models_on_every_seed():
    everything = sphere_cases(VALIDATION)
    cases = [c for c in everything if not c.comparison]
    assert len(cases) == 2 * 3 * 2  # spheres × truths × seeds
    again = [c for c in everything if c.comparison]
    assert {(c.sphere, c.truth.model, c.ratio) for c in again} == {
        ("PS", "hardening", 4.0),
        ("PTFE", "hardening", 4.0),
    }
    assert len(again) == 2 * 2  # spheres × seeds
    ptfe = [c for c in cases if c.sphere == "PTFE"]
    assert {(c.truth.model, c.truth.value) for c in ptfe} == {
        ("elastic", None),
        ("penetration_hardness", 10.0),
        ("hardening", 0.5),
    }
    assert {c.seed for c in ptfe} == {7, 8} and {c.ratio for c in ptfe} == {2.0}
    assert {c.truth.signal for c in ptfe if c.truth.model != "elastic"} == {"clear"}
    name = "PTFE_hardening_r2_s8"
    assert name in sphere_case_names(VALIDATION)
    assert case_named(VALIDATION, name).sphere == "PTFE"
    # the small sphere's cases are on no sheet sphere, and keep their names
    assert case_named(VALIDATION, "elastic_r4_s1").sphere is None
    # only the spheres the run can validate on
    assert {c.sphere for c in sphere_cases(VALIDATION, ["PS"])} == {"PS"}


def test_a_run_sphere_without_values_is_refused_by_name():
    broken = {**VALIDATION, "spheres": {**SPHERES, "run": ["PS", "glass"]}}
    with pytest.raises(ValueError, match="'glass'.*PS"):
        sphere_cases(broken)


def test_a_sheet_sphere_is_made_as_the_virtual_experiment_makes_it(full_config):
    """Diameter, E*, loads and roughness from the sheet row; the spectrum, PSF and counts from
    the virtual experiment's config; the PSF's stated error from the validation's."""
    record = _sheet_record("PTFE", 3.14, 0.5)
    virtual = full_config["virtual_experiment"]
    sphere = Sphere.from_sheet(record, full_config["validation"], virtual)
    assert sphere.radius_m == pytest.approx(1.57e-3)
    assert sphere.e_star_pa == pytest.approx(0.5e9)
    assert sphere.loads_n == pytest.approx((0.025, 0.05, 0.1, 0.2, 0.3))
    assert sphere.roughness.rms_m == pytest.approx(60e-9)
    assert sphere.roughness.rolloff_m == pytest.approx(virtual["roughness_rolloff_um"] * 1e-6)
    assert sphere.roughness.reference_pixel_m == pytest.approx(virtual["afm_pixel_nm"] * 1e-9)
    assert sphere.psf_fwhm_m == pytest.approx(virtual["psf_fwhm_nm"] * 1e-9)
    assert sphere.psf_se_m == pytest.approx(full_config["validation"]["psf_se_nm"] * 1e-9)
    assert sphere.window_factor == full_config["validation"]["spheres"]["window_factor"]
    assert sheet_priors(record) == {"p_y_mpa": 30.0, "k_mpa_per_nm": 0.5}


@pytest.mark.parametrize(
    ("sphere", "pixel_nm"),
    # the reproduction's scenes solve them at these pixels (docs/study.md §4: PS 206 nm,
    # PMMA-4mm 296 nm, PTFE 522 nm); 0.5 nm: the docs round to the nanometre
    [("PS", 206.0), ("PMMA-4mm", 296.0), ("PTFE", 522.0)],
)
def test_the_study_solves_a_sheet_sphere_at_the_reproductions_pixel(full_config, sphere, pixel_nm):
    schema = load_schema(REPO / "workflow" / "schemas" / "materials.schema.yaml")
    record = read_sample_sheet(REPO / "config" / "materials.tsv", schema)[sphere]
    the_sphere = Sphere.from_sheet(
        record, full_config["validation"], full_config["virtual_experiment"]
    )
    preset = full_config["solver_presets"]["standard"]
    assert study_pixel_m(the_sphere, preset) * 1e9 == pytest.approx(pixel_nm, abs=0.5)


def test_spheres_a_run_cannot_validate_on_are_left_out_and_named():
    config = {"materials": ["PS"], "validation": {**VALIDATION, "spheres": SPHERES}}
    selected = {"PS": _sheet_record("PS", 0.6, 3.7)}
    assert runnable_validation_spheres(config, selected) == ["PS"]
    [line] = left_out_validation_spheres(config, selected)
    assert "PTFE is not a sphere of the selected materials ['PS']" in line
    no_prior = {"PS": _sheet_record("PS", 0.6, 3.7, hardness_mpa=None)}
    assert runnable_validation_spheres(config, no_prior) == []
    lines = left_out_validation_spheres(config, no_prior)
    assert any("PS's sheet row has no hardness_mpa" in line for line in lines)
    # a measured sphere whose row leaves its roughness to its AFM map
    measured = {"PS": _sheet_record("PS", 0.6, 3.7, roughness_rms_nm=None)}
    assert runnable_validation_spheres(config, measured) == []
    assert "no roughness_rms_nm" in left_out_validation_spheres(config, measured)[0]
    records = validation_case_records(config)
    assert validation_sphere_record(selected, records["PS_elastic_r2_s7"]) is selected["PS"]
    assert validation_sphere_record(selected, records["elastic_r4_s1"]) is None


def test_the_schema_takes_the_validations_models_and_keys_from_the_records():
    """The truths' models, their value keys, the priors' and the sheet spheres' values' keys
    come from the models' records (amontons.models); the truths' iteration from the solver's."""
    schema = load_schema(REPO / "workflow" / "schemas" / "config.schema.yaml")
    validation = schema["properties"]["validation"]["properties"]
    truth = validation["truths"]["additionalProperties"]["properties"]
    assert truth["model"]["enum"] == list(models.field_model_names())
    keys = list(models.parameter_keys())
    assert set(keys) <= set(truth)
    values = validation["spheres"]["properties"]["values"]["additionalProperties"]
    for node in (validation["priors"], values):
        assert node["required"] == keys and list(node["properties"]) == keys
    assert validation["spheres"]["properties"]["truth_iteration"]["enum"] == list(ITERATIONS)


def test_a_case_job_takes_its_own_record_and_no_key_that_enumerates_the_cases(full_config):
    """A case's job params are its own record and the settings it is judged with: a seed or
    a sphere added to the study changes neither for the cases already run (Snakemake reruns
    a job whose params change)."""
    config = full_config
    name = sphere_case_names(config["validation"])[0]
    before = (validation_case_records(config)[name], validation_case_settings(config))
    more = copy.deepcopy(config)
    more["validation"]["spheres"]["seeds"] += 3
    more["validation"]["spheres"]["run"] = [*more["validation"]["spheres"]["run"], "PMMA-1.5mm"]
    more["validation"]["seeds"] += 1
    after = (validation_case_records(more)[name], validation_case_settings(more))
    assert after == before
    assert Case.from_record(before[0]) == case_named(config["validation"], name)
    settings = before[1]
    assert "seeds" not in settings and "run" not in settings["spheres"]
    assert settings["spheres"]["truth_iteration"] == "preconditioned"
