"""Confocal images in the microscopes' own formats (amontons.io.confocal), each read from a real
file its format's own writer made: OME-TIFF and ImageJ hyperstacks by tifffile, CZI by
pylibCZIrw (Zeiss's libCZI). Pixel values and pixel sizes come back exactly; every kind of bad
file stops with an error that names the file and what it holds."""

import numpy as np
import pylibCZIrw.czi as pyczi
import pytest
import tifffile

from amontons.io.confocal import ImageChoice, read_confocal, read_planes
from amontons.io.confocal_writers import write_confocal
from amontons.io.layout import IMAGE_FORMATS, RawDataError
from amontons.io.rawdata import read_fluorescence, read_reflection
from amontons.io.tiff import ImageError, read_image, write_image

# 0.25 µm is a binary fraction: µm and m both hold it exactly, in every format's metadata.
PIXEL_M = 250e-9
PIXEL_UM = 0.25
RNG = np.random.default_rng(37)
# Two channels (fluorescence, reflection), three frames, 6 x 8 px: distinct counts everywhere.
STACK = RNG.integers(1, 4000, size=(3, 2, 6, 8)).astype(np.uint16)
CHANNELS = ["fluorescence", "reflection"]


def _ome(path, stack=STACK, pixel_um=PIXEL_UM, channels=CHANNELS):
    metadata = {"axes": "TCYX", "Channel": {"Name": channels}}
    if pixel_um is not None:
        metadata |= {
            "PhysicalSizeX": pixel_um,
            "PhysicalSizeXUnit": "µm",
            "PhysicalSizeY": pixel_um,
            "PhysicalSizeYUnit": "µm",
        }
    tifffile.imwrite(path, stack, ome=True, photometric="minisblack", metadata=metadata)
    return path


def _czi(path, stack=STACK, pixel_m=PIXEL_M, channels=CHANNELS, skip=(), scenes=1):
    """A CZI of ``stack`` (frames, channels, y, x) in each of ``scenes`` scenes (scene s holds
    stack + s); the planes (t, c) in ``skip`` are never written."""
    with pyczi.create_czi(str(path), exist_ok=True) as czi:
        for scene in range(scenes):
            for t, c in np.ndindex(*stack.shape[:2]):
                if (t, c) not in skip:
                    plane = (stack[t, c] + scene)[..., np.newaxis]
                    czi.write(plane, plane={"T": t, "C": c, "Z": 0}, scene=scene)
        names = dict(enumerate(channels))
        czi.write_metadata(channel_names=names, scale_x=pixel_m or 0.0, scale_y=pixel_m or 0.0)
    return path


@pytest.mark.parametrize("name", ["25.ome.tif", "25.ome.tiff"])
def test_ome_tiff_written_by_tifffile_gives_the_chosen_channel_frame_and_pixel(tmp_path, name):
    path = _ome(tmp_path / name)
    image = read_confocal(path, None, ImageChoice(channel="reflection", frames=2))
    np.testing.assert_array_equal(image.data, STACK[2, 1])
    assert image.data.dtype == np.uint16
    assert image.pixel_m == PIXEL_M and image.pixel_source == "file"


def test_imagej_hyperstack_written_by_tifffile_gives_the_chosen_channel_and_pixel(tmp_path):
    path = tmp_path / "25.tif"
    resolution = (1 / PIXEL_UM, 1 / PIXEL_UM)  # pixels per µm
    tifffile.imwrite(
        path, STACK, imagej=True, resolution=resolution, metadata={"axes": "TCYX", "unit": "um"}
    )
    image = read_confocal(path, None, ImageChoice(channel=0, frames=1))
    np.testing.assert_array_equal(image.data, STACK[1, 0])
    assert image.pixel_m == PIXEL_M and image.pixel_source == "file"


