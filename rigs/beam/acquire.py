"""Acquisition chain: accelerometer mount, IEPE coupling, anti-alias decimation, noise, gain
error, 16-bit quantisation at an auto-selected range; encoder by edge time-stamping; the
impact hammer's load cell through the same converter."""
from __future__ import annotations

import numpy as np
from scipy import signal


def _base_excited(freq, zeta, fs):
    """Second-order sensor/bracket response to base acceleration (bilinear, pre-warped)."""
    w = 2 * np.pi * freq
    wp = 2 * fs * np.tan(w / (2 * fs))
    b, a = signal.bilinear([2 * zeta * wp, wp * wp], [1, 2 * zeta * wp, wp * wp], fs)
    return b, a


def accelerometer(x, fs_in, fs_out, sensors, rng, gain, bracket=None):
    """Acceleration along the sensor axis [m/s2] at fs_in -> measured samples at fs_out.

    Returns (samples, range_used [m/s2]).
    """
    y = signal.lfilter(*_base_excited(sensors.mount_frequency, sensors.mount_damping, fs_in), x)
    if bracket is not None:
        y = signal.lfilter(*_base_excited(bracket[0], bracket[1], fs_in), y)
    sos = signal.butter(2, sensors.highpass, btype="highpass", fs=fs_in, output="sos")
    y = signal.sosfilt(sos, y)
    y = decimate(y, fs_in, fs_out)
    y = y * gain + rng.normal(0.0, sensors.noise, y.size)
    return quantise(y, sensors.ranges, sensors.bits)


def quantise(y, ranges, bits):
    """Quantisation at the smallest range that holds the record with 25 % headroom.
    Returns (samples, range_used)."""
    peak = np.max(np.abs(y)) * 1.25
    rng_used = next((r for r in ranges if r >= peak), ranges[-1])
    lsb = 2 * rng_used / 2**bits
    yq = np.clip(np.round(y / lsb), -(2 ** (bits - 1)), 2 ** (bits - 1) - 1) * lsb
    return yq, rng_used


def decimate(y, fs_in, fs_out):
    """The converter's delta-sigma style linear-phase decimation filter, flat to 0.45 fs_out,
    delay removed; the same for every analogue channel."""
    factor = int(round(fs_in / fs_out))
    if factor > 1:
        n_taps, beta = signal.kaiserord(100.0, (0.55 - 0.45) * fs_out / (fs_in / 2))
        taps = signal.firwin(n_taps | 1, 0.5 * fs_out, window=("kaiser", beta), fs=fs_in)
        d = (taps.size - 1) // 2
        y = signal.fftconvolve(np.concatenate([y, np.full(d, y[-1])]), taps, mode="full")[d:d + y.size]
        y = y[::factor]
    return y


def load_cell(force, fs_in, fs_out, hammer, rng):
    """Hammer force [N] at fs_in -> the load cell's samples at fs_out.

    Quartz load cell (its resonance far above the band, DC-coupled over a record: the
    discharge time constant of a hammer is thousands of seconds), the same decimation filter
    as the accelerometers, a sensitivity error drawn per record, noise, 16-bit quantisation
    at the smallest range that holds the record. Returns (samples, gain, range_used [N]).
    """
    gain = 1.0 + float(rng.normal(0.0, hammer.gain_error))
    y = decimate(force, fs_in, fs_out) * gain
    y = y + rng.normal(0.0, hammer.noise, y.size)
    yq, rng_used = quantise(y, hammer.ranges, hammer.bits)
    return yq, gain, rng_used


def encoder(angle, fs_in, fs_out, n_out, lines, line_error):
    """Unwrapped shaft angle from a quadrature encoder read by edge time-stamping.

    angle: true shaft angle at fs_in [rad]; line_error: (lines,) placement errors [rad].
    Edges (4 per line) are located in time by interpolation of the true angle (80 MHz
    timer), the output angle is interpolated between the nominal angles of the edges.
    """
    t = np.arange(angle.size) / fs_in
    mono = np.maximum.accumulate(angle)
    step = 2 * np.pi / (4 * lines)
    k = np.arange(np.ceil(mono[0] / step), np.floor(mono[-1] / step) + 1).astype(np.int64)
    true_edges = k * step + line_error[(k // 4) % lines]
    times = np.round(np.interp(true_edges, mono, t) * 80e6) / 80e6
    nominal = k * step
    t_out = np.arange(n_out) / fs_out
    out = np.interp(t_out, times, nominal)
    # beyond the first/last edge: extrapolate with the edge rate at that end
    for sel, (i0, i1) in ((t_out < times[0], (0, min(8, times.size - 1))),
                          (t_out > times[-1], (max(times.size - 9, 0), times.size - 1))):
        if sel.any() and i1 > i0:
            rate = (nominal[i1] - nominal[i0]) / (times[i1] - times[i0])
            ref = i0 if sel is not None and t_out[sel][0] < times[0] else i1
            out[sel] = nominal[ref] + rate * (t_out[sel] - times[ref])
    return out - 2 * np.pi * np.floor(out[0] / (2 * np.pi))
