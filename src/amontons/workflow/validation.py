"""The validation study's jobs (docs/study.md §7): one per case of the config's
``validation`` slice (amontons.validation.cases), named for the Snakefile."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.validation.cases import case_names


def validation_cases(config: Mapping) -> list[str]:
    """The names of the validation study's cases: the wildcards of its case jobs."""
    return case_names(config["validation"])
