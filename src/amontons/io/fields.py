"""Fields of a simulation in HDF5 (h5py): one group per load, one dataset per field, units and
settings as attributes (docs/simulate.md, "Outputs")."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import h5py
import numpy as np

from amontons.io.files import atomic_path

# How every array is compressed: the byte shuffle, then gzip at level 1 (HDF5's standard
# filters, which every HDF5 reader has). Against gzip at h5py's default level 4 without the
# shuffle, on the pipeline's float64 maps: a 2048² levelled AFM map writes in 0.38 s instead
# of 1.0 s, reads in 0.16 instead of 0.24 s and takes 11.9 instead of 15.6 MB; a scan value's
# rendered images 0.56 instead of 0.84 s (docs/study.md §5). The values are the same.
COMPRESSION = {"compression": "gzip", "compression_opts": 1, "shuffle": True}

# Field name → unit, in the order written.
FIELD_UNITS = {
    "pressure": "Pa",
    "gap": "m",
    "plastic_displacement": "m",
    "deformed_heights": "m",
    "contact": "1",
    "image": "arbitrary (rendered fluorescence)",
}


def _attribute(value):
    """HDF5 attributes hold numbers and strings; nested or None values go as JSON text."""
    if value is None or isinstance(value, Mapping | list | tuple):
        return json.dumps(value)
    return value


def write_load_series(
    path: str | Path,
    fields: Sequence[Mapping[str, np.ndarray]],
    per_load: Sequence[Mapping],
    settings: Mapping,
) -> None:
    """Write one group ``load_<i>`` per load with the fields of FIELD_UNITS (each with its
    ``unit`` attribute) and that load's diagnostics as group attributes; ``settings`` (scene
    and grid) go to the file's attributes. Written atomically: no half-written file."""
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        for key, value in settings.items():
            h5.attrs[key] = _attribute(value)
        for index, (load_fields, info) in enumerate(zip(fields, per_load, strict=True)):
            group = h5.create_group(f"load_{index}")
            for key, value in info.items():
                group.attrs[key] = _attribute(value)
            for name, unit in FIELD_UNITS.items():
                if name not in load_fields:
                    continue
                data = np.asarray(load_fields[name])
                data = data.astype(np.uint8) if data.dtype == bool else data
                dataset = group.create_dataset(name, data=data, **COMPRESSION)
                dataset.attrs["unit"] = unit


def read_load_series(path: str | Path) -> tuple[list[dict], list[dict], dict]:
    """(fields per load, diagnostics per load, settings) as written by write_load_series."""
    with h5py.File(path, "r") as h5:
        settings = _attributes(h5)
        fields, per_load = [], []
        for name in _load_groups(h5):
            group = h5[name]
            per_load.append(_attributes(group))
            fields.append(
                {
                    key: group[key][()].astype(bool) if key == "contact" else group[key][()]
                    for key in group
                }
            )
    return fields, per_load, settings


def read_load_series_field(
    path: str | Path, name: str
) -> tuple[list[np.ndarray], list[dict], dict]:
    """One field of every load of a file of write_load_series (its arrays, as stored), the
    loads' diagnostics and the settings, in one read and without the other fields."""
    with h5py.File(path, "r") as h5:
        groups = _load_groups(h5)
        arrays = [h5[group][name][()] for group in groups]
        per_load = [_attributes(h5[group]) for group in groups]
        settings = _attributes(h5)
    return arrays, per_load, settings


def _load_groups(h5) -> list[str]:
    """The load groups of a file of write_load_series, in load order (``load_<i>``)."""
    return sorted(h5, key=lambda name: int(name.split("_")[1]))


def read_load_series_settings(path: str | Path) -> dict:
    """The settings of a file of write_load_series alone, without reading its fields."""
    with h5py.File(path, "r") as h5:
        return _attributes(h5)


def _attributes(node) -> dict:
    """The attributes of a file or group of write_load_series, decoded."""
    return {key: _decoded(value) for key, value in node.attrs.items()}


def _decoded(value):
    if isinstance(value, str) and value[:1] in "[{n":
        try:
            return json.loads(value)
        except json.JSONDecodeError:
            return value
    return value.item() if isinstance(value, np.generic) else value


def write_levelled_map(path: str | Path, heights_m: np.ndarray, pixel_m: float, attrs: Mapping):
    """A levelled AFM map (heights in m, square pixels of ``pixel_m``) with its sphere fit and
    provenance as attributes, atomically."""
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        dataset = h5.create_dataset("heights", data=np.asarray(heights_m), **COMPRESSION)
        dataset.attrs["unit"] = "m"
        h5.attrs["pixel_m"] = pixel_m
        for key, value in attrs.items():
            h5.attrs[key] = _attribute(value)


def read_levelled_map(path: str | Path) -> tuple[np.ndarray, float, dict]:
    """(heights in m, pixel in m, attributes) as written by write_levelled_map."""
    with h5py.File(path, "r") as h5:
        attrs = {key: _decoded(value) for key, value in h5.attrs.items()}
        return h5["heights"][()], float(attrs.pop("pixel_m")), attrs


def write_named_records(
    path: str | Path, records: Mapping[str, Mapping], arrays: Mapping[str, Mapping[str, np.ndarray]]
) -> None:
    """One group per name: its record as attributes, its arrays as datasets, float64 values
    kept to the bit (units are the keys' suffixes). Written atomically."""
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        for name, record in records.items():
            group = h5.create_group(name)
            for key, value in record.items():
                group.attrs[key] = _attribute(value)
            for key, data in arrays.get(name, {}).items():
                group.create_dataset(key, data=np.asarray(data), **COMPRESSION)


def read_named_records(path: str | Path) -> tuple[dict[str, dict], dict[str, dict]]:
    """(records, arrays) per name, as written by write_named_records."""
    with h5py.File(path, "r") as h5:
        records = {
            name: {key: _decoded(value) for key, value in h5[name].attrs.items()} for name in h5
        }
        arrays = {name: {key: h5[name][key][()] for key in h5[name]} for name in h5}
    return records, arrays
