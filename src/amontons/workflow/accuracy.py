"""The accuracy study's jobs (docs/accuracy.md): its problems at every setting of its grid,
the timing points, and what they read of the study's sphere."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.accuracy.settings import (
    problem_kind,
    settings_by_name,
    timing_point_pattern,
    timing_points,
)
from amontons.workflow import paths as files
from amontons.workflow.paths import RunPaths
from amontons.workflow.spheres import Spheres

# The wildcard constraint of a timing point's name.
TIMING_POINT = timing_point_pattern()


class AccuracyStudy:
    """The accuracy study of a run (config ``accuracy``; its sphere resolved by
    amontons.accuracy.settings.check_accuracy_study)."""

    def __init__(self, config: Mapping, spheres: Spheres, paths: RunPaths):
        self.study = config["accuracy"]
        self.sphere = self.study["sphere"]
        self.spheres = spheres
        self.paths = paths

    def _measured(self, name: str) -> str:
        return self.paths.measured(name, self.spheres.rows.material_of(self.sphere), self.sphere)

    def levelled_map(self) -> str:
        """The levelled AFM map of the study's sphere."""
        return self._measured(files.LEVELLED_MAP)

    def sphere_inputs(self, wildcards) -> dict[str, str]:
        """The AFM map a rough-sphere problem presses and the PSF every problem is rendered
        with."""
        inputs = {"psf": self._measured(files.PSF)}
        if problem_kind(wildcards.problem)[1] == "sphere":
            inputs["levelled"] = self.levelled_map()
        return inputs

    def sphere_record(self) -> dict:
        """The sheet values a problem takes from the study's sphere, and its name."""
        return {**self.spheres.rows.scene_record(self.sphere), "sphere": self.sphere}

    def files(self, name: str) -> list[str]:
        """``name`` of every problem at every setting (the reference included)."""
        return [
            self.paths.accuracy_setting(name, problem, setting)
            for problem in self.study["problems"]
            for setting in settings_by_name(problem, self.study)
        ]

    def timing_point_files(self) -> list[str]:
        """The summary of every timing point."""
        return [self.paths.timing_point(point) for point in timing_points(self.study)]
