"""Rule validate_case: one case of the validation study (docs/study.md §7), its truth solved
finer than the study solves it, judged by the study's scans and decision; its record."""

from amontons.io.files import write_json
from amontons.measure.area import OtsuSettings
from amontons.runlog import run_logged
from amontons.validation.case import run_case
from amontons.validation.cases import case_named
from amontons.validation.study import StudySettings
from amontons.validation.truth import Sphere


def main(
    case: str, validation: dict, scans: dict, judgement: dict, preset: dict, otsu: dict, out: str
):
    otsu_settings = OtsuSettings.from_config(otsu)
    settings = StudySettings(
        pixel_m=preset["pixel_nm"] * 1e-9,
        tol=preset["tol"],
        priors=validation["priors"],
        scans=scans,
        judgement=judgement,
        otsu=otsu_settings,
        inner_confidence=validation["inner_confidence"],
    )
    record = run_case(
        case_named(validation, case),
        Sphere.from_config(validation),
        settings,
        validation["truth_tol"],
        otsu_settings,
    )
    write_json(out, record)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        case=sm.wildcards.case,
        validation=sm.params.validation,
        scans=sm.params.scans,
        judgement=sm.params.judgement,
        preset=sm.params.preset,
        otsu=sm.params.otsu,
        out=sm.output.record,
    )
