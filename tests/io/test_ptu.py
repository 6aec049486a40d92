"""FLIM from PicoQuant PTU files (T3 image mode): files with known mono-exponential lifetimes
in and outside a contact disc, written by ptufile's writer, read back to the photon counts and
mean arrival times; the time origin fitted to the image's decay; and every kind of bad file
refused with the project's error naming the file.

The Poisson standard error of a pixel's mean arrival time is sqrt(τ² + σ²)/sqrt(N): the
arrival time after the instrument response's peak is a Gaussian jitter (sd σ) plus an
exponential delay (sd τ), and the mean of N photons has 1/N of their variance. Over a region
of M pixels, the mean of the pixel means has sqrt(Σ_i (τ² + σ²)/N_i)/M.
"""

import numpy as np
import ptufile
import pytest
from ptufile.ptufile import encode_tag

from amontons.io.layout import RawDataError, flim_file
from amontons.io.ptu import PtuError, read_ptu_image, write_ptu_image
from amontons.io.tiff import write_image
from amontons.measure.area import OtsuSettings
from amontons.measure.lifetime import exgaussian_cdf, fit_time_origin, measure_lifetime, sides
from amontons.physics.gaussian import FWHM_PER_SIGMA
from amontons.virtual.flim import TcspcSettings, photon_histograms

PIXEL = 200e-9
SIDE, DISC_RADIUS_PX = 32, 9
CONTACT_NS, OUTSIDE_NS = 1.3, 0.5  # appendix Fig. B.3 inside; the virtual experiment's outside
# A MicroTime 200 with a PicoHarp: 40 MHz laser, 16 ps bins, a 200 ps instrument response
TCSPC = dict(irf_fwhm_s=200e-12, irf_peak_s=2e-9, bin_s=16e-12, sync_period_s=25e-9)
SIGMA_NS = 0.2 / FWHM_PER_SIGMA  # the response's sd
# 4 standard errors: this file compares ~20 estimates with their truth; at 4 SE an unbiased
# estimate falls outside with 6e-5 chance each (at 3 SE, one file in 20 would fail by chance),
# while half a TCSPC bin of bias (8 ps) is ≥ 9 SE on either side at 10,000 photons
BOUND_SE = 4.0


def _disc():
    rows, cols = np.indices((SIDE, SIDE))
    return np.hypot(rows - (SIDE - 1) / 2, cols - (SIDE - 1) / 2) <= DISC_RADIUS_PX


def _write(path, photons_per_pixel, seed, **changes):
    tcspc = TcspcSettings(photons_per_pixel=photons_per_pixel, **{**TCSPC, **changes})
    lifetime_s = np.where(_disc(), CONTACT_NS, OUTSIDE_NS) * 1e-9
    histograms = photon_histograms(lifetime_s, tcspc, rng=np.random.default_rng(seed))
    write_ptu_image(
        path, histograms, bin_s=tcspc.bin_s, sync_period_s=tcspc.sync_period_s, pixel_m=PIXEL
    )
    return histograms


def _region_se(photons, region, tau_ns):
    return np.sqrt(np.sum((tau_ns**2 + SIGMA_NS**2) / photons[region])) / region.sum()


@pytest.mark.parametrize("photons_per_pixel", [100, 1000, 10000])
def test_mean_arrival_times_lie_within_the_poisson_standard_error(tmp_path, photons_per_pixel):
    path = tmp_path / "flim.ptu"
    histograms = _write(path, photons_per_pixel, seed=photons_per_pixel)
    image = read_ptu_image(path)
    np.testing.assert_array_equal(image.photons, histograms.sum(axis=-1))
    assert image.pixel_m == pytest.approx(PIXEL, rel=1e-12)
    assert image.bin_ns == pytest.approx(0.016) and image.period_ns == pytest.approx(25.0)
    origin = fit_time_origin(image.decay, image.bin_ns, image.period_ns)
    assert abs(origin.after_sync_ns - 2.0) <= BOUND_SE * origin.standard_error_ns
    disc = _disc()
    for region, tau in ((disc, CONTACT_NS), (~disc, OUTSIDE_NS)):
        arrival = image.mean_after_sync_ns[region] - origin.after_sync_ns
        se = _region_se(image.photons, region, tau)
        assert abs(arrival.mean() - tau) <= BOUND_SE * np.hypot(se, origin.standard_error_ns)
        # each pixel scatters by its own Poisson error, no more: the sd of the standardised
        # pixel errors is 1 within 0.15 (3 sd of an sd estimated from ≥ 250 pixels)
        pixel_se = np.sqrt((tau**2 + SIGMA_NS**2) / image.photons[region])
        z = (image.mean_after_sync_ns[region] - 2.0 - tau) / pixel_se
        assert z.std() == pytest.approx(1.0, abs=0.15)


