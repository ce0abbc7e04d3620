"""Shaft angle, angular resampling, time-synchronous averaging (TSA) and order spectra.

A gear's mesh vibration is periodic in the *shaft angle*, not in time: when the speed wanders,
its harmonics smear in an FFT over time. Resampling the signal at equal angle increments
(computed order tracking) makes it periodic in the sample index again, so that

* averaging many revolutions (TSA) keeps what is locked to the shaft and averages everything
  else (other shafts, bearings, noise) towards zero, by about ``1/sqrt(n_revs)`` for random content;
* an FFT over whole revolutions puts shaft orders on exact bins (order spectrum).

Shaft angles are in radians, unwrapped (monotonically increasing), one value per signal sample.
Angle 0 (mod 2*pi) is the shaft's reference mark: the first tacho edge, or the encoder's zero.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline, PchipInterpolator

from twin.signals._checks import SignalError, as_signal, positive, positive_int, same_length
from twin.signals.spectral import amplitude_spectrum

TWO_PI = 2.0 * np.pi


def shaft_angle_from_tacho(pulses, fs: float, pulses_per_rev: int, *, threshold: float | None = None,
                           hysteresis: float | None = None) -> np.ndarray:
    """Shaft angle at every sample from a tachometer (or once-per-rev) pulse train.

    Rising edges are found with a Schmitt trigger (a rise counts only after the signal went below
    ``threshold - hysteresis/2`` and then above ``threshold + hysteresis/2``, so noise on a slow
    edge cannot double-count), then each edge is timed to a fraction of a sample by linear
    interpolation of the crossing of ``threshold``. Edge ``k`` is at angle ``2*pi*k/pulses_per_rev``;
    between edges the angle follows a cubic spline through the edge times (smooth speed), falling
    back to a monotone PCHIP interpolant if a violent speed change made the spline non-monotonic.

    Parameters
    ----------
    pulses : (n,) array
        Tacho signal [any unit, e.g. V].
    fs : float
        Sampling rate [Hz].
    pulses_per_rev : int
        Pulses per shaft revolution (1 for a once-per-rev mark, 512 for the rig's encoders).
    threshold : float, optional
        Trigger level [unit of pulses]; default the mid-point of the 1st and 99th percentiles.
    hysteresis : float, optional
        Schmitt-trigger width [unit of pulses]; default 10 % of the 1st-99th percentile range.

    Returns
    -------
    angle : (n,) array
        Unwrapped shaft angle [rad], 0 at the first detected edge. NaN before the first and after
        the last edge, where it could only be extrapolated; :func:`angular_resample` skips those.
    """
    x = as_signal(pulses, "pulses")
    fs = positive(fs, "fs")
    ppr = positive_int(pulses_per_rev, "pulses_per_rev")
    lo_pct, hi_pct = np.percentile(x, [1.0, 99.0])
    span = hi_pct - lo_pct
    if span <= 0:
        raise SignalError("pulses is flat (no edges to detect)")
    thr = 0.5 * (lo_pct + hi_pct) if threshold is None else float(threshold)
    hyst = 0.1 * span if hysteresis is None else float(hysteresis)
    if hyst < 0:
        raise SignalError(f"hysteresis must be >= 0, got {hysteresis!r}")
    high, low = thr + 0.5 * hyst, thr - 0.5 * hyst

    # Schmitt trigger: 1 above `high`, 0 below `low`, previous state in between (forward fill).
    state = np.full(x.size, -1, dtype=np.int8)
    state[x >= high] = 1
    state[x <= low] = 0
    defined = np.flatnonzero(state >= 0)
    if defined.size == 0:
        raise SignalError(f"pulses never leaves the hysteresis band around threshold={thr:g}")
    last_defined = np.maximum.accumulate(np.where(state >= 0, np.arange(x.size), defined[0]))
    state = state[last_defined]
    rises = np.flatnonzero((state[1:] == 1) & (state[:-1] == 0)) + 1

    # Time each rise at the last upward crossing of the threshold before it was confirmed.
    crossings = np.flatnonzero((x[:-1] < thr) & (x[1:] >= thr)) + 1
    idx = crossings[np.searchsorted(crossings, rises, side="right") - 1]
    frac = (thr - x[idx - 1]) / (x[idx] - x[idx - 1])
    edge_times = (idx - 1 + frac) / fs
    if edge_times.size < 3:
        raise SignalError(f"found {edge_times.size} tacho edges at threshold={thr:g}; need at least 3")

    edge_angles = TWO_PI * np.arange(edge_times.size) / ppr
    t = np.arange(x.size) / fs
    inside = (t >= edge_times[0]) & (t <= edge_times[-1])
    angle = np.full(x.size, np.nan)
    angle[inside] = CubicSpline(edge_times, edge_angles)(t[inside])
    if np.any(np.diff(angle[inside]) <= 0):
        # A cubic spline can overshoot between sparse edges when the speed jumps; the physical
        # angle never runs backwards, and PCHIP guarantees that.
        angle[inside] = PchipInterpolator(edge_times, edge_angles)(t[inside])
    return angle


def shaft_angle_from_encoder(angle, *, period: float = TWO_PI) -> np.ndarray:
    """Unwrapped shaft angle from a wrapping angle or counter reading.

    Parameters
    ----------
    angle : (n,) array
        Encoder reading that wraps every revolution: an angle [rad] in [0, 2*pi) or (-pi, pi],
        or a counter [counts] that wraps at ``period`` (e.g. 512 for a 512-line encoder).
    period : float
        Reading per revolution [rad or counts]; 2*pi for an angle.

    Returns
    -------
    angle : (n,) array
        Unwrapped shaft angle [rad]. Assumes the shaft turns less than half a revolution between
        samples (otherwise the wrap direction is ambiguous).
    """
    a = as_signal(angle, "angle")
    period = positive(period, "period")
    return np.unwrap(a, period=period) * (TWO_PI / period)


def shaft_angle_from_speed(n: int, fs: float, speed_hz, *, phase: float = 0.0) -> np.ndarray:
    """Shaft angle when only the speed is known (nominal or measured speed profile).

    Parameters
    ----------
    n : int
        Number of samples.
    fs : float
        Sampling rate [Hz].
    speed_hz : float or (n,) array
        Shaft speed [rev/s = Hz]: a constant, or one value per sample (integrated by the
        trapezoidal rule).
    phase : float
        Angle at the first sample [rad].

    Returns
    -------
    angle : (n,) array
        Unwrapped shaft angle [rad].
    """
    n = positive_int(n, "n")
    fs = positive(fs, "fs")
    speed = np.asarray(speed_hz, dtype=float)
    if speed.ndim == 0:
        positive(speed, "speed_hz")
        return phase + TWO_PI * float(speed) * np.arange(n) / fs
    speed = as_signal(speed, "speed_hz", min_length=1)
    if speed.size != n:
        raise SignalError(f"speed_hz must be a scalar or have n={n} samples, got {speed.size}")
    if np.any(speed <= 0):
        raise SignalError(f"speed_hz must be > 0, its minimum is {speed.min():g}")
    increments = 0.5 * (speed[1:] + speed[:-1]) / fs
    return phase + TWO_PI * np.concatenate(([0.0], np.cumsum(increments)))


def angular_resample(x, fs: float, shaft_angle, samples_per_rev: int) -> tuple[np.ndarray, np.ndarray]:
    """Resample a signal at equal shaft-angle increments over whole revolutions.

    The output grid starts at the first whole revolution (angle a multiple of 2*pi) inside the
    record and stops at the last, so revolution boundaries fall on the shaft's reference mark.
    Values come from a cubic spline of ``x`` against the angle: linear interpolation would act as
    a low-pass filter and attenuate mesh harmonics that have few samples per period.

    No anti-alias filter is applied: ``samples_per_rev`` must exceed twice the highest order
    present (at the highest speed, ``fs/speed_max``-sampled content above ``samples_per_rev/2``
    orders folds back). Low-pass ``x`` first if needed.

    Parameters
    ----------
    x : (n,) array
        Signal [unit] sampled at ``fs``.
    fs : float
        Sampling rate [Hz] (used only to check consistency; the angle carries the timing).
    shaft_angle : (n,) array
        Unwrapped shaft angle [rad] at each sample, increasing; NaN allowed at the two ends only.
    samples_per_rev : int
        Angular samples per revolution.

    Returns
    -------
    revs : (m,) array
        Revolution number (angle / 2*pi) at the start of each resampled revolution.
    x_angle : (m * samples_per_rev,) array
        Signal [unit] at angles ``2*pi*(revs[0] + j/samples_per_rev)``, j = 0 ... m*spr - 1.
    """
    x = as_signal(x, "x")
    positive(fs, "fs")
    theta = as_signal(shaft_angle, "shaft_angle", allow_nan=True)
    same_length(x, theta, "x", "shaft_angle")
    spr = positive_int(samples_per_rev, "samples_per_rev")
    finite = np.flatnonzero(np.isfinite(theta))
    if finite.size < 4:
        raise SignalError("shaft_angle has fewer than 4 finite samples")
    first, last = finite[0], finite[-1]
    if finite.size != last - first + 1:
        raise SignalError("shaft_angle may contain NaN only at its start and end (gap in the middle)")
    theta, x = theta[first:last + 1], x[first:last + 1]
    step = np.diff(theta)
    if np.any(step <= 0):
        i = int(np.flatnonzero(step <= 0)[0]) + first
        raise SignalError(f"shaft_angle must increase strictly; it stalls or reverses at sample {i} "
                          "(for a shaft turning backwards pass -shaft_angle)")
    k0 = int(np.ceil(theta[0] / TWO_PI - 1e-12))
    k1 = int(np.floor(theta[-1] / TWO_PI + 1e-12))
    m = k1 - k0
    if m < 1:
        raise SignalError(f"the record covers {(theta[-1] - theta[0]) / TWO_PI:.3g} revolutions "
                          "and no whole revolution between two reference marks")
    grid = TWO_PI * (k0 + np.arange(m * spr) / spr)
    x_angle = CubicSpline(theta, x)(grid)
    return k0 + np.arange(m, dtype=float), x_angle


def synchronous_average(x, fs: float, shaft_angle, samples_per_rev: int | None = None
                        ) -> tuple[np.ndarray, np.ndarray, int]:
    """Time-synchronous average: the mean revolution of a signal, in the shaft-angle domain.

    Parameters
    ----------
    x : (n,) array
        Signal [unit] sampled at ``fs``.
    fs : float
        Sampling rate [Hz].
    shaft_angle : (n,) array
        Unwrapped shaft angle [rad] (see :func:`angular_resample`).
    samples_per_rev : int, optional
        Angular samples per revolution; default the power of two at or above the mean number of
        time samples per revolution, so the resampling never discards bandwidth.

    Returns
    -------
    theta : (samples_per_rev,) array
        Shaft angle within the revolution [rad], from 0 to 2*pi (exclusive).
    tsa : (samples_per_rev,) array
        Averaged revolution [unit]. Content locked to the shaft is kept; random content is reduced
        by ``1/sqrt(n_revs)`` in RMS, and so roughly is a tone not locked to the shaft whose phase
        drifts from one revolution to the next.
    n_revs : int
        Number of revolutions averaged.
    """
    if samples_per_rev is None:
        theta = as_signal(shaft_angle, "shaft_angle", allow_nan=True)
        ok = np.flatnonzero(np.isfinite(theta))
        if ok.size < 2:
            raise SignalError("shaft_angle has fewer than 2 finite samples")
        revs_per_sample = (theta[ok[-1]] - theta[ok[0]]) / TWO_PI / (ok[-1] - ok[0])
        if revs_per_sample <= 0:
            raise SignalError("shaft_angle does not increase over the record")
        samples_per_rev = int(2 ** np.ceil(np.log2(1.0 / revs_per_sample)))
    spr = positive_int(samples_per_rev, "samples_per_rev")
    revs, x_angle = angular_resample(x, fs, shaft_angle, spr)
    tsa = x_angle.reshape(revs.size, spr).mean(axis=0)
    return TWO_PI * np.arange(spr) / spr, tsa, int(revs.size)


def order_spectrum(x, fs: float, shaft_angle, *, samples_per_rev: int, max_order: float,
                   window: str = "hann") -> tuple[np.ndarray, np.ndarray]:
    """Amplitude spectrum against shaft order (cycles per revolution), from angular resampling.

    The angular record spans a whole number ``m`` of revolutions, so the order resolution is
    ``1/m`` and every integer order falls exactly on a bin whatever the speed variation was.

    Parameters
    ----------
    x : (n,) array
        Signal [unit] sampled at ``fs``.
    fs : float
        Sampling rate [Hz].
    shaft_angle : (n,) array
        Unwrapped shaft angle [rad] (see :func:`angular_resample`).
    samples_per_rev : int
        Angular samples per revolution; must be > 2 * max_order.
    max_order : float
        Highest order returned [cycles/rev].
    window : str
        Window name (see :func:`twin.signals.spectral.amplitude_spectrum`).

    Returns
    -------
    orders : (k,) array
        Orders [cycles/rev] from 0 to ``max_order``, spacing ``1/n_revs``.
    amplitude : (k,) array
        Peak amplitude [unit] of the component at each order (window-corrected).
    """
    spr = positive_int(samples_per_rev, "samples_per_rev")
    max_order = positive(max_order, "max_order")
    if max_order > spr / 2:
        raise SignalError(f"max_order={max_order:g} exceeds the angular Nyquist order "
                          f"samples_per_rev/2 = {spr / 2:g}")
    _, x_angle = angular_resample(x, fs, shaft_angle, spr)
    # With "sampling rate" = samples per revolution the frequency axis is in orders.
    orders, amplitude = amplitude_spectrum(x_angle, spr, window=window)
    keep = orders <= max_order * (1 + 1e-12)
    return orders[keep], amplitude[keep]
