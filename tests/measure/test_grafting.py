"""Grafting density from the absorbance spectrum (appendix Fig. B.1, docs/models.md §1.1)."""

import numpy as np
import pytest

from amontons.io.absorbance import AbsorbanceError, read_absorbance_csv, write_absorbance_csv
from amontons.measure.grafting import grafting_density
from amontons.virtual.absorbance import absorbance_spectrum

WAVELENGTHS_NM = np.arange(400.0, 600.01, 0.5)  # a 0.5 nm-step scan, 401 points
TRUE_DENSITY_PER_UM2 = 7.745e4  # see test_appendix_arithmetic


def test_appendix_arithmetic():
    # Noise-free band of peak 0.0016: Γ = 0.0016 / (6220 m²/mol · 2) · 6.022e23 /mol
    # = 1.286e-7 mol/m² · 6.022e23 = 7.745e16 m⁻² = 7.745e4 µm⁻². With LOWESS over a noise-free
    # 60 nm band the smoothed peak is within 0.5 % of 0.0016, so 1 % must hold.
    band = absorbance_spectrum(WAVELENGTHS_NM, noise_sd=0.0, rng=np.random.default_rng(0))
    result = grafting_density(WAVELENGTHS_NM, band)
    assert result.density_per_um2 == pytest.approx(TRUE_DENSITY_PER_UM2, rel=0.01)
    assert result.peak_wavelength_nm == pytest.approx(488.0, abs=0.5)
    # One face only doubles it: the appendix's ~80 000 µm⁻² needs n_faces = 2.
    single = grafting_density(WAVELENGTHS_NM, band, n_faces=1)
    assert single.density_per_um2 == pytest.approx(2 * result.density_per_um2)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_noisy_spectrum_recovers_density_within_5_percent(seed):
    # Noise sd 1e-4 (6 % of the peak): over 100 seeds the smoothed maximum scatters by 1.3 %
    # with a bias < 0.5 %, so 5 % is a ~4 σ bound; a frac of 0.2 (−5 % flattening) breaks it.
    rng = np.random.default_rng(seed)
    spectrum = absorbance_spectrum(WAVELENGTHS_NM, noise_sd=1e-4, rng=rng)
    result = grafting_density(WAVELENGTHS_NM, spectrum)
    assert result.density_per_um2 == pytest.approx(TRUE_DENSITY_PER_UM2, rel=0.05)
    assert result.peak_wavelength_nm == pytest.approx(488.0, abs=6.0)
    assert result.noise_sd == pytest.approx(1e-4, rel=0.15)


def test_flat_spectrum_has_no_band():
    flat = absorbance_spectrum(WAVELENGTHS_NM, peak_absorbance=0.0, rng=np.random.default_rng(4))
    with pytest.raises(AbsorbanceError, match="no absorption band"):
        grafting_density(WAVELENGTHS_NM, flat)


def test_negative_band_is_refused():
    dip = absorbance_spectrum(WAVELENGTHS_NM, peak_absorbance=-0.0016, rng=np.random.default_rng(5))
    with pytest.raises(AbsorbanceError, match="no absorption band"):
        grafting_density(WAVELENGTHS_NM, dip)


def test_maximum_at_the_range_end_is_refused():
    slope = 1e-5 * (WAVELENGTHS_NM - 400.0)  # a rising baseline reaching 0.002, no band
    with pytest.raises(AbsorbanceError, match="end of the range"):
        grafting_density(WAVELENGTHS_NM, slope)


def test_csv_round_trip(tmp_path):
    spectrum = absorbance_spectrum(WAVELENGTHS_NM, rng=np.random.default_rng(6))
    path = tmp_path / "absorbance.csv"
    write_absorbance_csv(path, WAVELENGTHS_NM, spectrum)
    wavelength, absorbance = read_absorbance_csv(path)
    np.testing.assert_allclose(wavelength, WAVELENGTHS_NM)
    np.testing.assert_allclose(absorbance, spectrum, rtol=1e-6, atol=1e-12)


def test_csv_missing_column_names_file_and_column(tmp_path):
    path = tmp_path / "absorbance.csv"
    path.write_text("wavelength_nm,A\n" + "".join(f"{400 + i},0.001\n" for i in range(20)))
    with pytest.raises(AbsorbanceError, match=r"absorbance\.csv: no column 'absorbance'"):
        read_absorbance_csv(path)