@pytest.mark.parametrize(
    ("fwhm_ps", "peak_ns", "tau_ns", "background_per_bin"),
    [
        (100.0, 2.0, 2.5, 0.0),  # a narrow response and a long lifetime
        (400.0, 5.0, 0.5, 0.0),  # a wide response against a short lifetime
        (200.0, 0.3, 1.3, 0.0),  # the response's left tail folds into the period's end
        (200.0, 2.0, 1.3, 50.0),  # dark counts: a flat background
    ],
)
def test_the_time_origin_fit_finds_the_instrument_response_peak(
    fwhm_ps, peak_ns, tau_ns, background_per_bin
):
    # 2e6 photons, drawn as photons (not from the fit's own model), folded into 25 ns
    rng = np.random.default_rng(int(fwhm_ps + 10 * tau_ns))
    sigma = fwhm_ps * 1e-3 / FWHM_PER_SIGMA
    n = 2_000_000
    arrival = np.mod(peak_ns + rng.normal(0, sigma, n) + rng.exponential(tau_ns, n), 25.0)
    bins = int(np.ceil(25.0 / 0.016))
    decay = np.bincount((arrival / 0.016).astype(int), minlength=bins)[:bins]
    decay = decay + rng.poisson(background_per_bin, bins)
    origin = fit_time_origin(decay, 0.016, 25.0)
    assert abs(origin.after_sync_ns - peak_ns) <= BOUND_SE * origin.standard_error_ns
    # the standard error is that of a fit on 2e6 photons: well below a bin
    assert 0 < origin.standard_error_ns < 0.005
    assert origin.irf_fwhm_ns == pytest.approx(fwhm_ps * 1e-3, rel=0.05)


def test_exgaussian_cdf_is_the_distribution_of_the_photons():
    # Against 1e6 drawn photons: the CDF at five times within the Kolmogorov bound 2/sqrt(n)
    rng = np.random.default_rng(5)
    t = 2.0 + rng.normal(0, 0.085, 1_000_000) + rng.exponential(1.3, 1_000_000)
    for at in (1.9, 2.0, 2.5, 4.0, 8.0):
        assert exgaussian_cdf(at, 2.0, 0.085, 1.3) == pytest.approx(np.mean(t <= at), abs=2e-3)


def _otsu():
    return OtsuSettings(bins=256, min_separation=0.5, min_contrast=5.0, min_patch_px=4)


def test_lifetime_json_comes_from_the_photons_with_their_counts(tmp_path):
    path = tmp_path / "flim.ptu"
    histograms = _write(path, 1000, seed=7)
    stats = measure_lifetime(path, None, otsu=_otsu(), exclude_edge_px=1)
    photons = histograms.sum(axis=-1)
    # at 1000 photons the contact stands 20 noise sd out: Otsu finds the disc itself, and the
    # sides are the disc and the rest, each less the 1 px band at the edge
    inside, outside = sides(_disc(), 1)
    assert stats.inside_n == inside.sum() and stats.outside_n == outside.sum()
    for mean, tau, region in (
        (stats.inside_mean_ns, CONTACT_NS, inside),
        (stats.outside_mean_ns, OUTSIDE_NS, outside),
    ):
        bound = np.hypot(_region_se(photons, region, tau), stats.time_origin.standard_error_ns)
        assert abs(mean - tau) <= BOUND_SE * bound
    record = stats.to_record(1)
    assert record["photons"]["inside"]["total"] == int(photons[inside].sum())
    assert record["photons"]["outside"]["total"] == int(photons[outside].sum())
    assert record["photons"]["outside"]["per_pixel_min"] == int(photons[outside].min())
    assert record["time_origin"]["after_sync_ns"] == pytest.approx(2.0, abs=0.01)
    assert record["time_origin"]["method"].startswith("fitted")


