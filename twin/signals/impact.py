"""Modes from a hammer (impact) test: impacts found in the force, FRF by H1/H2, modal peaks.

The record holds a train of hits and the response to each. The hits are found in the force
channel (peaks above a third of the largest, at least 50 ms apart); each hit opens a segment
that starts 1 % of a segment before it and lasts 95 % of the lower quartile of the intervals
between hits (of the shortest when there are fewer than five hits); a segment that would hold a
second hit is dropped (double-hit rejection), so the resolution is not set by the two closest
blows of a hand-held hammer. The segments are averaged into H1, H2 (paper Eq. 16) and the
coherence, and the estimator is the one the record's noise calls for: H2 (the paper's) when the
force channel is the noisier (a moving hammer, a quiet structure), H1 when the response is (a
hammer test on running or rolling gears, whose own vibration is noise to the FRF and biases H2
high wherever it outweighs the blows' response). Modes are the FRF peaks confirmed by a phase
turn (:func:`twin.signals.modes.modal_peaks`). A hammer excites only the structure, so every
confirmed peak is a mode; its confidence is its coherence times how far it clears the FRF's
local floor (the median level within about a third of an octave). The FRF is read up to where
the blows' force spectrum has fallen 20 dB (the tip's band), unless ``fmax`` says otherwise.
"""
from __future__ import annotations

import numpy as np
from scipy import signal as sps

from twin.signals._checks import SignalError, as_signal, positive, same_length
from twin.signals.modes import frf_h1_h2, modal_peaks
from twin.signals.survey import ModalSurvey, Mode


def find_impacts(force, fs: float, *, min_gap: float = 0.05) -> np.ndarray:
    """Sample indices of the hits in a hammer force record (peaks above a third of the largest)."""
    force = as_signal(force, "force")
    fs = positive(fs, "fs")
    mag = np.abs(force - np.median(force))
    if not mag.max() > 0:
        raise SignalError("the force channel is constant: no impact in the record")
    peaks, _ = sps.find_peaks(mag, height=mag.max() / 3.0, distance=max(1, int(min_gap * fs)))
    return peaks


ESTIMATORS = ("auto", "H1", "H2")