def test_czi_written_by_pylibczirw_gives_the_chosen_scene_channel_frame_and_pixel(tmp_path):
    path = _czi(tmp_path / "25.czi", scenes=2)
    planes = read_planes(path, series=1)
    assert planes.channels == tuple(CHANNELS) and planes.series_count == 2
    image = read_confocal(path, None, ImageChoice(channel="fluorescence", series=1, frames=0))
    np.testing.assert_array_equal(image.data, STACK[0, 0] + 1)
    assert image.data.dtype == np.uint16
    assert image.pixel_m == PIXEL_M and image.pixel_source == "file"


def test_frames_mean_averages_the_frames_and_a_lone_frame_is_returned_as_stored(tmp_path):
    image = read_confocal(_ome(tmp_path / "a.ome.tif"), None, ImageChoice(channel="fluorescence"))
    np.testing.assert_array_equal(image.data, STACK[:, 0].mean(axis=0))
    single = read_confocal(_czi(tmp_path / "b.czi", STACK[:1, :1], channels=["f"]), None)
    np.testing.assert_array_equal(single.data, STACK[0, 0])
    assert single.data.dtype == np.uint16


def test_a_plain_2d_tiff_is_read_exactly_as_before(tmp_path):
    write_image(tmp_path / "25.tif", STACK[0, 0], PIXEL_M)
    plain, confocal = read_image(tmp_path / "25.tif"), read_confocal(tmp_path / "25.tif")
    assert plain.data.tobytes() == confocal.data.tobytes()
    assert (plain.pixel_m, plain.pixel_source) == (confocal.pixel_m, confocal.pixel_source)


@pytest.mark.parametrize("image_format", ["tif", "ome_tiff", "czi"])
def test_the_virtual_experiments_writers_round_trip_pixels_and_pixel(tmp_path, image_format):
    data = STACK[0, 0]
    suffix = IMAGE_FORMATS[image_format]
    write_confocal(tmp_path / f"25{suffix}", data, 200e-9, image_format)
    image = read_confocal(tmp_path / f"25{suffix}", 200e-9)
    assert image.data.tobytes() == data.tobytes() and image.data.dtype == data.dtype
    # the same double as the plain TIFF's tag (50000 px/cm): 0.2 µm read as float("0.2") / 1e6
    # was one ulp off, and every area and PSF width measured on it with it
    assert image.pixel_m == 200e-9


@pytest.mark.parametrize("pixel_nm", ["200", "130", "32", "97.65625"])
def test_decimal_pixel_sizes_read_as_the_nearest_double_in_every_unit(tmp_path, pixel_nm):
    metres = float(pixel_nm + "e-9")
    for unit, text in (("µm", f"{float(pixel_nm) / 1000!r}"), ("nm", pixel_nm)):
        path = tmp_path / f"{unit}.ome.tif"
        metadata = {"axes": "YX", "PhysicalSizeX": text, "PhysicalSizeXUnit": unit}
        tifffile.imwrite(path, STACK[0, 0], ome=True, metadata=metadata)
        assert read_confocal(path, None).pixel_m == metres, unit


# --- bad files: each kind stops with a named error ---


@pytest.mark.parametrize("write", [_ome, _czi], ids=["ome_tiff", "czi"])
def test_no_pixel_size_in_the_file_takes_the_sheets_and_says_so_or_stops(tmp_path, write):
    suffix = ".ome.tif" if write is _ome else ".czi"
    path = write(tmp_path / f"25{suffix}", **{"pixel_um" if write is _ome else "pixel_m": None})
    choice = ImageChoice(channel="fluorescence", frames=0)
    with pytest.raises(ImageError, match=rf"25{suffix}: no pixel size in the .* metadata and no "):
        read_confocal(path, None, choice)
    image = read_confocal(path, 200e-9, choice)
    assert (image.pixel_m, image.pixel_source) == (200e-9, "sheet")