def test_a_given_instrument_response_peak_is_the_origin(tmp_path):
    path = tmp_path / "flim.ptu"
    _write(path, 1000, seed=8)
    fitted = measure_lifetime(path, None, otsu=_otsu(), exclude_edge_px=0)
    given = measure_lifetime(path, None, otsu=_otsu(), exclude_edge_px=0, irf_peak_ns=2.0)
    assert given.time_origin.standard_error_ns == 0.0
    shift = fitted.time_origin.after_sync_ns - 2.0
    assert given.inside_mean_ns - fitted.inside_mean_ns == pytest.approx(shift, abs=1e-12)
    with pytest.raises(RawDataError, match="within the 25 ns laser period"):
        measure_lifetime(path, None, otsu=_otsu(), exclude_edge_px=0, irf_peak_ns=30.0)


def test_the_ptu_map_and_the_same_map_as_tiff_give_the_same_lifetimes(tmp_path):
    # The same data through both routes: the PTU's arrival-time map saved as a float TIFF
    # (what FLIM software exports) gives the same statistics to the last bit.
    path = tmp_path / "flim.ptu"
    _write(path, 1000, seed=9)
    from_ptu = measure_lifetime(path, None, otsu=_otsu(), exclude_edge_px=2, irf_peak_ns=2.0)
    image = read_ptu_image(path)
    write_image(tmp_path / "flim.tif", image.mean_after_sync_ns - 2.0, PIXEL)
    from_tif = measure_lifetime(tmp_path / "flim.tif", None, otsu=_otsu(), exclude_edge_px=2)
    assert from_tif.to_record(2) == {
        k: v for k, v in from_ptu.to_record(2).items() if k not in ("photons", "time_origin")
    }


def test_pixel_size_from_the_header_else_the_sheet(tmp_path):
    path = tmp_path / "flim.ptu"
    _write(path, 100, seed=1)
    assert read_ptu_image(path, 180e-9).pixel_m == pytest.approx(PIXEL, rel=1e-12)
    histograms = np.ones((4, 4, 8), np.uint16)
    bare = tmp_path / "bare.ptu"  # a header whose pixel size is 0: none given
    ptufile.imwrite(bare, histograms, 25e-9, 16e-12, tags={"ImgHdr_PixResol": 0.0})
    assert read_ptu_image(bare, 180e-9).pixel_m == pytest.approx(180e-9)
    with pytest.raises(PtuError, match="no pixel size"):
        read_ptu_image(bare)


def test_one_detector_channel_or_all(tmp_path):
    histograms = np.zeros((4, 5, 2, 64), np.uint16)
    histograms[:, :, 0, 10] = 7
    histograms[:, :, 1, 20] = 3
    path = tmp_path / "two.ptu"
    ptufile.imwrite(path, histograms, 25e-9, 25e-9 / 64, pixel_resolution=0.2)
    assert read_ptu_image(path).photons.sum() == 20 * 10
    assert read_ptu_image(path, channel=1).photons.sum() == 20 * 3
    with pytest.raises(PtuError, match=r"channel 2 recorded no photon.*\[0, 1\]"):
        read_ptu_image(path, channel=2)


# --- files that are not a T3 FLIM image --------------------------------------------------------


def _tagged_file(path, tags, records):
    """A PTU as PicoQuant's software lays it out: magic, version, tags, then the records."""
    header = [b"PQTTTR\x00\x001.0.00\x00\x00"]
    header += [encode_tag(key, value) for key, value in tags.items()]
    header.append(encode_tag("Header_End", None))
    path.write_bytes(b"".join(header) + np.asarray(records, np.uint32).tobytes())