def impact_segments(hits, n_samples: int, fs: float, length: int | None = None) -> tuple[list[int], int]:
    """Start samples and length [samples] of the segments an FRF averages: one per hit, from 1 % of
    a segment before it, ``length`` long (default 95 % of the lower quartile of the intervals between
    hits, of the shortest when there are fewer than five); a segment that would hold the next hit is
    dropped (double-hit rejection)."""
    hits = np.asarray(hits, dtype=np.int64)
    if hits.size < 2:
        raise SignalError(f"found {hits.size} impact(s) in the force channel; an FRF needs at least 2 "
                          "(several hits, each followed by the response's decay)")
    gaps = np.diff(hits)
    if length is None:
        length = int(0.95 * (np.quantile(gaps, 0.25) if gaps.size >= 4 else np.min(gaps)))
    pre = max(1, length // 100)
    nxt = np.append(hits[1:], np.iinfo(np.int64).max)
    starts = [int(h - pre) for h, after in zip(hits, nxt)
              if h - pre >= 0 and h - pre + length <= n_samples and after >= h - pre + length]
    if len(starts) < 2 or length < 64:
        raise SignalError(f"the hits are {np.min(gaps) / fs:.3g} s apart: too close for an FRF "
                          "(need at least 64 samples and 2 whole segments)")
    return starts, int(length)


def hammer_frf_matrix(tests, fs: float, *, estimator: str = "auto"):
    """The FRF matrix of several hammer tests with the same response channels.

    tests : sequence of ``(force, responses)``, one per struck point: the force [N] (n,) and a
    sequence of responses (n,) in the same channel order for every test. All are cut into segments
    of one length (the shortest any test allows, :func:`impact_segments`), so the FRFs share one
    frequency grid. Returns ``f`` (n_f,) [Hz], ``H`` (n_f, n_out, n_ref) complex [unit / N],
    ``coherence`` (n_f, n_out, n_ref) and the upper edge [Hz] of the band every test's tip excites.
    Each FRF by H1 or H2 as ``estimator`` (``"auto"``: per test and channel, as
    :func:`analyse_impacts`).
    """
    if estimator not in ESTIMATORS:
        raise SignalError(f"unknown FRF estimator {estimator!r}: use one of {', '.join(ESTIMATORS)}")
    fs = positive(fs, "fs")
    prepared = []
    for force, responses in tests:
        force = as_signal(force, "force")
        responses = [as_signal(r, "response") for r in responses]
        for r in responses:
            same_length(force, r, "force", "response")
        hits = find_impacts(force, fs)
        prepared.append((force, responses, hits, impact_segments(hits, force.size, fs)[1]))
    if not prepared or len({len(r) for _, r, _, _ in prepared}) != 1 or not prepared[0][1]:
        raise SignalError("the hammer tests must have the same response channels (at least one)")
    length = min(p[3] for p in prepared)
    H, coh, top = [], [], []
    for force, responses, hits, _ in prepared:
        starts, _ = impact_segments(hits, force.size, fs, length)
        fx = np.concatenate([force[s:s + length] for s in starts])
        top.append(tip_band(fx, length, fs))
        col, cc = [], []
        for y in responses:
            fy = np.concatenate([y[s:s + length] for s in starts])
            est = noisier_channel_estimator(force, y, hits, fs) if estimator == "auto" else estimator
            f, h1, h2, c = frf_h1_h2(fx, fy, fs, nperseg=length)
            col.append(h1 if est == "H1" else h2)
            cc.append(c)
        H.append(np.array(col).T)
        coh.append(np.array(cc).T)
    return f, np.stack(H, axis=2), np.stack(coh, axis=2), float(min(top))


def analyse_impacts(force, response, fs: float, *, fmin: float | None = None,
                    fmax: float | None = None, estimator: str = "auto") -> ModalSurvey:
    """Modes [Hz] with damping ratios from a hammer record (force [N], response [unit]).

    ``estimator``: ``"auto"`` (the one the noisier channel calls for, see the module docstring),
    or ``"H1"``/``"H2"`` forced.
    """
    if estimator not in ESTIMATORS:
        raise SignalError(f"unknown FRF estimator {estimator!r}: use one of {', '.join(ESTIMATORS)}")
    force = as_signal(force, "force")
    response = as_signal(response, "response")
    same_length(force, response, "force", "response")
    fs = positive(fs, "fs")
    hits = find_impacts(force, fs)
    starts, length = impact_segments(hits, force.size, fs)
    fx = np.concatenate([force[s:s + length] for s in starts])
    fy = np.concatenate([response[s:s + length] for s in starts])
    why = "as asked"
    if estimator == "auto":
        estimator = noisier_channel_estimator(force, response, hits, fs)
        why = f"the {'response' if estimator == 'H1' else 'force'} channel is the noisier"
    f, h1, h2, coh = frf_h1_h2(fx, fy, fs, nperseg=length)
    h = h1 if estimator == "H1" else h2
    df = f[1] - f[0]
    fmin = float(4 * df if fmin is None else fmin)
    if fmax is None:
        fmax = min(0.4 * fs, 10_000.0, tip_band(fx, length, fs))
    fmax = float(fmax)
    ok = np.isfinite(h) & (f > 0)
    f, h, coh = f[ok], h[ok], coh[ok]
    freqs, damping = modal_peaks(f, h, n=200, fmin=fmin, fmax=fmax, prominence_db=3.0)
    level = 20 * np.log10(np.maximum(np.abs(h), np.finfo(float).tiny))
    band = (f >= fmin) & (f <= fmax)
    floor = float(np.median(level[band]))
    modes = []
    for fn, zeta in zip(freqs, damping):
        k = int(np.argmin(np.abs(f - fn)))
        prom = float(level[k] - local_floor(f, level, fn))
        c = float(np.clip(coh[k], 0.0, 1.0))
        conf = c * (1.0 - np.exp(-max(prom, 0.0) / 6.0))
        modes.append(Mode(float(fn), float(zeta), float(conf), prom,
                          {"coherence": round(c, 3), "hits": len(starts), "resolution_hz": round(float(df), 4),
                           "frequency_sd_hz": round(float(df) / 4, 4), "estimator": estimator,
                           "reason": "FRF peak with a phase turn (hammer test)"}))
    note = f"FRF by {estimator}, {why} ({len(starts)} of {hits.size} hits used, {df:.2f} Hz resolution)"
    return ModalSurvey("hammer", tuple(modes), (), (), (fmin, fmax), float(df), f[band], level[band] - floor,
                       notes=(note,))


#: How far [dB] the blows' force spectrum may fall below its low-frequency level within the band
#: the FRF is read in: beyond, the hammer tip puts too little force in to read a response.
TIP_DROP_DB = 20.0


def tip_band(segments, length: int, fs: float) -> float:
    """Upper edge [Hz] of the band the blows excite: where the mean force auto-spectrum of the
    segments (``segments``: their samples end to end, ``length`` each) first falls ``TIP_DROP_DB``
    below its level at the lowest frequencies (a hammer tip's pulse of duration T has a lobe to
    about 1/T; the FRF beyond is noise over noise)."""
    x = np.asarray(segments, float).reshape(-1, length)
    gxx = np.mean(np.abs(np.fft.rfft(x, axis=1)) ** 2, axis=0)
    ref = float(np.median(gxx[1:max(2, gxx.size // 50)]))
    low = np.flatnonzero(gxx[1:] < ref * 10 ** (-TIP_DROP_DB / 10))
    return float(fs / 2 if low.size == 0 else (low[0] + 1) * fs / length)


#: Half-width of the band a peak's floor is read from, as a frequency ratio (about a third of an
#: octave each side).
FLOOR_RATIO = 1.25


def local_floor(f, level, fn: float) -> float:
    """The FRF's floor [dB] near ``fn`` [Hz]: the median level between ``fn / FLOOR_RATIO`` and
    ``fn * FLOOR_RATIO``. A mode's prominence is read against it, not against the whole band's
    median: an accelerance rises with frequency, so a low mode (a shaft's) can stand well clear of
    its neighbourhood and still lie below the median of a band that holds the casing's modes."""
    near = (f >= fn / FLOOR_RATIO) & (f <= fn * FLOOR_RATIO)
    return float(np.median(level[near])) if near.any() else float(np.median(level))


def noisier_channel_estimator(force, response, hits, fs: float) -> str:
    """``"H1"`` when the response channel is the noisier of the two, else ``"H2"``.

    Each channel's noise-to-signal ratio [-]: the force's r.m.s. away from the hits (more than
    10 ms from any) over its r.m.s. within 1 ms of them; the response's r.m.s. in the 10 ms before
    each hit (the structure between blows: its own running vibration, plus what is left of the
    previous decay) over its r.m.s. in the 10 ms after. H1 is unbiased by response noise, H2 by
    force noise (:func:`twin.signals.modes.frf_h1_h2`).
    """
    force, response = np.asarray(force, float), np.asarray(response, float)
    w, p = max(2, int(0.01 * fs)), max(1, int(0.001 * fs))
    near = np.zeros(force.size, bool)
    pulse = np.zeros(force.size, bool)
    for h in hits:
        near[max(0, h - w):h + w] = True
        pulse[max(0, h - p):h + p] = True
    rms = lambda x: float(np.sqrt(np.mean(np.square(x)))) if x.size else 0.0   # noqa: E731
    force_nsr = rms(force[~near]) / max(rms(force[pulse]), np.finfo(float).tiny)
    before = np.concatenate([response[max(0, h - w):h] for h in hits])
    after = np.concatenate([response[h:h + w] for h in hits])
    response_nsr = rms(before) / max(rms(after), np.finfo(float).tiny)
    return "H1" if response_nsr > force_nsr else "H2"
