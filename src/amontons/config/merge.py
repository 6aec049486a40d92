"""The configuration a run sees: config/config.yaml with overlays merged over it, as Snakemake
merges ``--configfile`` over the Snakefile's configfile."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import yaml


def merge_config(base: Mapping, overlay: Mapping) -> dict:
    """``base`` with ``overlay``'s keys merged over it, nested mappings key by key (lists and
    values replaced), as Snakemake merges ``--configfile`` over the Snakefile's configfile."""
    merged = dict(base)
    for key, value in overlay.items():
        if isinstance(value, Mapping) and isinstance(merged.get(key), Mapping):
            merged[key] = merge_config(merged[key], value)
        else:
            merged[key] = value
    return merged


def read_config(base: str | Path, *overlays: str | Path) -> dict:
    """The configuration a run sees: the YAML file ``base`` with each overlay merged over it
    in turn (e.g. config/config.yaml, then config/test.yaml)."""
    with open(base, encoding="utf-8") as stream:
        config = yaml.safe_load(stream)
    for overlay in overlays:
        with open(overlay, encoding="utf-8") as stream:
            config = merge_config(config, yaml.safe_load(stream) or {})
    return config
