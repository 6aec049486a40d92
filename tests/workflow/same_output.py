"""What the cluster executors' tests share (tests/workflow/test_executor.py,
tests/cluster/test_slurm.py): the glass sphere's targets of the small data set that they run
through an executor, and two runs' outputs compared byte for byte wherever the bytes do not
carry the time."""

import json
from pathlib import Path

import h5py
import numpy as np

GLASS = "results/small/glass"
# The glass sphere's measurements, fits, figures and elastic scene: 14 jobs from its virtual
# experiment on.
GLASS_TARGETS = [
    f"{GLASS}/load_area.csv",
    f"{GLASS}/amontons.csv",
    f"{GLASS}/glass/measure/hertz_check.csv",
    f"{GLASS}/glass/measure/intensity_pressure_fit.json",
    f"{GLASS}/glass/measure/psf.json",
    f"{GLASS}/glass/measure/edge_gap.json",
    f"{GLASS}/glass/measure/grafting_density.json",
    f"{GLASS}/glass/measure/topography.json",
    f"{GLASS}/glass/scenes/elastic/fields.h5",
]


def without_wall_times(value):
    """A JSON value with every ``wall_time_s`` (a measured duration) left out."""
    if isinstance(value, dict):
        return {k: without_wall_times(v) for k, v in value.items() if k != "wall_time_s"}
    if isinstance(value, list):
        return [without_wall_times(v) for v in value]
    return value


def h5_contents(path: Path) -> dict:
    """Every dataset (values) and attribute of an HDF5 file, by path, but the attributes
    ``wall_time_s`` (measured durations)."""
    out = {}
    with h5py.File(path, "r") as f:
        out["/attrs"] = without_wall_times(dict(f.attrs))

        def visit(name, obj):
            out[f"{name}/attrs"] = without_wall_times(dict(obj.attrs))
            if isinstance(obj, h5py.Dataset):
                out[name] = obj[()]

        f.visititems(visit)
    return out


def assert_same_output(ours: Path, reference: Path) -> None:
    """``ours`` equals ``reference`` byte for byte, except where the bytes carry the time:
    PDF (creation date; the PNG of the same figure is compared), HDF5 (object timestamps;
    every dataset and attribute but the wall times is compared exactly instead) and
    solve.json (wall times; the rest compared)."""
    if ours.suffix == ".pdf":
        return
    if ours.suffix == ".h5":
        a, b = h5_contents(ours), h5_contents(reference)
        assert a.keys() == b.keys(), ours
        for key in a:
            if isinstance(a[key], dict):
                assert a[key].keys() == b[key].keys(), (ours, key)
                for name in a[key]:
                    assert np.array_equal(a[key][name], b[key][name]), (ours, key, name)
            else:
                assert np.array_equal(a[key], b[key]), (ours, key)
        return
    if ours.name == "solve.json":
        a, b = (json.loads(p.read_text()) for p in (ours, reference))
        assert without_wall_times(a) == without_wall_times(b), ours
        return
    assert ours.read_bytes() == reference.read_bytes(), ours