def t2_mode(path):
    # A PicoHarp T2 measurement: time tags of the photons, no sync, no TCSPC bin, no pixels.
    tags = {
        "File_GUID": "{5c5a39b4-57c0-4c3e-8a8e-34b2e37bbb0e}",
        "Measurement_Mode": 2,
        "Measurement_SubMode": 0,
        "MeasDesc_GlobalResolution": 4e-12,
        "MeasDesc_Resolution": 4e-12,
        "TTResult_NumberOfRecords": 100,
        "TTResult_SyncRate": 40_000_000,
        "TTResultFormat_TTTRRecType": int(ptufile.PtuRecordType.PicoHarpT2),
        "TTResultFormat_BitsPerRecord": 32,
    }
    _tagged_file(path, tags, np.arange(100) * 1000)


def t3_point(path):
    # A T3 point measurement (a decay at one spot): TCSPC bins but no line or frame markers.
    tags = {
        "File_GUID": "{5c5a39b4-57c0-4c3e-8a8e-34b2e37bbb0f}",
        "Measurement_Mode": 3,
        "Measurement_SubMode": 0,
        "MeasDesc_GlobalResolution": 25e-9,
        "MeasDesc_Resolution": 16e-12,
        "TTResult_NumberOfRecords": 100,
        "TTResult_SyncRate": 40_000_000,
        "TTResultFormat_TTTRRecType": int(ptufile.PtuRecordType.PicoHarpT3),
        "TTResultFormat_BitsPerRecord": 32,
    }
    # PicoHarp T3: channel 1 (bits 28-31), dtime (16-27), sync count (0-15)
    _tagged_file(path, tags, (1 << 28) | (100 << 16) | np.arange(100))


def truncated_records(path):
    _write(path, 100, seed=2)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) - 4000])


def truncated_header(path):
    _write(path, 100, seed=2)
    path.write_bytes(path.read_bytes()[:700])


def not_a_ptu(path):
    write_image(path, np.ones((8, 8), np.uint16), PIXEL)


def no_photons(path):
    write_ptu_image(
        path, np.zeros((8, 8, 64), np.uint16), bin_s=16e-12, sync_period_s=25e-9, pixel_m=PIXEL
    )


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (t2_mode, "measurement mode T2.*expected a T3 image-mode"),
        (t3_point, "sub-mode 0.*not an image"),
        (truncated_records, "truncated: .* of the .* photon records"),
        (truncated_header, "not a readable PicoQuant PTU"),
        (not_a_ptu, "not a readable PicoQuant PTU"),
        (no_photons, "holds no photon"),
    ],
    ids=["t2-mode", "t3-point", "truncated-records", "truncated-header", "tiff", "no-photons"],
)
def test_bad_ptu_files_are_refused_naming_the_file(tmp_path, make, message):
    path = tmp_path / "flim.ptu"
    make(path)
    with pytest.raises(PtuError, match=message) as error:
        read_ptu_image(path, PIXEL)
    assert str(path) in str(error.value)


def test_a_pixel_without_photons_has_no_arrival_time(tmp_path):
    histograms = np.zeros((16, 16, 64), np.uint16)
    histograms[:, :, 20] = 50
    histograms[3, 4] = 0
    path = tmp_path / "flim.ptu"
    write_ptu_image(path, histograms, bin_s=16e-12, sync_period_s=25e-9, pixel_m=PIXEL)
    with pytest.raises(RawDataError, match=r"flim.ptu: 1 pixels hold no photon"):
        measure_lifetime(path, None, otsu=_otsu(), exclude_edge_px=0, irf_peak_ns=0.1)


def test_a_sphere_has_one_flim_file_of_either_format(tmp_path):
    assert flim_file(tmp_path) is None
    (tmp_path / "flim.ptu").write_bytes(b"")
    assert flim_file(tmp_path) == tmp_path / "flim.ptu"
    (tmp_path / "flim.tif").write_bytes(b"")
    with pytest.raises(RawDataError, match="both flim.tif and flim.ptu"):
        flim_file(tmp_path)
