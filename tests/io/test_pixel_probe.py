"""The header probe the DAG asks whether an image states its pixel size
(amontons.io.pixel_probe) agrees with the readers on files their own writers made: where it
says yes, the reader finds a pixel with no sheet value; where it says no, the reader needs
one."""

import numpy as np
import ptufile
import pylibCZIrw.czi as pyczi
import pytest
import tifffile

from amontons.io.confocal import ImageChoice, read_confocal
from amontons.io.confocal_writers import write_confocal
from amontons.io.layout import RawDataError
from amontons.io.pixel_probe import states_pixel_size, tiff_scan_side_m
from amontons.io.ptu import PtuError, read_ptu_header, read_ptu_image
from amontons.io.tiff import ImageError, read_tiff, write_image

DATA = np.arange(1, 65, dtype=np.uint16).reshape(8, 8)


def _czi_without_scaling(path):
    with pyczi.create_czi(str(path), exist_ok=True) as czi:
        czi.write(DATA[..., np.newaxis], plane={"C": 0, "T": 0, "Z": 0})
        czi.write_metadata(channel_names={0: "fluorescence"})


def _imagej(path, unit):
    metadata = {"axes": "YX", **({"unit": unit} if unit else {})}
    tifffile.imwrite(path, DATA, imagej=True, resolution=(4.0, 4.0), metadata=metadata)


WRITERS = {
    "25.tif": (lambda p: write_confocal(p, DATA, 200e-9, "tif"), True),
    "big.tif": (
        lambda p: tifffile.imwrite(
            p, DATA, bigtiff=True, resolution=(5e4, 5e4), resolutionunit="CENTIMETER"
        ),
        True,
    ),
    "untagged.tif": (lambda p: tifffile.imwrite(p, DATA), False),
    "72dpi.tif": (
        lambda p: tifffile.imwrite(p, DATA, resolution=(72, 72), resolutionunit=2),
        False,
    ),
    "25.ome.tif": (lambda p: write_confocal(p, DATA, 200e-9, "ome_tiff"), True),
    "bare.ome.tif": (
        lambda p: tifffile.imwrite(p, DATA, ome=True, photometric="minisblack"),
        False,
    ),
    "hyper.tif": (lambda p: _imagej(p, "um"), True),
    "nounit.tif": (lambda p: _imagej(p, None), False),
    "uncalibrated.tif": (lambda p: _imagej(p, "pixel"), False),
    "25.czi": (lambda p: write_confocal(p, DATA, 200e-9, "czi"), True),
    "bare.czi": (_czi_without_scaling, False),
}


@pytest.mark.parametrize("name", list(WRITERS))
def test_the_probe_says_what_the_reader_finds(tmp_path, name):
    write, states = WRITERS[name]
    path = tmp_path / name
    write(path)
    assert states_pixel_size(path) is states
    if states:
        assert read_confocal(path, None, ImageChoice()).pixel_source == "file"
    else:
        with pytest.raises(ImageError, match="no pixel size in the"):
            read_confocal(path, None, ImageChoice())


@pytest.mark.parametrize("name", ["25.tif", "25.czi"])
def test_a_file_that_is_not_its_format_is_named(tmp_path, name):
    (tmp_path / name).write_bytes(b"GIF89a not an image at all")
    with pytest.raises(RawDataError, match=rf"{name}: not a"):
        states_pixel_size(tmp_path / name)


SCAN = np.zeros((300, 200), dtype=np.float32)  # rows × columns: the shorter side is 200 px


@pytest.mark.parametrize(
    "write, sheet_pixel_m, side_px",
    [
        (lambda p: write_image(p, SCAN, 40e-9), None, 200),  # the virtual experiment's maps
        (lambda p: write_image(p, SCAN, 40e-9), 40e-9, 200),  # a sheet pixel agreeing
        (lambda p: tifffile.imwrite(p, SCAN, bigtiff=True, resolution=(2.5e5, 2.5e5),
                                    resolutionunit="CENTIMETER"), None, 200),
        (lambda p: tifffile.imwrite(p, SCAN.T), 40e-9, 200),  # no unit: the sheet's pixel
    ],
)  # fmt: skip
def test_a_tiff_scans_size_is_read_from_its_header_as_the_reader_reads_it(
    tmp_path, write, sheet_pixel_m, side_px
):
    """To the reader's pixel (the same rational resolution tags, 1e-12 relative for the one
    rounding of a division), times the header's width and length."""
    path = tmp_path / "afm_before.tif"
    write(path)
    pixel_m = read_tiff(path).pixel_x_m or sheet_pixel_m
    assert tiff_scan_side_m(path, sheet_pixel_m) == pytest.approx(side_px * pixel_m, rel=1e-12)


def test_a_tiff_scan_without_a_pixel_or_a_readable_header_has_no_size(tmp_path):
    """None: the job that reads the map then names the file or the missing pixel, or finds
    the map where a vendor's TIFF keeps it."""
    untagged = tmp_path / "untagged.tif"
    tifffile.imwrite(untagged, SCAN)
    truncated = tmp_path / "truncated.tif"
    write_image(truncated, SCAN, 40e-9)
    truncated.write_bytes(truncated.read_bytes()[:6])
    assert tiff_scan_side_m(untagged) is None
    # integer samples: a vendor's TIFF (or its preview page), whose map its reader finds
    preview = tmp_path / "preview.tif"
    tifffile.imwrite(preview, SCAN.astype(np.uint8), resolution=(2.5e5, 2.5e5),
                     resolutionunit="CENTIMETER")  # fmt: skip
    assert tiff_scan_side_m(preview, 40e-9) is None
    assert tiff_scan_side_m(truncated, 40e-9) is None
    assert tiff_scan_side_m(tmp_path / "absent.tif", 40e-9) is None


@pytest.mark.parametrize("pixel_um, states", [(0.2, True), (0.0, False)])
def test_the_probe_reads_a_ptu_header_as_the_photon_reader_does(tmp_path, pixel_um, states):
    """The FLIM photons' pixel (ImgHdr_PixResol, µm; 0: none given), read from the tag header
    with the standard library, agrees with ptufile's reading (amontons.io.ptu)."""
    path = tmp_path / "flim.ptu"
    histograms = np.ones((6, 4, 8), np.uint16)
    ptufile.imwrite(path, histograms, 25e-9, 16e-12, tags={"ImgHdr_PixResol": pixel_um})
    assert states_pixel_size(path) is states
    header = read_ptu_header(path)
    assert header.shape == (6, 4)
    # µm to m: one rounding
    assert header.pixel_m == (pytest.approx(0.2e-6, rel=1e-15) if states else None)
    if not states:
        with pytest.raises(PtuError, match="no pixel size"):
            read_ptu_image(path)


def test_a_ptu_cut_in_its_header_is_named(tmp_path):
    path = tmp_path / "flim.ptu"
    ptufile.imwrite(path, np.ones((4, 4, 8), np.uint16), 25e-9, 16e-12, pixel_resolution=0.2)
    path.write_bytes(path.read_bytes()[:200])
    with pytest.raises(RawDataError, match=r"flim\.ptu: the PTU header ends before Header_End"):
        states_pixel_size(path)
