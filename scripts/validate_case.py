"""Rule validate_case: one case of the validation study (docs/study.md §7), its truth solved
finer than the study solves it, judged by the study's scans and decision; its record. A case
on a sphere of the materials sheet is seen as the virtual experiment sees that sphere, at the
pixel the run's solver preset solves it at, about the sheet's priors."""

from amontons.contact.options import DEFAULT_ITERATION
from amontons.io.files import write_json
from amontons.measure.area import OtsuSettings
from amontons.runlog import run_logged
from amontons.validation.case import run_case
from amontons.validation.cases import Case
from amontons.validation.study import StudySettings, sheet_priors
from amontons.validation.truth import Sphere, study_pixel_m


def main(
    case: dict,
    validation: dict,
    virtual: dict,
    record: dict | None,
    scans: dict,
    judgement: dict,
    preset: dict,
    otsu: dict,
    out: str,
):
    otsu_settings = OtsuSettings.from_config(otsu)
    the_case = Case.from_record(case)
    if record is None:
        sphere, priors = Sphere.from_config(validation), validation["priors"]
        iteration = DEFAULT_ITERATION
    else:
        sphere, priors = Sphere.from_sheet(record, validation, virtual), sheet_priors(record)
        iteration = validation["spheres"]["truth_iteration"]
    settings = StudySettings(
        pixel_m=study_pixel_m(sphere, preset),
        tol=preset["tol"],
        priors=priors,
        scans=scans,
        judgement=judgement,
        otsu=otsu_settings,
        inner_confidence=validation["inner_confidence"],
    )
    result = run_case(the_case, sphere, settings, validation["truth_tol"], otsu_settings, iteration)
    write_json(out, result)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        case=sm.params.case,
        validation=sm.params.validation,
        virtual=sm.params.virtual,
        record=sm.params.sphere,
        scans=sm.params.scans,
        judgement=sm.params.judgement,
        preset=sm.params.preset,
        otsu=sm.params.otsu,
        out=sm.output.record,
    )
