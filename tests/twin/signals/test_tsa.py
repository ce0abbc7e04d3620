"""Known-answer tests of shaft-angle recovery, time-synchronous averaging and order spectra.

The shaft of the paper's rig (input, 20 Hz) is given a +-5 % sinusoidal speed fluctuation, so
anything locked to the shaft smears in time-domain spectra and only angle-domain processing
recovers it.
"""
from __future__ import annotations

import numpy as np
import pytest

from twin.signals import (SignalError, amplitude_spectrum, angular_resample, order_spectrum, shaft_angle_from_encoder,
                          shaft_angle_from_speed, shaft_angle_from_tacho, synchronous_average)

FS = 5120.0
DURATION = 10.0
SHAFT_HZ = 20.0
N = int(FS * DURATION)
T = np.arange(N) / FS
SPEED = SHAFT_HZ * (1.0 + 0.05 * np.sin(2 * np.pi * 0.7 * T))  # +-5 %, 0.7 Hz
THETA = shaft_angle_from_speed(N, FS, SPEED, phase=0.3)
SPR = 256


def locked_waveform(theta):
    """A revolution-periodic 'gear' signal: mesh order 19 and its harmonic, 1x, one damaged tooth."""
    within = np.mod(theta, 2 * np.pi)
    return (np.cos(19 * theta) + 0.4 * np.cos(38 * theta + 0.3) + 0.3 * np.cos(theta)
            + 1.5 * np.exp(-0.5 * ((within - 2.0) / 0.05) ** 2))


def test_speed_integration_matches_the_analytic_angle():
    exact = 0.3 + 2 * np.pi * SHAFT_HZ * (T - 0.05 / (2 * np.pi * 0.7) * (np.cos(2 * np.pi * 0.7 * T) - 1))
    assert np.max(np.abs(THETA - exact)) < 1e-6
    constant = shaft_angle_from_speed(100, FS, 20.0)
    assert constant[10] == pytest.approx(2 * np.pi * 20 * 10 / FS)


def test_tsa_recovers_the_locked_waveform_despite_speed_fluctuation():
    rng = np.random.default_rng(20)
    x = locked_waveform(THETA) + np.cos(2 * np.pi * 263.7 * T) + rng.normal(0.0, 1.0, N)
    theta, tsa, n_revs = synchronous_average(x, FS, THETA, samples_per_rev=SPR)
    assert theta.shape == tsa.shape == (SPR,)
    assert n_revs == 199
    assert np.corrcoef(tsa, locked_waveform(theta))[0, 1] > 0.99  # measured 0.9967


def test_tsa_suppresses_what_is_not_locked_to_the_shaft():
    rng = np.random.default_rng(21)
    noise = rng.normal(0.0, 1.0, N)
    _, tsa_noise, n_revs = synchronous_average(noise, FS, THETA, samples_per_rev=SPR)
    # Random content: RMS reduced by 1/sqrt(n_revs) (measured 0.067 vs 1/sqrt(199) = 0.071).
    assert np.std(tsa_noise) == pytest.approx(1 / np.sqrt(n_revs), rel=0.2)
    tone = np.cos(2 * np.pi * 263.7 * T)
    _, tsa_tone, _ = synchronous_average(tone, FS, THETA, samples_per_rev=SPR)
    # A tone whose phase drifts against the shaft is reduced at least as much (measured 0.005).
    assert np.sqrt(np.mean(tsa_tone**2)) / np.sqrt(0.5) < 1 / np.sqrt(n_revs)


def test_default_samples_per_rev_is_a_power_of_two_above_the_time_sampling():
    theta, _, _ = synchronous_average(locked_waveform(THETA), FS, THETA)
    assert theta.size == 256  # 5120 Hz / 20 Hz = 256 samples per revolution


def test_tacho_edges_give_the_angle_to_a_fraction_of_a_sample():
    for pulses_per_rev in (1, 4):
        # Rounded pulses with finite rise time; rising edges at shaft angle 2*pi*k/ppr.
        tacho = np.tanh(3 * np.sin(pulses_per_rev * THETA))
        angle = shaft_angle_from_tacho(tacho, FS, pulses_per_rev)
        ok = np.isfinite(angle)
        first_edge = 2 * np.pi * np.ceil(THETA[0] * pulses_per_rev / (2 * np.pi)) / pulses_per_rev
        error = angle[ok] - (THETA[ok] - first_edge)
        # One sample is 2*pi*20/5120 = 0.025 rad; measured max error 1.0e-4 rad.
        assert np.max(np.abs(error)) < 5e-4
        assert np.isnan(angle[0]) and np.isnan(angle[-1])


