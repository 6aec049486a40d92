"""The virtual experiment: files that read back through the readers with the right metadata,
determinism, and truth that an independent recomputation and the analysis recover.

Two spheres at the small-data settings of config/test.yaml (256 nm solver pixel): a smooth
glass sphere, whose truth must be Hertz's, and a rough PS sphere under contact hardening,
whose AFM scans and plastic deformation the tests read back."""

import json

import numpy as np
import pytest

from amontons.config import read_config
from amontons.io.heightmap import read_height_map
from amontons.io.layout import RawDataError, fluorescence_images, per_load_files, rheometer_name
from amontons.io.rawdata import (
    read_absorbance,
    read_bead,
    read_flim,
    read_reflection,
    read_rheometer_traces,
)
from amontons.io.tiff import read_image
from amontons.measure.area import otsu_contact_area
from amontons.measure.topography import level_sphere
from amontons.physics import hertz
from amontons.physics.roughness import roughness_statistics
from amontons.power_law import fit_power_law
from amontons.virtual.experiment import generate_sphere
from amontons.virtual.settings import InstrumentSettings, SurfaceSettings

LOADS_MN = [25.0, 50.0, 100.0, 200.0]
# the truths' values in the records' config units: k = 10000 MPa/nm (1e19 Pa/m) makes glass's
# hardening layer negligible; PS flows by contact hardening at 5 MPa/nm
GLASS = {"diameter_m": 4e-3, "e_star_pa": 32.8e9, "roughness_rms_m": 0.0, "k": 10000.0}
PS = {"diameter_m": 0.6e-3, "e_star_pa": 3.7e9, "roughness_rms_m": 80e-9, "k": 5.0}


def _config(repo, **overrides):
    """The virtual experiment of config/test.yaml, with ``overrides`` (config units)."""
    config = read_config(repo / "config" / "config.yaml", repo / "config" / "test.yaml")
    settings = config["virtual_experiment"]
    settings.update(overrides)
    return settings, config["optics"]["newton_rings"]


def _generate(folder, repo, sphere="glass", seed=11, flim_load_n=None, truth=None, **overrides):
    """One sphere's files; ``truth``: its (model, value), contact hardening at the sphere's k
    where None."""
    spec = GLASS if sphere == "glass" else PS
    model, value = ("hardening", spec["k"]) if truth is None else truth
    settings, newton_rings = _config(repo, **overrides)
    return generate_sphere(
        folder,
        sphere=sphere,
        diameter_m=spec["diameter_m"],
        e_star_pa=spec["e_star_pa"],
        roughness_rms_m=spec["roughness_rms_m"],
        true_model=model,
        true_value=value,
        loads_n=[f * 1e-3 for f in LOADS_MN],
        pixel_m=200e-9,
        reflection_load_n=0.025,
        flim_load_n=flim_load_n,
        shear_strength_pa=30e6,
        settings=InstrumentSettings.from_config(settings, newton_rings),
        surface=SurfaceSettings.from_config(settings),
        seed=seed,
    )


@pytest.fixture(scope="module")
def glass(tmp_path_factory, repo):
    folder = tmp_path_factory.mktemp("glass")
    return folder, _generate(folder, repo, flim_load_n=0.1)


@pytest.fixture(scope="module")
def rough(tmp_path_factory, repo):
    """A rough PS sphere with a 1024 px AFM scan of two Hertz diameters, enough sag to fit the
    sphere."""
    folder = tmp_path_factory.mktemp("ps")
    return folder, _generate(folder, repo, sphere="PS", afm_side_px=1024)


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory, repo):
    """The rough sphere again with the same seed, with another seed, and with only the bead's
    brightness changed."""
    root = tmp_path_factory.mktemp("again")
    _generate(root / "same", repo, sphere="PS", afm_side_px=1024)
    _generate(root / "other", repo, sphere="PS", seed=12, afm_side_px=1024)
    _generate(root / "brighter", repo, sphere="PS", afm_side_px=1024, bead_peak_counts=3000.0)
    return root


