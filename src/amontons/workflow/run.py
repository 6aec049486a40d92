"""A run of the workflow as its DAG sees it: the config checked once, and every helper the
rules call (paths, spheres, scenes and scans, study, targets, accuracy study, resources),
built from it. workflow/rules/common.smk only binds these to the names the rules use."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from amontons.accuracy.settings import check_accuracy_study
from amontons.config.errors import ConfigError
from amontons.config.scenes import (
    check_curvature_pairs,
    check_scans,
    check_scenes,
    resolve_scene_presets,
)
from amontons.config.schema import load_schema, validate
from amontons.config.sheet import (
    check_reference_load,
    check_selected_materials,
    check_shared_files,
    read_sample_sheet,
)
from amontons.io.export_map import ExportMapError, export_maps
from amontons.io.layout import IMAGE_FORMATS, load_axis_conflict
from amontons.workflow.accuracy import AccuracyStudy
from amontons.workflow.data_stamp import data_stamp
from amontons.workflow.ledger import read_held_out
from amontons.workflow.paths import RunPaths
from amontons.workflow.raw_files import SHEET_EXPORT_COLUMN
from amontons.workflow.resources import SolveResources
from amontons.workflow.scenes import Scenes
from amontons.workflow.spheres import Spheres
from amontons.workflow.study import Study
from amontons.workflow.summary import Summary
from amontons.workflow.targets import Targets

# Locates a file of the workflow folder by its path there (e.g. "schemas/config.schema.yaml").
Locate = Callable[[str], str | Path]


def _in_folder(folder: Path) -> Locate:
    return lambda name: folder / name


def config_digest(config: Mapping) -> str:
    """A digest of a run's config (resolved), for the stamp of a sphere's data: a changed
    config lets a failed sphere back into the tables (amontons.workflow.ledger)."""
    return hashlib.sha256(json.dumps(config, sort_keys=True, default=str).encode()).hexdigest()


def load_workflow_config(
    config: Mapping, config_schema: Mapping, sheet_schema: Mapping, source: str
) -> dict[str, dict]:
    """Validate a config mapping and its sample sheet, resolving scene presets and the
    accuracy study's sphere in place; return the sheet records (sphere id → record) of the
    selected materials. Every check runs before any job; ``source`` names the config file(s)
    in the messages."""
    validate(config, config_schema, source)
    resolve_scene_presets(config, source)
    sheet = read_sample_sheet(config["materials_sheet"], sheet_schema)
    check_selected_materials(config["materials"], sheet, source)
    check_shared_files(sheet, config["materials_sheet"])
    selected = {s: r for s, r in sheet.items() if r["material"] in config["materials"]}
    check_reference_load(config["load_area"]["reference_load_mn"], selected, source)
    check_scenes(config, selected, source)
    check_scans(config, source)
    check_curvature_pairs(config, source)
    check_accuracy_study(config, sheet, source)
    check_load_series(config["optics"]["images"], source)
    check_rheometer_exports(config.get("rheometer_export"), selected, source)
    return selected


def check_rheometer_exports(value, records: Mapping[str, Mapping], source: str) -> None:
    """The config's rheometer_export (none, one column map, or named maps;
    amontons.io.export_map.export_maps) must describe exports, and a sheet row that names a
    map for its sphere (column rheometer_export) must name one of them."""
    try:
        maps = export_maps(value)
    except ExportMapError as error:
        raise ConfigError(f"{source}: {error}") from error
    for sphere, record in records.items():
        named = record.get(SHEET_EXPORT_COLUMN)
        if named is not None and named not in maps:
            raise ConfigError(
                f"sphere {sphere}: {SHEET_EXPORT_COLUMN} = {named!r} in the sheet; expected one "
                f"of the export maps of {source}'s rheometer_export: {list(maps) or 'none'}"
            )


def check_load_series(images: Mapping, source: str) -> None:
    """optics.images.load_series takes over the choice along its axis (series or frames):
    that choice must keep its default, as a file of one plane per load has no other plane to
    pick (amontons.io.layout.load_axis_conflict). Each sphere's planes are checked against
    its loads when the DAG looks at its folder (amontons.workflow.load_series)."""
    series = images["load_series"]
    if series is None:
        return
    conflict = load_axis_conflict(series["axis"], images)
    if conflict is not None:
        raise ConfigError(f"{source}: {conflict}")


@dataclass
class WorkflowRun:
    """Everything the rules ask of a run (see the module docstring)."""

    config: Mapping
    paths: RunPaths
    spheres: Spheres
    scenes: Scenes
    study: Study
    targets: Targets
    accuracy: AccuracyStudy
    resources: SolveResources
    summary: Summary

    @property
    def materials(self) -> list[str]:
        return list(self.config["materials"])

    def left_out(self) -> list[str]:
        """Per sphere, what its data do not allow and why (amontons.workflow.optional_inputs)."""
        return [
            f"sphere {sphere} ({self.spheres.rows.material_of(sphere)}): {line}"
            for sphere in self.spheres
            for line in self.spheres.inputs.left_out(sphere) + self.scenes.left_out(sphere)
        ]

    def outside_scan(self) -> list[str]:
        """Per measured sphere whose AFM scan's size its header gives, the loads each scene
        will leave outside the scan (amontons.workflow.scenes)."""
        return [
            f"sphere {sphere} ({self.spheres.rows.material_of(sphere)}): {line}"
            for sphere in self.spheres
            for line in self.scenes.predicted_outside_scan(sphere)
        ]

    def failed(self) -> list[str]:
        """Per sphere held out by an earlier run's failure, each failed job and what the
        sphere is held out of (amontons.workflow.ledger)."""
        return [
            f"sphere {sphere} ({self.spheres.rows.material_of(sphere)}): {line}"
            for sphere in self.spheres.held_out
            for line in self.spheres.hold_outs.failed_lines(sphere)
        ]

    def data_stamp(self, sphere: str) -> str:
        """The stamp of a sphere's data under this run's config (amontons.workflow.ledger)."""
        return data_stamp(self.spheres.rows, sphere, config_digest(self.config))

    @classmethod
    def from_config(
        cls, config: Mapping, workflow_dir: str | Path | Locate, source: str
    ) -> WorkflowRun:
        """Check ``config`` (resolved in place) against the workflow's schemas and build the
        run. ``workflow_dir``: the workflow folder (schemas/, resources.json,
        timing_model.json), or a function that locates one of its files by its path in that
        folder (Snakemake's ``workflow.source_path``, which also serves a deployed module)."""
        locate = workflow_dir if callable(workflow_dir) else _in_folder(Path(workflow_dir))
        records = load_workflow_config(
            config,
            load_schema(locate("schemas/config.schema.yaml")),
            load_schema(locate("schemas/materials.schema.yaml")),
            source,
        )
        paths = RunPaths(config["run"])
        spheres = Spheres(
            records,
            paths,
            psf_stand_in=config["optics"]["psf"].get("stand_in") is not None,
            synthetic_flim=config["virtual_experiment"]["formats"]["flim"],
            synthetic_images=IMAGE_FORMATS[config["virtual_experiment"]["formats"]["images"]],
            load_series=config["optics"]["images"]["load_series"],
        )
        spheres.pixels.check()
        spheres.series.check(config["optics"]["images"]["series"])
        digest = config_digest(config)
        spheres.hold_outs.hold_out(
            read_held_out(paths, spheres, lambda sphere: data_stamp(spheres.rows, sphere, digest))
        )
        scenes = Scenes(config, spheres, paths)
        study = Study(config, spheres, scenes, paths)
        return cls(
            config=config,
            paths=paths,
            spheres=spheres,
            scenes=scenes,
            study=study,
            targets=Targets(spheres, scenes, study, paths),
            accuracy=AccuracyStudy(config, spheres, paths),
            summary=Summary(config["materials"], spheres, scenes, study, paths),
            resources=SolveResources.from_files(
                config, spheres, locate("resources.json"), locate("timing_model.json")
            ),
        )
