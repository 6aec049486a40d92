"""A sphere's whole load series in one confocal file (config optics.images.load_series): one
series or one frame per load, each read from a real file its format's own writer made
(OME-TIFF and ImageJ hyperstacks by tifffile, CZI by pylibCZIrw). Every load's image is a
distinct known array, so a plane read for the wrong load cannot pass; pixel values and pixel
sizes come back exactly. A file with a plane too many or too few, and a choice that picks
along the load axis too, stop with errors that name the file and the loads."""

import numpy as np
import pylibCZIrw.czi as pyczi
import pytest
import tifffile

from amontons.io.confocal import ImageChoice, LoadPlane, read_confocal, read_planes
from amontons.io.layout import IN_LOAD_ORDER, RawDataError, load_axis_conflict, plane_loads
from amontons.io.pixel_probe import load_plane_count
from amontons.io.rawdata import fluorescence_planes, read_fluorescence_loads
from amontons.io.tiff import ImageError, write_image

# 0.25 µm is a binary fraction: µm and m both hold it exactly, in every format's metadata.
PIXEL_M = 250e-9
PIXEL_UM = 0.25
LOADS = [25.0, 50.0, 100.0]
CHANNELS = ["fluorescence", "reflection"]
RNG = np.random.default_rng(3737)
# One (channels, y, x) stack per load, 6 x 8 px: distinct counts everywhere, so each load's
# image differs from every other load's and from the other channel.
PER_LOAD = RNG.integers(1, 4000, size=(len(LOADS), 2, 6, 8)).astype(np.uint16)
# A file whose planes are not in the sheet's order: plane p holds the load ORDER.index(p) ...
PLANES = [2, 0, 1]  # each load's plane index, in the sheet's load order
SHUFFLED = np.empty_like(PER_LOAD)
for _load, _plane in enumerate(PLANES):
    SHUFFLED[_plane] = PER_LOAD[_load]
OME_PIXEL = {
    "PhysicalSizeX": PIXEL_UM,
    "PhysicalSizeXUnit": "µm",
    "PhysicalSizeY": PIXEL_UM,
    "PhysicalSizeYUnit": "µm",
}


def _ome_series(path, stacks=PER_LOAD):
    """An OME-TIFF with one series (OME image) per entry of ``stacks`` (channels, y, x)."""
    with tifffile.TiffWriter(path, ome=True) as tif:
        for stack in stacks:
            metadata = {"axes": "CYX", "Channel": {"Name": CHANNELS}} | OME_PIXEL
            tif.write(stack, photometric="minisblack", metadata=metadata)
    return path


def _ome_frames(path, stacks=PER_LOAD):
    """An OME-TIFF of one series whose T frames are ``stacks``."""
    metadata = {"axes": "TCYX", "Channel": {"Name": CHANNELS}} | OME_PIXEL
    tifffile.imwrite(path, stacks, ome=True, photometric="minisblack", metadata=metadata)
    return path


def _imagej_frames(path, stacks=PER_LOAD):
    """An ImageJ hyperstack whose T frames are ``stacks``."""
    resolution = (1 / PIXEL_UM, 1 / PIXEL_UM)  # pixels per µm
    metadata = {"axes": "TCYX", "unit": "um"}
    tifffile.imwrite(path, stacks, imagej=True, resolution=resolution, metadata=metadata)
    return path


def _czi(path, stacks=PER_LOAD, axis="series"):
    """A CZI holding ``stacks``: one scene each (``axis`` 'series'), or one T each."""
    with pyczi.create_czi(str(path), exist_ok=True) as czi:
        for i, stack in enumerate(stacks):
            for c, plane in enumerate(stack):
                t, scene = (0, i) if axis == "series" else (i, 0)
                czi.write(plane[..., np.newaxis], plane={"T": t, "C": c, "Z": 0}, scene=scene)
        czi.write_metadata(
            channel_names=dict(enumerate(CHANNELS)), scale_x=PIXEL_M, scale_y=PIXEL_M
        )
    return path