def test_tsa_from_a_noisy_tacho_still_recovers_the_waveform():
    rng = np.random.default_rng(22)
    tacho = np.tanh(3 * np.sin(THETA)) + 0.05 * rng.normal(size=N)
    angle = shaft_angle_from_tacho(tacho, FS, 1)
    x = locked_waveform(THETA) + rng.normal(0.0, 1.0, N)
    theta, tsa, _ = synchronous_average(x, FS, angle, samples_per_rev=SPR)
    # The tacho's angle 0 is the first edge, i.e. shaft angle 2*pi*k: same phase reference.
    assert np.corrcoef(tsa, locked_waveform(theta))[0, 1] > 0.99  # measured 0.995


def test_hysteresis_ignores_noise_chatter_on_the_edges():
    rng = np.random.default_rng(23)
    # Slow edges (about 13 samples from -1 to 1) with noise: a bare comparator sees several
    # threshold crossings per edge.
    tacho = np.clip(3 * np.sin(THETA), -1, 1) + 0.05 * rng.normal(size=N)
    first_edge = 2 * np.pi * np.ceil(THETA[0] / (2 * np.pi))

    def worst_error(**kw):
        angle = shaft_angle_from_tacho(tacho, FS, 1, **kw)
        ok = np.isfinite(angle)
        return np.max(np.abs(angle[ok] - (THETA[ok] - first_edge)))

    assert worst_error() < 0.1  # default hysteresis: one edge per pulse (measured 0.041 rad)
    assert worst_error(hysteresis=0.0) > 1.0  # chatter counted as extra pulses


def test_encoder_angle_is_unwrapped():
    wrapped = np.angle(np.exp(1j * THETA))  # (-pi, pi]
    angle = shaft_angle_from_encoder(wrapped)
    assert np.max(np.abs(angle - (THETA - THETA[0] + wrapped[0]))) < 1e-9
    counts = np.mod(THETA / (2 * np.pi) * 512, 512)  # 512-line counter, as on the rig
    angle = shaft_angle_from_encoder(counts, period=512)
    assert np.max(np.abs(np.diff(angle) - np.diff(THETA))) < 1e-9


def test_order_19_lands_exactly_on_order_19():
    x = 0.8 * np.cos(19 * THETA + 0.4) + 0.2 * np.cos(2 * np.pi * 263.7 * T)
    orders, amplitude = order_spectrum(x, FS, THETA, samples_per_rev=SPR, max_order=60)
    peak = np.argmax(amplitude)
    assert orders[peak] == pytest.approx(19.0, abs=1e-12)
    assert amplitude[peak] == pytest.approx(0.8, rel=1e-3)  # measured 0.79994
    assert orders[-1] <= 60
    # In time the same component is smeared over +-19 Hz and its line collapses.
    _, time_amplitude = amplitude_spectrum(x, FS)
    f = np.fft.rfftfreq(N, 1 / FS)
    assert time_amplitude[np.abs(f - 380) < 25].max() < 0.3


def test_angular_resample_covers_whole_revolutions_from_the_reference_mark():
    x = np.cos(THETA)
    revs, x_angle = angular_resample(x, FS, THETA, SPR)
    assert x_angle.size == revs.size * SPR
    assert revs[0] == 1.0  # THETA starts at 0.3 rad, so the first mark is revolution 1
    grid = 2 * np.pi * (revs[0] + np.arange(x_angle.size) / SPR)
    assert np.max(np.abs(x_angle - np.cos(grid))) < 1e-5


def test_errors_name_the_bad_input():
    with pytest.raises(SignalError, match="increase"):
        angular_resample(np.zeros(N), FS, -THETA, SPR)
    with pytest.raises(SignalError, match="max_order"):
        order_spectrum(np.zeros(N), FS, THETA, samples_per_rev=64, max_order=40)
    with pytest.raises(SignalError, match="pulses_per_rev"):
        shaft_angle_from_tacho(np.sin(THETA), FS, 0)
    with pytest.raises(SignalError, match="speed_hz"):
        shaft_angle_from_speed(N, FS, -SPEED)
    with pytest.raises(SignalError, match="whole revolution"):
        angular_resample(np.zeros(100), FS, np.linspace(0.1, 1.0, 100), SPR)
