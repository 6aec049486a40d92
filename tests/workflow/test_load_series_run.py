"""A sphere's load series in one file gives what its per-load images give (issue 37).

The small run's virtual PS sphere is copied twice as measured data: as it is
(fluorescence/<load>.tif), and with its per-load images repacked into one OME-TIFF whose T
frames hold the loads in a shuffled order that the config's planes list undoes
(optics.images.load_series). Both spheres' contact areas come from one Snakemake run; they
must be the same table, but for the column naming the file read. A plane mapped to the wrong
load would put one load's area at another's, and a pixel read differently would change every
area: either fails the comparison, which is exact.
"""

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import tifffile
import yaml

from amontons.io.tiff import read_image
from amontons.workflow.paths import CONTACT_AREA, RunPaths

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[2]
PER_LOAD, SERIES = "PS-perload", "PS-series"
# Each sheet load's frame index in the repacked file (loads 25, 50, 100, 200, 300 mN).
PLANES = [3, 0, 4, 1, 2]


def _snakemake(project, configfile, *args):
    command = [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile")]
    result = subprocess.run(
        [*command, "-d", str(project), "--configfile", configfile, "--cores", "2", *args],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=1200,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    return result


def _repack(folder: Path, loads: list[float]) -> None:
    """``folder``'s per-load images as one OME-TIFF of T frames (frame PLANES[i] holds the
    i-th load), with their pixel in µm, in place of fluorescence/."""
    images = [read_image(folder / "fluorescence" / f"{load:g}.tif") for load in loads]
    frames = np.empty((len(loads), *images[0].data.shape), images[0].data.dtype)
    for image, plane in zip(images, PLANES, strict=True):
        frames[plane] = image.data
    pixel_um = images[0].pixel_m * 1e6
    metadata = {"axes": "TYX", "PhysicalSizeX": pixel_um, "PhysicalSizeY": pixel_um}
    tifffile.imwrite(
        folder / "fluorescence.ome.tif",
        frames,
        ome=True,
        photometric="minisblack",
        metadata=metadata,
    )
    shutil.rmtree(folder / "fluorescence")


@pytest.fixture(scope="module")
def project(small_data, tmp_path_factory):
    """A project after both copies' contact-area jobs, the copies made from the small run's
    virtual PS sphere (the session's small-data run, tests/workflow/conftest.py)."""
    project = tmp_path_factory.mktemp("load_series")
    shutil.copytree(REPO / "config", project / "config")
    config = yaml.safe_load((project / "config" / "test.yaml").read_text())
    paths = RunPaths(config["run"])
    config["materials"] = ["PS"]
    sheet = pd.read_csv(project / "config" / "materials.tsv", sep="\t", dtype=str)
    ps = sheet[sheet["sphere"] == "PS"]
    loads = [float(f) for f in ps["loads_mn"].iloc[0].split(",")]
    rows = []
    for name in (PER_LOAD, SERIES):
        folder = project / "lab" / name
        shutil.copytree(small_data / paths.synthetic_sphere("PS"), folder)
        (folder / "truth.json").unlink()
        rows.append(ps.assign(sphere=name, data_source=str(folder)))
    _repack(project / "lab" / SERIES, loads)
    pd.concat(rows).to_csv(project / "config" / "own.tsv", sep="\t", index=False)
    config.update(materials_sheet="config/own.tsv")
    config["optics"] = {"images": {"load_series": {"axis": "frames", "planes": PLANES}}}
    (project / "config" / "own.yaml").write_text(yaml.safe_dump(config))
    targets = [paths.measured(CONTACT_AREA, "PS", name) for name in (PER_LOAD, SERIES)]
    _snakemake(project, "config/own.yaml", *targets)
    return project, targets


def test_the_series_file_gives_the_per_load_contact_areas(project):
    root, (per_load, series) = project
    a, b = pd.read_csv(root / per_load), pd.read_csv(root / series)
    assert list(b["image"]) == [str(root / "lab" / SERIES / "fluorescence.ome.tif")] * 5
    assert all(Path(p).parent.name == "fluorescence" for p in a["image"])
    assert len(set(a["area_um2"])) == 5  # five distinct areas: a swap of loads would show
    pd.testing.assert_frame_equal(
        a.drop(columns="image"), b.drop(columns="image"), check_exact=True
    )
    assert set(b["pixel_source"]) == {"file"}


def test_replacing_the_series_file_reruns_its_jobs_only(project):
    root, targets = project
    (root / "lab" / SERIES / "fluorescence.ome.tif").touch()
    dry = _snakemake(root, "config/own.yaml", "-n", *targets)
    jobs = [line.strip() for line in dry.stdout.splitlines() if "sphere=" in line]
    assert jobs and all(f"sphere={SERIES}" in line for line in jobs), dry.stdout[-2000:]
