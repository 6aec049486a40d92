"""The sample sheet's rows of the selected spheres, as the DAG reads them: a sphere's
material, loads and values, whether the virtual experiment makes its data, and the folder its
row names for them (config/README.md, "Your own data")."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.config.errors import ConfigError
from amontons.models import CONTACT_HARDENING, model_named, with_parameter
from amontons.workflow.paths import RunPaths

# The sheet values a scene takes from its sphere.
SCENE_COLUMNS = (
    "diameter_mm",
    "e_star_gpa",
    "loads",
    *(m.parameter.sheet_column for m in with_parameter()),
)
# The model the virtual experiment makes a sphere's contact with where its row names none
# (the reproduction's spheres flow by contact hardening: docs/workflow.md), and the columns
# that name another and its value.
DEFAULT_TRUE_MODEL = CONTACT_HARDENING.name
TRUE_MODEL_COLUMN = "true_model"
TRUE_VALUE_COLUMN = "true_value"


class SheetRows:
    """The sheet records (sphere id → record, amontons.config.sheet) of the selected
    materials, in the sheet's order, and where each sphere's raw data lie: the virtual
    experiment's folder of the run (data_source 'synthetic') or the folder its row names."""

    def __init__(self, records: Mapping[str, dict], paths: RunPaths):
        self.records = dict(records)
        self.paths = paths

    def __iter__(self):
        return iter(self.records)

    def row(self, sphere: str) -> dict:
        return self.records[sphere]

    def material_of(self, sphere: str) -> str:
        return self.records[sphere]["material"]

    def is_synthetic(self, sphere: str) -> bool:
        return self.records[sphere]["data_source"] == "synthetic"

    def loads_mn(self, sphere: str) -> list[float]:
        return list(self.records[sphere]["loads"])

    def value(self, sphere: str, column: str) -> float | None:
        """A numeric sheet value, or None where the cell is empty."""
        value = self.records[sphere].get(column)
        return None if value is None else float(value)

    def true_model(self, sphere: str) -> str:
        """The model a virtual sphere's contact is made with (:data:`DEFAULT_TRUE_MODEL` where
        its row names none)."""
        return self.records[sphere].get(TRUE_MODEL_COLUMN) or DEFAULT_TRUE_MODEL

    def true_value(self, sphere: str) -> float | None:
        """The true model's parameter (its record's config unit; None for a model without
        one): the row's ``true_value``, or else the model's prior column."""
        model = self.true_model(sphere)
        parameter = model_named(model).parameter
        if parameter is None:
            return None
        value = self.value(sphere, TRUE_VALUE_COLUMN)
        value = self.value(sphere, parameter.sheet_column) if value is None else value
        if value is None:
            raise ConfigError(
                f"sphere {sphere}: true_model = {model!r} with neither "
                f"{TRUE_VALUE_COLUMN} nor {parameter.sheet_column} in the sheet; expected the "
                "value the virtual experiment makes its contact with"
            )
        return value

    def pixel_nm(self, sphere: str) -> float | None:
        """The fluorescence images' pixel from the sheet, nm; None where the sheet leaves it
        to the files' metadata."""
        return self.value(sphere, "fluorescence_pixel_nm")

    def scene_record(self, sphere: str) -> dict:
        """The sheet values a scene takes from its sphere (None where a cell is empty)."""
        row = self.records[sphere]
        return {key: row.get(key) for key in SCENE_COLUMNS}

    def data_label(self, spheres) -> str:
        """'synthetic data' if any of ``spheres`` comes from the virtual experiment."""
        synthetic = any(self.is_synthetic(s) for s in spheres)
        return "synthetic data" if synthetic else "measured data"

    def raw_dir(self, sphere: str) -> str:
        """Folder of a sphere's raw data: the virtual experiment's, or the one the sheet
        names."""
        if self.is_synthetic(sphere):
            return self.paths.synthetic_sphere(sphere)
        return self.records[sphere]["data_source"]

    def raw_file(self, sphere: str, name: str) -> str:
        """Path of one raw file of a sphere (e.g. 'bead.tif')."""
        return f"{self.raw_dir(sphere)}/{name}"
