"""The workflow's configuration and sample sheet, checked before any job, with messages a user
can act on (config/README.md): one module per concern.

- :mod:`~amontons.config.errors`: :class:`ConfigError`;
- :mod:`~amontons.config.schema`: JSON Schema validation, every violation named (and
  :mod:`~amontons.config.reference`, config/README.md's key tables rendered from the schemas);
- :mod:`~amontons.config.sheet`: the sample sheet, read and checked;
- :mod:`~amontons.config.scenes`: scenes, presets, scans and curvature pairs;
- :mod:`~amontons.config.geometry`: a scene's window and grid in SI, shared with the simulation;
- :mod:`~amontons.config.merge`: config overlays.

Standard library, jsonschema and yaml only: the workflow imports it to build its DAG. The
accuracy study checks its own section (amontons.accuracy.settings); amontons.workflow runs
every check in order.
"""

from amontons.config.errors import ConfigError
from amontons.config.merge import merge_config, read_config
from amontons.config.schema import load_schema, validate
from amontons.config.sheet import (
    MIN_LOADS,
    RESERVED_NAMES,
    check_reference_load,
    check_selected_materials,
    parse_loads_mn,
    read_sample_sheet,
)

__all__ = [
    "MIN_LOADS",
    "RESERVED_NAMES",
    "ConfigError",
    "check_reference_load",
    "check_selected_materials",
    "load_schema",
    "merge_config",
    "parse_loads_mn",
    "read_config",
    "read_sample_sheet",
    "validate",
]