@pytest.mark.parametrize("write", [_ome, _czi], ids=["ome_tiff", "czi"])
def test_a_channel_not_in_the_file_is_refused_with_the_files_channels(tmp_path, write):
    path = write(tmp_path / ("25.ome.tif" if write is _ome else "25.czi"))
    message = (
        r"channel 'FITC' chosen \(optics.images\), but the file has no such channel; it holds "
        r"1 series, channels \['fluorescence', 'reflection'\] and 3 frames of 6 x 8 px"
    )
    with pytest.raises(ImageError, match=message):
        read_confocal(path, PIXEL_M, ImageChoice(channel="FITC"))
    with pytest.raises(ImageError, match=r"2 channels .* and no optics.images channel chosen"):
        read_confocal(path, PIXEL_M)


def test_a_series_or_frame_the_file_lacks_is_refused_with_what_it_holds(tmp_path):
    path = _czi(tmp_path / "25.czi")
    with pytest.raises(ImageError, match=r"25\.czi: series 1 chosen .* holds 1 series \(0 to 0\)"):
        read_confocal(path, PIXEL_M, ImageChoice(channel=0, series=1))
    with pytest.raises(
        ImageError, match=r"25\.czi: frame 3 chosen .* 3 frames .* index from 0 to 2"
    ):
        read_confocal(path, PIXEL_M, ImageChoice(channel=0, frames=3))


@pytest.mark.parametrize("write", [_ome, _czi], ids=["ome_tiff", "czi"])
def test_a_truncated_file_is_refused_naming_it(tmp_path, write):
    path = write(tmp_path / ("25.ome.tif" if write is _ome else "25.czi"))
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    with pytest.raises(ImageError, match=rf"{path.name}: not a readable .* expected a complete"):
        read_confocal(path, PIXEL_M, ImageChoice(channel="fluorescence"))


def test_a_channel_that_holds_no_image_is_refused(tmp_path):
    # A CZI whose reflection channel was named but never recorded (libCZI reads its absent
    # planes as 0) and an OME-TIFF whose reflection detector counted nothing: neither is an
    # image.
    three = np.concatenate([STACK, STACK[:, :1]], axis=1)
    absent = _czi(
        tmp_path / "25.czi",
        three,
        channels=[*CHANNELS, "transmission"],
        skip={(0, 1), (1, 1), (2, 1)},
    )
    dark = STACK.copy()
    dark[:, 1] = 0
    zero = _ome(tmp_path / "50.ome.tif", dark)
    for path in (absent, zero):
        with pytest.raises(
            ImageError, match=rf"{path.name}: channel 'reflection' holds no image \(all 144 pixels"
        ):
            read_confocal(path, PIXEL_M, ImageChoice(channel="reflection"))
        read_confocal(path, PIXEL_M, ImageChoice(channel="fluorescence"))  # the other one is


@pytest.mark.parametrize("write", [_ome, _czi, None], ids=["ome_tiff", "czi", "tif"])
def test_a_file_and_sheet_pixel_more_than_1_percent_apart_stop_naming_both(tmp_path, write):
    if write is None:
        path = tmp_path / "25.tif"
        write_image(path, STACK[0, 0], PIXEL_M)
    else:
        path = write(tmp_path / ("25.ome.tif" if write is _ome else "25.czi"))
    choice = ImageChoice(channel="fluorescence", frames=0) if write else ImageChoice()
    message = (
        rf"{path.name}: the .* give a pixel of 250 nm, the sheet's fluorescence_pixel_nm is "
        r"253 nm: they differ by 1\.19%; expected them within 1%"
    )
    with pytest.raises(ImageError, match=message):
        read_confocal(path, 253e-9, choice)
    assert read_confocal(path, 252e-9, choice).pixel_m == PIXEL_M  # 0.8 %: the file's


def test_rawdata_readers_pass_the_choice_and_name_what_they_read(tmp_path):
    path = _czi(tmp_path / "reflection.czi")
    like = read_fluorescence(path, None, ImageChoice(channel="fluorescence", frames=0))
    reflection = read_reflection(path, None, like=like, choice=ImageChoice("reflection", 0, 0))
    np.testing.assert_array_equal(reflection.data, STACK[0, 1])
    with pytest.raises(RawDataError, match=r"reflection image: .*reflection\.czi: channel 'x'"):
        read_reflection(path, None, choice=ImageChoice(channel="x"))