def test_images_read_back_as_16_bit_with_their_pixel(glass):
    folder, truth = glass
    for path in fluorescence_images(folder / "fluorescence", LOADS_MN):
        image = read_image(path)
        assert image.data.dtype == np.uint16
        assert image.data.shape == (truth["image_side_px"],) * 2
        assert image.pixel_m == pytest.approx(200e-9, rel=1e-12)
        # Background ≈ 120 counts, contact ≈ 1500–2000: nothing near 16-bit saturation.
        assert 50 < np.median(image.data) < 400 and image.data.max() < 5000


def test_smooth_glass_truth_matches_an_independent_hertz_recomputation(glass):
    _, truth = glass
    radius, e_star = GLASS["diameter_m"] / 2, GLASS["e_star_pa"]
    for load, area, edge in zip(LOADS_MN, truth["area_um2"], truth["edge_radius_um"], strict=True):
        a = hertz.contact_radius(load * 1e-3, radius, e_star)
        # The solver's contact is a set of 256 nm pixels: its area is πa² to within one ring
        # of pixels (2Δx/a ≈ 5 % at 25 mN); measured +0.5 %, so 2 % holds with margin.
        assert area == pytest.approx(np.pi * a**2 * 1e12, rel=0.02)
        assert edge == pytest.approx(a * 1e6, rel=0.02)
    # Hertz approach d = a²/R (the solver's d is absolute for a free half-space).
    a0 = hertz.contact_radius(25e-3, radius, e_star)
    assert truth["approach_nm"][0] == pytest.approx(a0**2 / radius * 1e9, rel=0.02)
    assert truth["area_exponent"] == pytest.approx(2 / 3, abs=0.01)
    assert truth["edge_gap_nm"] == pytest.approx(0.0, abs=0.5)  # no roughness, no gap
    # Per ray (every degree): a smooth contact's rays all leave it at the Hertz radius, to
    # the staircase of its 256 nm solver pixels (a pixel corner reaches 0.7 px = 0.18 µm
    # past its centre), where the Hertz gap is still < 0.1 nm.
    profiles = truth["edge_profiles"]
    np.testing.assert_allclose(profiles["edge_radius_um"], a0 * 1e6, atol=0.3)
    assert profiles["mean_ring_gap_nm"] == pytest.approx(0.0, abs=0.5)
    assert max(profiles["local_gap_nm"]) < 0.5
    assert json.loads(json.dumps(truth)) == truth


RAW_FILES = [
    "fluorescence/25.tif",
    "rheometer/25.csv",
    "reflection.tif",
    "bead.tif",
    "absorbance.csv",
    "afm_before.tif",
    "afm_after.tif",
]


@pytest.mark.parametrize("name", RAW_FILES)
def test_same_seed_gives_identical_files_and_another_seed_does_not(rough, regenerated, name):
    folder, _ = rough
    original = (folder / name).read_bytes()
    assert (regenerated / "same" / name).read_bytes() == original
    assert (regenerated / "other" / name).read_bytes() != original


def test_instruments_draw_independent_noise(rough, regenerated):
    # Changing one instrument (the bead's brightness) leaves every other file byte-identical.
    folder, _ = rough
    brighter = regenerated / "brighter"
    assert (brighter / "bead.tif").read_bytes() != (folder / "bead.tif").read_bytes()
    for name in RAW_FILES:
        if name != "bead.tif":
            assert (brighter / name).read_bytes() == (folder / name).read_bytes()


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
    traces = read_rheometer_traces(
        per_load_files(folder / "rheometer", LOADS_MN, rheometer_name), LOADS_MN
    )
    for trace, load in zip(traces, LOADS_MN, strict=True):
        assert trace.rotation_radius_m == pytest.approx(truth["rotation_radius_mm"] * 1e-3)
        # 0.2 mN normal-force noise averages to < 0.01 mN over 2000 samples.
        assert np.mean(trace.normal_force_n) * 1e3 == pytest.approx(load, abs=0.05)


