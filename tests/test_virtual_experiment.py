"""The walking-skeleton virtual experiment: files that read back, determinism, and truth that an
independent recomputation and the analysis recover."""

import json

import numpy as np
import pytest
import yaml

from amontons.images import read_image
from amontons.optics.area import otsu_contact_area
from amontons.powerlaw import fit_power_law
from amontons.rawdata import (
    RawDataError,
    fluorescence_images,
    read_absorbance,
    read_bead,
    read_flim,
    read_reflection,
    read_rheometer_traces,
)
from amontons.virtual.experiment import InstrumentSettings, generate_sphere

LOADS_MN = [25.0, 50.0, 100.0, 200.0]


def _settings(repo, **overrides):
    """The virtual experiment of config/test.yaml, with ``overrides`` (config units)."""
    with open(repo / "config" / "test.yaml") as stream:
        settings = yaml.safe_load(stream)["virtual_experiment"]
    settings.update(overrides)
    return InstrumentSettings.from_config(settings)


def _generate(folder, repo, seed=11, flim_load_n=None, **overrides):
    return generate_sphere(
        folder,
        sphere="glass",
        diameter_m=4e-3,
        e_star_pa=32.8e9,
        loads_n=[f * 1e-3 for f in LOADS_MN],
        pixel_m=200e-9,
        reflection_load_n=0.025,
        flim_load_n=flim_load_n,
        shear_strength_pa=30e6,
        settings=_settings(repo, **overrides),
        seed=seed,
    )


@pytest.fixture(scope="module")
def glass(tmp_path_factory, repo):
    folder = tmp_path_factory.mktemp("glass")
    return folder, _generate(folder, repo, flim_load_n=0.1)


def test_images_read_back_as_16_bit_with_their_pixel(glass):
    folder, truth = glass
    for path in fluorescence_images(folder / "fluorescence", LOADS_MN):
        image = read_image(path)
        assert image.data.dtype == np.uint16
        assert image.data.shape == (truth["image_side_px"],) * 2
        assert image.pixel_m == pytest.approx(200e-9, rel=1e-12)
        # Background ≈ 120 counts, contact ≈ 1500–2000: nothing near 16-bit saturation.
        assert 50 < np.median(image.data) < 400 and image.data.max() < 5000


def test_truth_matches_an_independent_hertz_recomputation(glass):
    _, truth = glass
    a = (3 * 25e-3 * 2e-3 / (4 * 32.8e9)) ** (1 / 3)
    assert truth["contact_radius_um"][0] == pytest.approx(a * 1e6, rel=1e-12)
    assert json.loads(json.dumps(truth)) == truth


RAW_FILES = [
    "fluorescence/25.tif",
    "rheometer/25.csv",
    "reflection.tif",
    "bead.tif",
    "absorbance.csv",
    "flim.tif",
]


@pytest.mark.parametrize("name", RAW_FILES)
def test_same_seed_gives_identical_files_and_another_seed_does_not(glass, tmp_path, repo, name):
    folder, _ = glass
    _generate(tmp_path / "same", repo, flim_load_n=0.1)
    _generate(tmp_path / "other", repo, seed=12, flim_load_n=0.1)
    original = (folder / name).read_bytes()
    assert (tmp_path / "same" / name).read_bytes() == original
    assert (tmp_path / "other" / name).read_bytes() != original


def test_instruments_draw_independent_noise(glass, tmp_path, repo):
    # Changing one instrument (the bead's brightness) leaves every other file byte-identical.
    folder, _ = glass
    _generate(tmp_path / "brighter", repo, flim_load_n=0.1, bead_peak_counts=3000.0)
    assert (tmp_path / "brighter" / "bead.tif").read_bytes() != (folder / "bead.tif").read_bytes()
    for name in RAW_FILES:
        if name != "bead.tif":
            assert (tmp_path / "brighter" / name).read_bytes() == (folder / name).read_bytes()