def _images(axis, plane_loads_mn, **choice):
    """A rule's ``images`` param for a load-series file (Spheres.fluorescence_choice); the
    channel by index, as ImageJ hyperstacks name none."""
    base = {"channel": 0, "series": 0, "frames": "mean"} | choice
    return base | {"load_series": {"axis": axis, "plane_loads_mn": list(plane_loads_mn)}}


WRITERS = {
    "ome_series": ("series", _ome_series, "all.ome.tif"),
    "ome_frames": ("frames", _ome_frames, "all.ome.tif"),
    "imagej_frames": ("frames", _imagej_frames, "all.tif"),
    "czi_scenes": ("series", _czi, "all.czi"),
    "czi_frames": ("frames", lambda p, s=PER_LOAD: _czi(p, s, axis="frames"), "all.czi"),
}


@pytest.mark.parametrize("kind", WRITERS)
def test_each_load_gets_its_own_plane_in_load_order(tmp_path, kind):
    axis, write, name = WRITERS[kind]
    path = write(tmp_path / name)
    images = read_fluorescence_loads(path, LOADS, None, _images(axis, LOADS))
    for load, image in enumerate(images):
        np.testing.assert_array_equal(image.data, PER_LOAD[load, 0])
        assert image.data.dtype == np.uint16 and image.path == path
        assert image.pixel_m == PIXEL_M and image.pixel_source == "file"


@pytest.mark.parametrize("kind", WRITERS)
def test_a_planes_list_maps_a_shuffled_file_and_any_subset_of_loads(tmp_path, kind):
    """Planes stored 50, 100, 25 mN; the list [2, 0, 1] says so. Asked for in another order,
    or one load alone (as the edge gap reads its load), each load still gets its image."""
    axis, write, name = WRITERS[kind]
    path = write(tmp_path / name, SHUFFLED)
    by_plane = plane_loads(LOADS, PLANES, "sphere PS")
    assert by_plane == [50.0, 100.0, 25.0]
    images = _images(axis, by_plane, channel=1)
    for asked in ([100.0, 25.0, 50.0], [25.0]):
        read = read_fluorescence_loads(path, asked, None, images)
        for load, image in zip(asked, read, strict=True):
            np.testing.assert_array_equal(image.data, PER_LOAD[LOADS.index(load), 1])


def test_the_frames_choice_applies_within_each_series(tmp_path):
    """Series carry the loads; each series may hold frames (here 2), which frames picks or
    averages as for a per-load file."""
    stacks = np.stack([PER_LOAD, PER_LOAD + 7], axis=1)  # (loads, frames, channels, y, x)
    path = tmp_path / "all.ome.tif"
    with tifffile.TiffWriter(path, ome=True) as tif:
        for stack in stacks:
            metadata = {"axes": "TCYX", "Channel": {"Name": CHANNELS}} | OME_PIXEL
            tif.write(stack, photometric="minisblack", metadata=metadata)
    second = read_fluorescence_loads(path, LOADS, None, _images("series", LOADS, frames=1))
    mean = read_fluorescence_loads(path, LOADS, None, _images("series", LOADS))
    for load in range(len(LOADS)):
        np.testing.assert_array_equal(second[load].data, PER_LOAD[load, 0] + 7)
        np.testing.assert_array_equal(mean[load].data, PER_LOAD[load, 0] + 3.5)


@pytest.mark.parametrize("kind", WRITERS)
@pytest.mark.parametrize("planes", [2, 4])
def test_a_plane_too_many_or_too_few_stops_naming_the_file_and_the_loads(tmp_path, kind, planes):
    axis, write, name = WRITERS[kind]
    stacks = np.concatenate([PER_LOAD, PER_LOAD[:1] + 1])[:planes]
    path = write(tmp_path / name, stacks)
    held = f"it holds {planes} series" if axis == "series" else f"and {planes} frames of 6 x 8"
    message = (
        rf"fluorescence image: .*{name}: .*{held}.*, but optics\.images\.load_series puts the "
        rf"sheet's 3 loads \[25\.0, 50\.0, 100\.0\] mN along its {axis}, one each; expected "
        rf"exactly 3 {axis}"
    )
    with pytest.raises(RawDataError, match=message):
        read_fluorescence_loads(path, LOADS, None, _images(axis, LOADS))