def test_afm_scans_read_back_with_their_pixel_curvature_and_roughness(rough):
    folder, truth = rough
    afm = truth["afm"]
    before = read_height_map(folder / "afm_before.tif")
    # The scan covers afm_field_factor (2) Hertz diameters at the largest load; 1024 px of
    # 32 nm cannot, so the pixel grows to that field over 1024 px.
    a_max = hertz.contact_radius(max(truth["loads_mn"]) * 1e-3, 0.3e-3, 3.7e9)
    assert before.pixel_m == pytest.approx(max(32e-9, 2 * 2 * a_max / 1024), rel=1e-6)
    assert afm["pixel_nm"] == pytest.approx(before.pixel_m * 1e9, rel=1e-6)
    assert before.heights.shape == (1024, 1024)
    fit = level_sphere(before.heights, before.pixel_m)
    # A 33 µm scan of a 0.3 mm sphere sags by ~450 nm, against 80 nm rms roughness whose long
    # waves (10 µm roll-off) look like form: the radius is what the data can tell to ~15 %.
    assert fit.radius_m == pytest.approx(0.3e-3, rel=0.15)
    # The scan-line offsets (2 nm) are found and removed; slope and curvature are set by the
    # short waves and come back within 5 % of the truth (noise 0.3 nm adds a little slope).
    found = roughness_statistics(fit.roughness, before.pixel_m)
    assert found.slope_rms == pytest.approx(afm["slope_rms"], rel=0.05)
    assert found.curvature_rms_per_m * 1e-6 == pytest.approx(afm["curvature_rms_per_um"], rel=0.1)


def test_afm_after_contact_is_flattened_by_the_plastic_displacement(rough):
    folder, truth = rough
    afm = truth["afm"]
    before = read_height_map(folder / "afm_before.tif").heights
    after = read_height_map(folder / "afm_after.tif").heights
    change = after - before
    # Artefacts of two scans: two 2 nm line offsets that may stack, and the extreme of 10⁶
    # noisy differences (5 σ of √2 × 0.3 nm). Beyond them the surface only goes down, by as
    # much as the truth's plastic depth inside the scan.
    artefacts = 2 * afm["line_offset_nm"] * 1e-9 + 5 * np.sqrt(2) * afm["noise_nm"] * 1e-9
    assert change.max() < artefacts
    assert -change.min() == pytest.approx(afm["max_plastic_depth_nm"] * 1e-9, abs=artefacts)
    assert afm["max_plastic_depth_nm"] > 20  # PS flows by tens of nm here


@pytest.fixture(scope="module")
def other_truths(tmp_path_factory, repo):
    """The rough PS sphere (the same surface) made elastic and with penetration hardness at
    110 MPa."""
    root = tmp_path_factory.mktemp("truths")
    return {
        model: _generate(root / model, repo, sphere="PS", truth=(model, value))
        for model, value in (("elastic", None), ("penetration_hardness", 110.0))
    }


def test_a_sphere_is_made_with_the_model_its_truth_names(other_truths):
    """Penetration hardness caps every pressure at p_Y, so its mean contact pressure stays
    below it and its area exceeds the elastic one at every load (the same surface and
    loads); an elastic sphere does not flow. The truth names the model and its value."""
    elastic, hardness = other_truths["elastic"], other_truths["penetration_hardness"]
    assert elastic["true_model"] == "elastic" and "hardness_mpa" not in elastic
    assert hardness["true_model"] == "penetration_hardness" and hardness["hardness_mpa"] == 110.0
    assert elastic["max_plastic_depth_nm"] == [0.0] * len(LOADS_MN)
    assert elastic["afm"]["max_plastic_depth_nm"] == 0.0
    # 1e-9: the load control's tolerance on the mean pressure of a capped field
    assert max(hardness["mean_pressure_mpa"]) <= 110.0 * (1 + 1e-9)
    assert max(elastic["mean_pressure_mpa"]) > 110.0
    assert all(h > e for h, e in zip(hardness["area_um2"], elastic["area_um2"], strict=True))


