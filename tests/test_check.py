"""The data check (python -m amontons.check) on a measured sphere's confocal files: each image
with its format, shape, pixel and where the pixel came from; images that state no pixel, with
none in the sheet, stop the run before any job, naming the sphere and the file."""

import shutil

import numpy as np
import pandas as pd
import ptufile
import pylibCZIrw.czi as pyczi
import pytest
import tifffile
import yaml

from amontons.check import check, report

LOADS = (25, 50, 100, 200, 300)
CHANNELS = ["fluorescence", "reflection"]


def _two_channel_ome(path, load, pixel_um):
    planes = np.stack([np.full((16, 16), load, np.uint16), np.full((16, 16), 7, np.uint16)])
    metadata = {"axes": "CYX", "Channel": {"Name": CHANNELS}}
    if pixel_um is not None:
        metadata |= {"PhysicalSizeX": pixel_um, "PhysicalSizeY": pixel_um}
    tifffile.imwrite(path, planes, ome=True, photometric="minisblack", metadata=metadata)


def _reflection_czi(path):
    with pyczi.create_czi(str(path), exist_ok=True) as czi:
        for channel in range(2):
            plane = np.full((16, 16, 1), 100 + channel, np.uint16)
            czi.write(plane, plane={"C": channel, "T": 0, "Z": 0})
        names = dict(enumerate(CHANNELS))
        czi.write_metadata(channel_names=names, scale_x=250e-9, scale_y=250e-9)


@pytest.fixture
def project(tmp_path, repo, monkeypatch):
    """A project whose one PS sphere is measured: two-channel OME-TIFFs per load (0.25 µm
    pixels), a CZI reflection image; the sheet's fluorescence_pixel_nm left empty."""
    shutil.copytree(repo / "config", tmp_path / "config")
    lab = tmp_path / "lab"
    (lab / "fluorescence").mkdir(parents=True)
    for load in LOADS:
        _two_channel_ome(lab / "fluorescence" / f"{load}mN.ome.tif", load, 0.25)
    _reflection_czi(lab / "reflection.czi")
    sheet = pd.read_csv(repo / "config" / "materials.tsv", sep="\t", dtype=str)
    row = sheet[sheet["sphere"] == "PS"].assign(data_source=str(lab), fluorescence_pixel_nm="")
    row.to_csv(tmp_path / "config" / "own.tsv", sep="\t", index=False)
    overlay = {
        "materials": ["PS"],
        "materials_sheet": "config/own.tsv",
        "optics": {"images": {"channel": "fluorescence", "reflection_channel": "reflection"}},
    }
    (tmp_path / "config" / "own.yaml").write_text(yaml.safe_dump(overlay))
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_the_check_lists_each_images_format_shape_and_pixel_source(project, repo):
    (plan,) = check(["config/own.yaml"], repo / "workflow")
    assert plan["errors"] == []
    images = [f for f in plan["files"] if f["path"].endswith((".ome.tif", ".czi"))]
    assert [f["format"] for f in images] == ["OME-TIFF"] * len(LOADS) + ["CZI"]
    assert all(f["shape"] == [16, 16] and f["pixel_nm"] == 250.0 for f in images)
    assert all(f["pixel_from"] == "file" for f in images)
    text = report([plan])
    assert "25mN.ome.tif [OME-TIFF]: 16×16 px, pixel 250 nm (file)" in text
    assert "reflection.czi [CZI]: 16×16 px, pixel 250 nm (file)" in text


def test_a_channel_the_files_lack_is_reported_with_what_they_hold(project, repo):
    overlay = yaml.safe_load((project / "config" / "own.yaml").read_text())
    overlay["optics"]["images"]["reflection_channel"] = "transmission"
    (project / "config" / "own.yaml").write_text(yaml.safe_dump(overlay))
    (plan,) = check(["config/own.yaml"], repo / "workflow")
    (reflection,) = [f for f in plan["files"] if f["path"].endswith("reflection.czi")]
    assert "channel 'transmission' chosen" in reflection["error"]
    assert "channels ['fluorescence', 'reflection']" in reflection["error"]