def test_a_choice_along_the_load_axis_too_is_refused():
    for axis, key, value in (("frames", "frames", 1), ("series", "series", 1)):
        load = LoadPlane(axis, tuple(LOADS), 50.0)
        with pytest.raises(
            ValueError, match=rf"optics\.images\.{key} is 1, but .*axis is '{axis}'"
        ):
            ImageChoice(**{key: value}, load=load)
    # the other axis's choice stays free
    assert ImageChoice(frames=1, load=LoadPlane("series", tuple(LOADS), 50.0)).frames == 1
    assert load_axis_conflict("frames", {"series": 2, "frames": "mean"}) is None


def test_a_load_that_is_no_plane_and_a_planes_list_that_does_not_fit_are_refused(tmp_path):
    path = _ome_series(tmp_path / "all.ome.tif")
    with pytest.raises(RawDataError, match=r"all\.ome\.tif: no plane for \[75\.0\] mN"):
        fluorescence_planes(path, [25.0, 75.0], _images("series", LOADS))
    for planes in ([0, 1], [0, 1, 1], [1, 2, 3]):
        with pytest.raises(RawDataError, match=r"sphere PS: .*planes .* for the sheet's 3 loads"):
            plane_loads(LOADS, planes, "sphere PS")
    assert plane_loads(LOADS, IN_LOAD_ORDER, "sphere PS") == LOADS


def test_a_plain_tiff_cannot_hold_a_load_series(tmp_path):
    path = tmp_path / "all.tif"
    write_image(path, PER_LOAD[0, 0], PIXEL_M)
    with pytest.raises(RawDataError, match=r"all\.tif: a plain TIFF holds one image"):
        read_fluorescence_loads(path, LOADS, None, _images("frames", LOADS, channel=None))


def test_the_file_pixel_is_held_to_the_sheets_within_1_percent(tmp_path):
    path = _ome_frames(tmp_path / "all.ome.tif")
    choice = ImageChoice("fluorescence", load=LoadPlane("frames", tuple(LOADS), 100.0))
    with pytest.raises(ImageError, match=r"all\.ome\.tif: .*250 nm.*253 nm.*expected them within"):
        read_confocal(path, 253e-9, choice)
    image = read_confocal(path, 252e-9, choice)  # 0.8 %: the file's
    assert image.pixel_m == PIXEL_M and image.pixel_source == "file"
    np.testing.assert_array_equal(image.data, PER_LOAD[2, 0])


@pytest.mark.parametrize("kind", WRITERS)
@pytest.mark.parametrize("planes", [1, 3, 4])
def test_the_header_count_the_dag_checks_is_the_readers(tmp_path, kind, planes):
    """The DAG counts a load-series file's planes from its header alone
    (amontons.io.pixel_probe.load_plane_count); the count must be the one the jobs' reader
    finds, along both axes."""
    axis, write, name = WRITERS[kind]
    path = write(tmp_path / name, np.concatenate([PER_LOAD, PER_LOAD[:1] + 1])[:planes])
    read = read_planes(path)
    assert load_plane_count(path, "series") == read.series_count
    assert load_plane_count(path, "frames") == len(read.data)
    assert load_plane_count(path, axis) == planes


def test_the_header_count_of_a_plain_tiff_is_left_to_the_reader(tmp_path):
    write_image(tmp_path / "all.tif", PER_LOAD[0, 0], PIXEL_M)
    assert load_plane_count(tmp_path / "all.tif", "frames") is None
