"""The validation study's jobs (docs/study.md §7): one per case of the config's
``validation`` slice (amontons.validation.cases), named for the Snakefile, on its small
sphere (target ``validation``) and on the materials sheet's spheres that
``validation.spheres.run`` names (target ``validation_spheres``)."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.models import with_parameter
from amontons.validation.cases import (
    case_named,
    case_names,
    case_settings,
    sphere_case_names,
    sphere_of_case,
)


def validation_cases(config: Mapping) -> list[str]:
    """The names of the validation study's cases on its small sphere."""
    return case_names(config["validation"])


# a sheet sphere's truth is made with its roughness (which a measured sphere's row may leave
# to its AFM map) and its scans are centred on each plastic model's prior
NEEDED_COLUMNS = ("roughness_rms_nm", *(m.parameter.sheet_column for m in with_parameter()))


def runnable_validation_spheres(config: Mapping, selected: Mapping[str, dict]) -> list[str]:
    """The spheres ``validation.spheres.run`` names that the run can validate on: spheres of
    the selected materials whose sheet row states :data:`NEEDED_COLUMNS`."""
    return [
        sphere
        for sphere in config["validation"]["spheres"]["run"]
        if sphere in selected and not _missing_columns(selected[sphere])
    ]


def left_out_validation_spheres(config: Mapping, selected: Mapping[str, dict]) -> list[str]:
    """A line for each sphere ``validation.spheres.run`` names that the run cannot validate
    on, and why (the rest of the study runs without it)."""
    lines = []
    for sphere in config["validation"]["spheres"]["run"]:
        if sphere not in selected:
            lines.append(
                f"validation.spheres.run: {sphere} is not a sphere of the selected materials "
                f"{list(config['materials'])}; its validation cases are left out"
            )
        elif missing := _missing_columns(selected[sphere]):
            lines.append(
                f"validation.spheres.run: {sphere}'s sheet row has no {', '.join(missing)} (the "
                "truth's roughness and the priors its scans are centred on); its validation "
                "cases are left out"
            )
    return lines


def _missing_columns(record: Mapping) -> list[str]:
    """The columns of :data:`NEEDED_COLUMNS` a sheet row leaves empty."""
    return [c for c in NEEDED_COLUMNS if record.get(c) is None]


def validation_sphere_cases(config: Mapping, selected: Mapping[str, dict]) -> list[str]:
    """The names of the cases on the sheet's spheres the run can validate on."""
    return sphere_case_names(config["validation"], runnable_validation_spheres(config, selected))


def validation_sphere_record(config: Mapping, selected: Mapping[str, dict], case: str):
    """The sheet record of the sphere case ``case`` is on, None for the small sphere's."""
    sphere = sphere_of_case(config["validation"], case)
    return None if sphere is None else selected[sphere]


def validation_case_record(config: Mapping, case: str) -> dict:
    """Case ``case`` as its job's params take it (amontons.validation.cases.Case.to_record)."""
    return case_named(config["validation"], case).to_record()


def validation_case_settings(config: Mapping) -> dict:
    """What every case job is judged with: the validation slice less the keys that only
    enumerate the cases, so that a seed or a truth added reruns no case."""
    return case_settings(config["validation"])
