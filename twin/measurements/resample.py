"""Resampling a record to another sampling rate, visibly.

Vibration channels go through :func:`scipy.signal.resample_poly` with the rate ratio
approximated by a fraction ``up/down`` (both <= :data:`MAX_FACTOR`) and an anti-aliasing
low-pass at the lower of the two Nyquist frequencies, so downsampling does not alias. The
filter is longer than scipy's default (``40 max(up, down) + 1`` taps, Kaiser beta 8 instead
of ``20 max(up, down) + 1`` taps, beta 5): its pass band is flat to 1e-4 up to 80 % of that
Nyquist frequency (the default ripples by 5e-4 already at 4 %, enough to bias amplitude
features) and it attenuates by more than 80 dB from 120 %. The signal is padded with its
own linear trend (``padtype='line'``) so a DC offset does not ring at the record's ends the
way zero padding would; the first and last ``20 max(up, down) / up`` output samples still
carry the filter's edge transient.

The tachometer channel is not filtered: a pulse train would ring around every edge and an
encoder angle is a ramp. Pulses are carried by sample-and-hold (edges move by less than one
original sample period) and the angle by linear interpolation (extrapolated linearly past
the last sample).

Every resampled record carries its original rate in ``Record.resampled_from`` and the
function returns a note saying what was done; nothing is resampled silently.
"""
from __future__ import annotations

import dataclasses
import functools
import math
from fractions import Fraction

import numpy as np
from scipy.signal import firwin, resample_poly

from twin.errors import MeasurementError
from twin.measurements.record import Record

MAX_FACTOR = 1000          # bound on up and down; the FIR has 40 * max(up, down) + 1 taps
RATE_RTOL = 1e-6           # accepted relative error of the achieved rate
FILTER_HALF_LENGTH = 20    # taps per side, per unit of max(up, down)
KAISER_BETA = 8.0


def anti_aliasing_filter(up: int, down: int) -> np.ndarray:
    """Low-pass FIR for ``resample_poly(x, up, down, window=...)``, shape ``(40 max(up, down) + 1,)``.

    Cut-off at the lower Nyquist frequency (``1 / max(up, down)`` of the upsampled one);
    unit DC gain (``resample_poly`` applies the factor ``up`` itself).
    """
    return _filter(up, down).copy()


@functools.lru_cache(maxsize=16)
def _filter(up: int, down: int) -> np.ndarray:
    """:func:`anti_aliasing_filter`, designed once per ratio and read-only: a set of records at one
    rate shares it (50 kHz to 20.48 kHz takes 25 001 taps, whose design cost more than the filtering)."""
    m = max(up, down)
    taps = firwin(2 * FILTER_HALF_LENGTH * m + 1, 1.0 / m, window=("kaiser", KAISER_BETA))
    taps.flags.writeable = False
    return taps


def rational_ratio(from_rate: float, to_rate: float) -> tuple[int, int]:
    """``(up, down)`` with ``from_rate * up / down`` within :data:`RATE_RTOL` of ``to_rate``.

    Raises
    ------
    ValueError
        If no fraction with ``up, down <= MAX_FACTOR`` is close enough.
    """
    ratio = Fraction(to_rate / from_rate).limit_denominator(MAX_FACTOR)
    up, down = ratio.numerator, ratio.denominator
    if up < 1 or up > MAX_FACTOR or abs(from_rate * up / down - to_rate) > RATE_RTOL * to_rate:
        raise ValueError(f"no ratio up/down with up, down <= {MAX_FACTOR} takes {from_rate:g} Hz to "
                         f"{to_rate:g} Hz within {RATE_RTOL:g} (relative)")
    return up, down


def resample_record(record: Record, sample_rate: float) -> tuple[Record, str | None]:
    """Resample every channel of ``record`` to ``sample_rate`` [Hz].

    Returns
    -------
    record : Record
        The resampled record (``resampled_from`` = the original rate, kept from an earlier
        resampling if there was one), or ``record`` itself when the rate already matches.
    note : str or None
        One line describing the resampling, ``None`` if nothing was done.

    Raises
    ------
    MeasurementError
        If the rate ratio has no small rational approximation (see :func:`rational_ratio`).
    """
    fs = record.sample_rate
    if math.isclose(fs, sample_rate, rel_tol=1e-12):
        return record, None
    try:
        up, down = rational_ratio(fs, sample_rate)
    except ValueError as exc:
        raise MeasurementError(record.source or "<memory>", record.name, f"cannot resample: {exc}") from None
    n = record.n_samples
    n_new = -(-n * up // down)                         # ceil, the length resample_poly returns
    achieved = fs * up / down
    taps = _filter(up, down)
    channels = {}
    for name, x in record.channels.items():
        if name == record.tachometer and record.tachometer_kind == "pulse":
            idx = np.minimum((np.arange(n_new) * down) // up, n - 1)
            channels[name] = x[idx]
        elif name == record.tachometer and record.tachometer_kind == "angle":
            t_old = np.arange(n) / fs
            t_new = np.arange(n_new) / achieved
            y = np.interp(t_new, t_old, x)
            if n >= 2:
                past = t_new > t_old[-1]
                y[past] = x[-1] + (x[-1] - x[-2]) * fs * (t_new[past] - t_old[-1])
            channels[name] = y
        else:
            channels[name] = resample_poly(x, up, down, window=taps, padtype="line")
    original = record.resampled_from if record.resampled_from is not None else fs
    out = dataclasses.replace(record, channels=channels, sample_rate=float(sample_rate), resampled_from=original)
    parts = [f"record '{record.name}': resampled {fs:g} Hz -> {sample_rate:g} Hz "
             f"(up {up}, down {down}; scipy.signal.resample_poly, {taps.size}-tap Kaiser (beta {KAISER_BETA:g}) "
             f"anti-aliasing FIR, linear-trend padding); {n} -> {n_new} samples"]
    if sample_rate < fs:
        parts.append(f"content above {sample_rate / 2:g} Hz removed")
    if achieved != sample_rate:
        parts.append(f"achieved rate {achieved:.12g} Hz ({(achieved / sample_rate - 1) * 1e6:.3g} ppm off)")
    if record.tachometer is not None:
        how = "sample-and-hold" if record.tachometer_kind == "pulse" else "linear interpolation"
        parts.append(f"tachometer '{record.tachometer}' ({record.tachometer_kind}) by {how}")
    return out, "; ".join(parts)
