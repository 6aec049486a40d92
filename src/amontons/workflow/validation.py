"""The validation study's jobs (docs/study.md §7): one per case of the config's
``validation`` slice (amontons.validation.cases), named for the Snakefile, on its small
sphere (target ``validation``) and on the materials sheet's spheres that
``validation.spheres.run`` names (target ``validation_spheres``)."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.models import with_parameter
from amontons.validation.cases import (
    case_names,
    case_settings,
    cases_by_name,
    sphere_case_names,
)


def validation_cases(config: Mapping) -> list[str]:
    """The names of the validation study's cases on its small sphere."""
    return case_names(config["validation"])


# a sheet sphere's truth is made with its roughness (which a measured sphere's row may leave
# to its AFM map) and its scans are centred on each plastic model's prior
NEEDED_COLUMNS = ("roughness_rms_nm", *(m.parameter.sheet_column for m in with_parameter()))


def _why_left_out(config: Mapping, selected: Mapping[str, dict], sphere: str) -> str | None:
    """Why the run cannot validate on ``sphere`` (None: it can): not a sphere of the selected
    materials, or a sheet row without :data:`NEEDED_COLUMNS`."""
    if sphere not in selected:
        return (
            f"validation.spheres.run: {sphere} is not a sphere of the selected materials "
            f"{list(config['materials'])}; its validation cases are left out"
        )
    missing = [c for c in NEEDED_COLUMNS if selected[sphere].get(c) is None]
    if missing:
        return (
            f"validation.spheres.run: {sphere}'s sheet row has no {', '.join(missing)} (the "
            "truth's roughness and the priors its scans are centred on); its validation "
            "cases are left out"
        )
    return None


def runnable_validation_spheres(config: Mapping, selected: Mapping[str, dict]) -> list[str]:
    """The spheres ``validation.spheres.run`` names that the run can validate on."""
    run = config["validation"]["spheres"]["run"]
    return [s for s in run if _why_left_out(config, selected, s) is None]


def left_out_validation_spheres(config: Mapping, selected: Mapping[str, dict]) -> list[str]:
    """A line for each sphere ``validation.spheres.run`` names that the run cannot validate
    on, and why (the rest of the study runs without it)."""
    run = config["validation"]["spheres"]["run"]
    reasons = (_why_left_out(config, selected, s) for s in run)
    return [why for why in reasons if why is not None]


def validation_sphere_cases(config: Mapping, selected: Mapping[str, dict]) -> list[str]:
    """The names of the cases on the sheet's spheres the run can validate on."""
    return sphere_case_names(config["validation"], runnable_validation_spheres(config, selected))


def validation_case_records(config: Mapping) -> dict[str, dict]:
    """Every case as its job's params take it (amontons.validation.cases.Case.to_record), by
    name: built once for the DAG."""
    return {name: case.to_record() for name, case in cases_by_name(config["validation"]).items()}


def validation_sphere_record(selected: Mapping[str, dict], case: Mapping) -> dict | None:
    """The sheet record of the sphere a case (its record) is on, None for the small
    sphere's."""
    return None if case["sphere"] is None else selected[case["sphere"]]


def validation_case_settings(config: Mapping) -> dict:
    """What every case job is judged with: the validation slice less the keys that only
    enumerate the cases, so that a seed or a truth added reruns no case."""
    return case_settings(config["validation"])
