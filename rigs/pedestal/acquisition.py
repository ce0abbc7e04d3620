"""Sensor path and acquisition: bracket resonance, gain, anti-alias filter, ADC, encoder.

The casing acceleration along a sensor axis (from the structure at the integration rate) passes

1. the accelerometer-on-bracket mount, a base-excited single-degree-of-freedom resonator
   ``H(s) = (2 zeta w s + w^2) / (s^2 + 2 zeta w s + w^2)`` (bilinear, pre-warped at w);
2. the per-record sensitivity: the sensor's calibration error times a random gain error;
3. an analog anti-alias Butterworth low-pass (order 8, 0.4 of the output rate), applied causally;
4. the ADC: sampled at the output rate, plus white electronic noise.

The encoder is a 512-line quadrature encoder on the pinion shaft's free end: 2048 counts per
revolution, latched at the sample instants, written as the unwrapped angle [rad].
"""
from __future__ import annotations

import numpy as np
from scipy import signal

from .params import Acquisition


def mount_filter(acc: np.ndarray, fs: float, freq: float, zeta: float) -> np.ndarray:
    w = 2 * np.pi * freq
    wp = 2 * fs * np.tan(w / (2 * fs))               # pre-warp so the resonance stays at freq
    b, a = signal.bilinear([2 * zeta * wp, wp * wp], [1.0, 2 * zeta * wp, wp * wp], fs)
    return signal.lfilter(b, a, acc)


def antialias(x: np.ndarray, fs: float, acq: Acquisition) -> np.ndarray:
    sos = signal.butter(acq.antialias_order, acq.antialias_cutoff * acq.sample_rate, fs=fs,
                        output="sos")
    return signal.sosfilt(sos, x)


def acquire_channels(acc: np.ndarray, fs_int: float, acq: Acquisition, mount_freqs,
                     mount_damping, gains, start: int, n_out: int,
                     rng: np.random.Generator) -> np.ndarray:
    """Measured accelerations (2, n_out) from casing accelerations (2, N) at ``fs_int``.

    ``start`` is the first internal sample of the record (after the pre-roll).
    """
    out = np.empty((acc.shape[0], n_out))
    step = acq.oversampling
    for s in range(acc.shape[0]):
        y = mount_filter(acc[s], fs_int, mount_freqs[s], mount_damping[s])
        y = antialias(gains[s] * y, fs_int, acq)
        y = y[start:start + step * n_out:step]
        out[s] = y + rng.normal(0.0, acq.sensor_noise, n_out)
    return out


def encoder_angle(theta: np.ndarray, start: int, n_out: int, step: int, lines: int) -> np.ndarray:
    """Quantised, unwrapped encoder angle [rad] at the output samples, starting at 0."""
    counts_per_rad = 4 * lines / (2 * np.pi)
    th = theta[start:start + step * n_out:step]
    counts = np.floor(th * counts_per_rad)
    return (counts - counts[0]) / counts_per_rad
