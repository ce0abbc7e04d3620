"""Resampling a record to another sampling rate, visibly.

Vibration channels go through :func:`scipy.signal.resample_poly`'s polyphase filter
(computed as matrix products by :func:`polyphase`, the same numbers to round-off) with the rate ratio
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


# Rows of one matrix product in :func:`polyphase`: OpenBLAS runs a product of fewer than about
# 2.6e5 multiply-adds on the calling thread; larger ones start its own threads, which cost more
# than they save on these sizes (3 x slower, trial of 2026-11-26) and compete with the callers'
# worker threads.
ROWS_PER_PRODUCT = 16
PHASE_GROUPS = 4


@functools.lru_cache(maxsize=16)
def _plan(up: int, down: int) -> tuple[int, int, tuple]:
    """The polyphase matrices of :func:`polyphase` for one ratio: (taps per phase, outputs to
    skip, ((output phases, first input offset, inputs per block, matrix (inputs, phases)), ...)).

    Output sample ``up b + r`` is filter phase ``r``'s taps on the inputs ending at ``down b +
    base[r]``: for a group of consecutive phases their inputs overlap, so one matrix of the
    group's taps, placed at each phase's offset, gives the group's outputs of every block ``b``
    as one product with the block's inputs.  The zero-padding and output offset are
    ``resample_poly``'s."""
    taps = _filter(up, down)
    half = (taps.size - 1) // 2
    pre_pad = down - half % down
    skip = (half + pre_pad) // down
    h = np.concatenate([np.zeros(pre_pad), taps * up])
    q = -(-h.size // up)
    h = np.concatenate([h, np.zeros(q * up - h.size)]).reshape(q, up)        # h[k, phase]: tap k of the phase
    t = (np.arange(up) + skip) * down
    base, phase = t // up, t % up
    parts = []
    for rs in np.array_split(np.arange(up), min(PHASE_GROUPS, up)):
        start = int(base[rs[0]]) - (q - 1)
        width = int(base[rs[-1]]) - start + 1
        m = np.zeros((width, rs.size))
        for col, r in enumerate(rs):
            m[base[r] - np.arange(q) - start, col] = h[:, phase[r]]
        m.flags.writeable = False
        parts.append((slice(int(rs[0]), int(rs[-1]) + 1), start, width, m))
    return q, skip, tuple(parts)


def polyphase(x: np.ndarray, up: int, down: int) -> np.ndarray:
    """``scipy.signal.resample_poly(x, up, down, window=anti_aliasing_filter(up, down),
    padtype="line")`` of a 1-D float signal, to float64 round-off, as a few matrix products per
    group of filter phases (:func:`_plan`) instead of scipy's one multiply-add at a time (4 x
    faster for 50 kHz -> 20.48 kHz, 1 thread, trial of 2026-11-26).  ``up`` and ``down`` coprime."""
    x = np.asarray(x, dtype=np.float64)
    n = x.size
    if n < 2:
        return resample_poly(x, up, down, window=_filter(up, down), padtype="line")
    _, _, parts = _plan(up, down)
    n_out = -(-n * up // down)
    blocks = -(-n_out // up)
    lo = min(start for _, start, _, _ in parts)
    hi = max(start + width - 1 for _, start, width, _ in parts) + (blocks - 1) * down
    left, right = max(0, -lo), max(0, hi - (n - 1))
    slope = (x[-1] - x[0]) / (n - 1)               # padtype "line": the line through the end samples
    xe = np.concatenate([x[0] + slope * np.arange(-left, 0), x, x[-1] + slope * np.arange(1, right + 1)])
    y = np.empty((blocks, up))
    rows = left + down * np.arange(blocks)
    for phases, start, width, m in parts:
        inputs = np.lib.stride_tricks.sliding_window_view(xe, width)
        for a in range(0, blocks, ROWS_PER_PRODUCT):
            y[a:a + ROWS_PER_PRODUCT, phases] = inputs[start + rows[a:a + ROWS_PER_PRODUCT]] @ m
    return y.ravel()[:n_out]


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
            channels[name] = polyphase(x, up, down)
    original = record.resampled_from if record.resampled_from is not None else fs
    out = dataclasses.replace(record, channels=channels, sample_rate=float(sample_rate), resampled_from=original)
    parts = [f"record '{record.name}': resampled {fs:g} Hz -> {sample_rate:g} Hz "
             f"(up {up}, down {down}; polyphase as scipy.signal.resample_poly, {taps.size}-tap Kaiser (beta {KAISER_BETA:g}) "
             f"anti-aliasing FIR, linear-trend padding); {n} -> {n_new} samples"]
    if sample_rate < fs:
        parts.append(f"content above {sample_rate / 2:g} Hz removed")
    if achieved != sample_rate:
        parts.append(f"achieved rate {achieved:.12g} Hz ({(achieved / sample_rate - 1) * 1e6:.3g} ppm off)")
    if record.tachometer is not None:
        how = "sample-and-hold" if record.tachometer_kind == "pulse" else "linear interpolation"
        parts.append(f"tachometer '{record.tachometer}' ({record.tachometer_kind}) by {how}")
    return out, "; ".join(parts)