def test_every_raw_file_reads_back_through_the_readers(glass):
    folder, truth = glass
    fluorescence = read_image(folder / "fluorescence" / "25.tif")
    reflection = read_reflection(folder / "reflection.tif", like=fluorescence)
    assert reflection.data.dtype == np.uint16
    assert read_bead(folder / "bead.tif").data.dtype == np.uint16
    arrival = read_flim(folder / "flim.tif").data
    # 0.1 ns noise around 0.5 and 1.3 ns: every pixel within 0–2 ns.
    assert arrival.dtype == np.float32 and arrival.min() > 0 and arrival.max() < 2.0
    wavelength, absorbance = read_absorbance(folder / "absorbance.csv")
    assert wavelength[0] == 400 and wavelength[-1] == 600 and absorbance.max() < 0.003
    traces = read_rheometer_traces(folder / "rheometer", LOADS_MN)
    for trace, load in zip(traces, LOADS_MN, strict=True):
        assert trace.rotation_radius_m == pytest.approx(truth["rotation_radius_mm"] * 1e-3)
        # 0.2 mN normal-force noise averages to < 0.01 mN over 2000 samples.
        assert np.mean(trace.normal_force_n) * 1e3 == pytest.approx(load, abs=0.05)


def test_truth_holds_every_true_value(glass):
    _, truth = glass
    # Static friction is τ·A exactly; the first ring gap is λ/4n = 84.32 nm.
    np.testing.assert_allclose(
        truth["static_friction_mn"], np.array(truth["area_um2"]) * 1e-12 * 30e6 * 1e3
    )
    assert truth["first_ring_gap_nm"] == pytest.approx(84.32, abs=0.01)
    assert truth["grafting_density_per_um2"] == pytest.approx(7.745e4, rel=1e-3)
    assert truth["psf_fwhm_nm"] == pytest.approx(450.0)
    assert truth["intensity_pressure_exponent"] == 0.5
    assert truth["flim"]["contact_ns"] == 1.3 and truth["flim"]["contact_pixels"] > 0


def test_analysis_recovers_the_hertz_exponent_and_areas(glass):
    folder, truth = glass
    areas = []
    for path in fluorescence_images(folder / "fluorescence", LOADS_MN):
        image = read_image(path)
        areas.append(otsu_contact_area(image.data, image.pixel_m).area_m2 * 1e12)
    fit = fit_power_law(np.array(LOADS_MN), np.array(areas), x_ref=25)
    # Otsu on a PSF-blurred √p profile sits slightly inside the true edge: a bias of a few %
    # that shrinks as the contact grows, so the exponent comes out a little above 2/3.
    # Tolerances: exponent within 0.01, each area within 6 % of πa².
    assert fit.exponent.estimate == pytest.approx(2 / 3, abs=0.01)
    np.testing.assert_allclose(areas, truth["area_um2"], rtol=0.06)


def test_load_list_must_match_the_images(glass):
    folder, _ = glass
    with pytest.raises(RawDataError, match=r"no image for \[300.0\]"):
        fluorescence_images(folder / "fluorescence", [*LOADS_MN, 300.0])
    with pytest.raises(RawDataError, match=r"images not in the list: \[200.0\]"):
        fluorescence_images(folder / "fluorescence", LOADS_MN[:-1])


def test_saturating_settings_are_refused(tmp_path, repo):
    with pytest.raises(ValueError, match="lower contact_counts"):
        _generate(tmp_path, repo, contact_counts=60000.0)


def test_reflection_load_must_be_a_load(tmp_path, repo):
    with pytest.raises(ValueError, match="reflection load 30 mN is not one of the loads"):
        generate_sphere(
            tmp_path,
            sphere="glass",
            diameter_m=4e-3,
            e_star_pa=32.8e9,
            loads_n=[0.025, 0.05],
            pixel_m=200e-9,
            reflection_load_n=0.03,
            flim_load_n=None,
            shear_strength_pa=30e6,
            settings=_settings(repo),
            seed=1,
        )
