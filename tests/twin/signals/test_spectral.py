"""Known-answer tests of the spectral estimators (Welch PSD, amplitude and padded spectra, dB)."""
from __future__ import annotations

import numpy as np
import pytest

from twin.errors import TwinError
from twin.signals import SignalError, amplitude_spectrum, padded_spectrum, spectrum_db, welch_psd

FS = 4096.0


def test_white_noise_psd_level_is_two_sigma_squared_over_fs():
    rng = np.random.default_rng(10)
    sigma = 0.7
    x = rng.normal(0.0, sigma, int(60 * FS))
    f, psd = welch_psd(x, FS, resolution=4.0)
    assert f[1] - f[0] == pytest.approx(4.0)
    interior = psd[1:-1]
    # One-sided density of white noise: sigma^2 spread over 0 ... fs/2.
    assert np.mean(interior) == pytest.approx(2 * sigma**2 / FS, rel=0.01)


def test_psd_integrates_to_the_sine_power():
    t = np.arange(int(20 * FS)) / FS
    amplitude = 3.0
    x = amplitude * np.sin(2 * np.pi * 437.3 * t)
    f, psd = welch_psd(x, FS, resolution=1.0)
    df = f[1] - f[0]
    band = np.abs(f - 437.3) < 10
    assert np.sum(psd[band]) * df == pytest.approx(amplitude**2 / 2, rel=1e-3)


def test_psd_accepts_several_channels_along_the_last_axis():
    rng = np.random.default_rng(11)
    x = rng.normal(size=(3, 8192))
    f, psd = welch_psd(x, FS, resolution=8.0)
    assert psd.shape == (3, f.size)


def test_on_bin_sine_shows_its_amplitude_with_hann():
    n = 8192
    t = np.arange(n) / FS
    f0 = 123 * FS / n  # exactly on bin 123
    x = 2.5 * np.sin(2 * np.pi * f0 * t + 0.4) + 0.3
    f, amp = amplitude_spectrum(x, FS)
    assert f[123] == pytest.approx(f0)
    assert amp[123] == pytest.approx(2.5, rel=1e-9)
    assert amp[0] == pytest.approx(0.3, rel=1e-9)


def test_half_bin_sine_shows_hann_scalloping_and_flattop_corrects_it():
    n = 8192
    t = np.arange(n) / FS
    f0 = 123.5 * FS / n  # worst case, half-way between bins
    x = 1.0 * np.cos(2 * np.pi * f0 * t)
    _, hann = amplitude_spectrum(x, FS, window="hann")
    # Hann's scalloping loss at half a bin is the known 1.42 dB (factor 0.8488).
    assert hann.max() == pytest.approx(0.8488, abs=2e-3)
    _, flat = amplitude_spectrum(x, FS, window="flattop")
    assert flat.max() == pytest.approx(1.0, abs=2e-3)


def test_spectrum_db_amplitude_and_power():
    assert spectrum_db(np.array([10.0, 1.0]))[0] == pytest.approx(20.0)
    assert spectrum_db(np.array([100.0]), quantity="power")[0] == pytest.approx(20.0)
    assert spectrum_db(np.array([2e-6]), ref=1e-6)[0] == pytest.approx(6.0206, abs=1e-4)
    assert np.isfinite(spectrum_db(np.array([0.0]))[0])


def test_bad_arguments_name_the_value():
    with pytest.raises(SignalError, match="resolution"):
        welch_psd(np.zeros(100), FS, resolution=1.0)
    with pytest.raises(SignalError, match="overlap"):
        welch_psd(np.zeros(10000), FS, resolution=8.0, overlap=1.0)
    with pytest.raises(TwinError, match="fs"):
        amplitude_spectrum(np.zeros(10), -1.0)
    with pytest.raises(ValueError, match="quantity"):
        spectrum_db(np.ones(3), quantity="energy")


def test_padded_spectrum_locates_an_off_bin_line_and_reads_its_amplitude():
    # 0.5 s record: bins 2 Hz apart; a line 0.37 bin off and a second 1 Hz away (half a bin)
    t = np.arange(int(0.5 * FS)) / FS
    x = 2.0 + 0.8 * np.sin(2 * np.pi * 100.74 * t) + 0.3 * np.sin(2 * np.pi * 301.0 * t)
    f, amp = padded_spectrum(x, FS)
    assert f[1] - f[0] <= 2.0 / 8
    j = int(np.argmax(amp))
    assert f[j] == pytest.approx(100.74, abs=0.3 * FS / t.size)
    assert amp[j] == pytest.approx(0.8, rel=0.01)      # scalloping below 0.03 dB with 8x padding
    assert amp[np.argmin(np.abs(f - 301.0))] == pytest.approx(0.3, rel=0.02)
    assert amp[0] < 0.05                               # the mean (2.0) is removed


@pytest.mark.parametrize("x, kw, needle", [
    (np.ones((2, 8)), {}, "shape (2, 8)"),
    (np.array([0.0, np.nan, 1.0]), {}, "NaN"),
    (np.arange(8.0), {"pad": 0}, "pad must be at least 1, got 0"),
])
def test_padded_spectrum_refuses_bad_input_by_name(x, kw, needle):
    with pytest.raises(SignalError, match=needle.replace("(", r"\(").replace(")", r"\)")):
        padded_spectrum(x, FS, **kw)