def test_rough_sphere_area_grows_sublinearly(rough):
    _, truth = rough
    # Contact hardening on a rough sphere: α between 2/3 (Hertz) and 1 (the κ-law of a flat
    # rough surface); the mean pressure rises with load (appendix: ~100 → 250 MPa for PS).
    assert 0.7 < truth["area_exponent"] < 1.0
    assert np.all(np.diff(truth["mean_pressure_mpa"]) > 0)
    assert 50 < truth["mean_pressure_mpa"][0] < 300


def test_truth_holds_every_true_value(glass):
    _, truth = glass
    # Static friction is τ·A exactly; the first ring gap is λ/4n = 84.32 nm.
    np.testing.assert_allclose(
        truth["static_friction_mn"], np.array(truth["area_um2"]) * 1e-12 * 30e6 * 1e3
    )
    assert truth["first_ring_gap_nm"] == pytest.approx(84.32, abs=0.01)
    assert truth["grafting_density_per_um2"] == pytest.approx(7.745e4, rel=1e-3)
    assert truth["psf_fwhm_nm"] == pytest.approx(450.0)
    assert truth["local_intensity_pressure_exponent"] == 0.5
    assert truth["flim"]["contact_ns"] == 1.3 and truth["flim"]["contact_pixels"] > 0
    assert truth["solver"]["pixel_nm"] == pytest.approx(256.0)


def test_analysis_recovers_the_hertz_exponent_and_areas(glass):
    folder, truth = glass
    areas = []
    for path in fluorescence_images(folder / "fluorescence", LOADS_MN):
        image = read_image(path)
        areas.append(otsu_contact_area(image.data, image.pixel_m).area_m2 * 1e12)
    fit = fit_power_law(np.array(LOADS_MN), np.array(areas), x_ref=25)
    # Otsu on a PSF-blurred √p profile sits slightly inside the true edge: a bias of a few %
    # that shrinks as the contact grows, so the exponent comes out a little above 2/3.
    # Tolerances: exponent within 0.015, each area within 6 % of the true area.
    assert fit.exponent.estimate == pytest.approx(2 / 3, abs=0.015)
    np.testing.assert_allclose(areas, truth["area_um2"], rtol=0.06)


def test_load_list_must_match_the_images(glass):
    folder, _ = glass
    with pytest.raises(RawDataError, match=r"no image for \[300.0\]"):
        fluorescence_images(folder / "fluorescence", [*LOADS_MN, 300.0])
    with pytest.raises(RawDataError, match=r"images not in the list: \[200.0\]"):
        fluorescence_images(folder / "fluorescence", LOADS_MN[:-1])


def test_saturating_settings_are_refused(tmp_path, repo):
    with pytest.raises(ValueError, match="lower contact_counts"):
        _generate(tmp_path, repo, sphere="PS", contact_counts=60000.0)
    assert not list(tmp_path.rglob("*.tif"))  # nothing half-written


def test_reflection_load_must_be_a_load(tmp_path, repo):
    with pytest.raises(ValueError, match="reflection load 30 mN is not one of the loads"):
        settings, newton_rings = _config(repo)
        generate_sphere(
            tmp_path,
            sphere="glass",
            diameter_m=4e-3,
            e_star_pa=32.8e9,
            roughness_rms_m=0.0,
            true_model="hardening",
            true_value=10000.0,
            loads_n=[0.025, 0.05],
            pixel_m=200e-9,
            reflection_load_n=0.03,
            flim_load_n=None,
            shear_strength_pa=30e6,
            settings=InstrumentSettings.from_config(settings, newton_rings),
            surface=SurfaceSettings.from_config(settings),
            seed=1,
        )
