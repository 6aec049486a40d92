"""Every value the sheet may leave blank because a file states it (the fluorescence and the
AFM pixel), run with the sheet blank, format by format: the file's own value is used, and
where neither the file nor the sheet gives one, a named error says so (never a TypeError).

The lifetime job is run through its script's entry point, as Snakemake runs it: that is
where a blank sheet pixel once met an arithmetic on None (a PTU file's photons state their
pixel in the header)."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import ptufile
import pytest
import tifffile

from amontons.io.confocal import NO_CHOICE
from amontons.io.confocal_writers import write_confocal
from amontons.io.heightmap import read_height_map
from amontons.io.layout import RawDataError
from amontons.io.ptu import write_ptu_image
from amontons.io.rawdata import read_bead, read_fluorescence, read_reflection
from amontons.io.tiff import write_image
from amontons.virtual.flim import TcspcSettings, photon_histograms

REPO = Path(__file__).resolve().parents[1]
PIXEL_M = 200e-9
OTSU = {"otsu_bins": 256, "min_separation": 0.5, "min_contrast": 5.0, "min_patch_px": 4}
SIDE = 32


def _script(name: str):
    """A rule's script as a module (its entry point runs only under Snakemake)."""
    spec = importlib.util.spec_from_file_location(name, REPO / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _lifetimes_s() -> np.ndarray:
    """1.3 ns in a disc of 9 px radius (the contact), 0.5 ns outside: appendix Fig. B.3."""
    rows, cols = np.indices((SIDE, SIDE))
    disc = np.hypot(rows - (SIDE - 1) / 2, cols - (SIDE - 1) / 2) <= 9
    return np.where(disc, 1.3e-9, 0.5e-9)


def _flim_ptu(path: Path, pixel_m: float | None) -> None:
    tcspc = TcspcSettings(
        photons_per_pixel=1000, irf_fwhm_s=200e-12, irf_peak_s=2e-9, bin_s=16e-12,
        sync_period_s=25e-9,
    )  # fmt: skip
    histograms = photon_histograms(_lifetimes_s(), tcspc, rng=np.random.default_rng(4))
    if pixel_m is None:  # a header whose pixel is 0: none given
        ptufile.imwrite(path, histograms, 25e-9, 16e-12, tags={"ImgHdr_PixResol": 0.0})
    else:
        write_ptu_image(path, histograms, bin_s=16e-12, sync_period_s=25e-9, pixel_m=pixel_m)


def _flim_tif(path: Path, pixel_m: float | None) -> None:
    noise = np.random.default_rng(5).normal(0, 0.02, (SIDE, SIDE))
    arrival_ns = (_lifetimes_s() * 1e9 + noise).astype(np.float32)
    if pixel_m is None:
        tifffile.imwrite(path, arrival_ns)
    else:
        write_image(path, arrival_ns, pixel_m)


FLIM = {"flim.ptu": _flim_ptu, "flim.tif": _flim_tif}


@pytest.mark.parametrize("name", sorted(FLIM))
def test_the_lifetime_job_takes_the_flim_files_pixel_with_the_sheet_blank(tmp_path, name):
    """The contact's 1.3 ns and the outside's 0.5 ns within 0.1 ns: the job measured the
    file (whose pixel it took from the file), it did not just run."""
    flim = tmp_path / name
    FLIM[name](flim, PIXEL_M)
    out = tmp_path / "lifetime.json"
    script = _script("measure_lifetime")
    script.main(str(flim), str(out), None, OTSU, 2, None, None)
    record = json.loads(out.read_text())
    assert record["map"] == str(flim)
    inside, outside = record["inside_ns"]["mean"], record["outside_ns"]["mean"]
    assert abs(inside - 1.3) < 0.1 and abs(outside - 0.5) < 0.1, record


@pytest.mark.parametrize("name", sorted(FLIM))
def test_a_flim_file_without_a_pixel_and_a_blank_sheet_is_named(tmp_path, name):
    flim = tmp_path / name
    FLIM[name](flim, None)
    script = _script("measure_lifetime")
    with pytest.raises(RawDataError, match=rf"{flim}: no pixel size"):
        script.main(str(flim), str(tmp_path / "lifetime.json"), None, OTSU, 2, None, None)
    assert not (tmp_path / "lifetime.json").exists()


IMAGE = np.arange(1, 257, dtype=np.uint16).reshape(16, 16)
CONFOCAL_READERS = {
    "fluorescence": read_fluorescence,
    "reflection": read_reflection,
    "bead": read_bead,
}


@pytest.mark.parametrize("image_format", ["tif", "ome_tiff", "czi"])
@pytest.mark.parametrize("role", sorted(CONFOCAL_READERS))
def test_a_confocal_image_gives_its_own_pixel_with_the_sheet_blank(tmp_path, role, image_format):
    suffix = {"tif": ".tif", "ome_tiff": ".ome.tif", "czi": ".czi"}[image_format]
    path = tmp_path / f"{role}{suffix}"
    write_confocal(path, IMAGE, PIXEL_M, image_format)
    image = CONFOCAL_READERS[role](path, None, choice=NO_CHOICE)
    assert image.pixel_m == pytest.approx(PIXEL_M, rel=1e-6)  # CZI stores the pixel in µm
    bare = tmp_path / f"bare_{role}.tif"
    tifffile.imwrite(bare, IMAGE)
    with pytest.raises(RawDataError, match=rf"{bare}: no pixel size"):
        CONFOCAL_READERS[role](bare, None, choice=NO_CHOICE)


def test_an_afm_map_gives_its_own_pixel_with_the_sheet_blank(tmp_path):
    rows, cols = np.indices((64, 64))
    heights = -((rows - 32.0) ** 2 + (cols - 32.0) ** 2) * (32e-9) ** 2 / (2 * 0.3e-3)
    path = tmp_path / "afm_before.tif"
    write_image(path, heights, 32e-9)
    assert read_height_map(path, fallback_pixel_m=None).pixel_m == pytest.approx(32e-9, rel=1e-12)
    bare = tmp_path / "afm_bare.npy"
    np.save(bare, heights)
    with pytest.raises(ValueError, match=rf"{bare}: .*pixel"):
        read_height_map(bare, fallback_pixel_m=None)