def test_images_without_a_pixel_and_an_empty_sheet_cell_stop_before_any_job(project, repo):
    _two_channel_ome(project / "lab" / "fluorescence" / "50mN.ome.tif", 50, None)
    with pytest.raises(ValueError, match=r"sphere PS: .*50mN\.ome\.tif; expected the sheet's"):
        check(["config/own.yaml"], repo / "workflow")


def _series_file(project, loads):
    """The per-load images of ``loads`` repacked into lab/fluorescence.ome.tif, one series
    each (series i holds the i-th of ``loads``, its fluorescence channel filled with the load),
    in place of the fluorescence/ folder; the overlay maps the series in the sheet's order."""
    lab = project / "lab"
    shutil.rmtree(lab / "fluorescence")
    with tifffile.TiffWriter(lab / "fluorescence.ome.tif", ome=True) as tif:
        for load in loads:
            planes = np.stack([np.full((16, 16), load, np.uint16), np.full((16, 16), 7, np.uint16)])
            metadata = {"axes": "CYX", "Channel": {"Name": CHANNELS}}
            tif.write(planes, photometric="minisblack", metadata=metadata | {"PhysicalSizeX": 0.25})
    overlay = yaml.safe_load((project / "config" / "own.yaml").read_text())
    overlay["optics"]["images"]["load_series"] = {"axis": "series", "planes": "in_load_order"}
    (project / "config" / "own.yaml").write_text(yaml.safe_dump(overlay))


def test_a_load_series_file_is_listed_once_per_load_with_its_plane(project, repo):
    _series_file(project, LOADS)
    (plan,) = check(["config/own.yaml"], repo / "workflow")
    assert plan["errors"] == []
    series = [f for f in plan["files"] if f["path"].endswith("fluorescence.ome.tif")]
    assert [(f["load_mn"], f["plane"]) for f in series] == [
        (load, f"series {i}") for i, load in enumerate(LOADS)
    ]
    assert all(f["pixel_nm"] == 250.0 and f["pixel_from"] == "file" for f in series)
    text = report([plan])
    assert "fluorescence.ome.tif series 2 = 100 mN [OME-TIFF]: 16×16 px, pixel 250 nm" in text


def test_a_load_series_file_with_a_series_too_few_stops_before_any_job(project, repo):
    """Its header says it holds 4 series for 5 loads: the run would stop before any job."""
    _series_file(project, LOADS[:-1])
    message = (
        r"sphere PS: .*fluorescence\.ome\.tif: it holds 4 series \(its header says\), but "
        r"optics\.images\.load_series puts the sheet's 5 loads .* expected exactly 5 series"
    )
    with pytest.raises(ValueError, match=message):
        check(["config/own.yaml"], repo / "workflow")


def test_a_ptu_with_a_blank_sheet_pixel_is_listed_with_its_headers_pixel(project, repo):
    """The FLIM photons state their pixel in the PTU header (ImgHdr_PixResol): the check
    lists it from the file, and a PTU that states none, with the sheet blank, stops before
    any job naming it."""
    flim = project / "lab" / "flim.ptu"
    histograms = np.ones((12, 10, 16), np.uint16)
    ptufile.imwrite(flim, histograms, 25e-9, 16e-12, pixel_resolution=0.2)
    (plan,) = check(["config/own.yaml"], repo / "workflow")
    (record,) = [f for f in plan["files"] if f["path"] == str(flim)]
    assert record["shape"] == [12, 10] and record["pixel_from"] == "file"
    assert record["pixel_nm"] == pytest.approx(200.0, rel=1e-12)
    assert f"{flim} [ptu]: 12×10 px, pixel 200 nm (file)" in report([plan])
    ptufile.imwrite(flim, histograms, 25e-9, 16e-12, tags={"ImgHdr_PixResol": 0.0})
    with pytest.raises(ValueError, match=rf"sphere PS: {flim}; expected the sheet's"):
        check(["config/own.yaml"], repo / "workflow")
