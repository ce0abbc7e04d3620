"""Modes from a hammer (impact) test: impacts found in the force, FRF by H1/H2, modal peaks.

The record holds a train of hits and the response to each. The hits are found in the force
channel (peaks above a third of the largest, at least 50 ms apart); each hit opens a segment
that starts 1 % of a segment before it and lasts 95 % of the shortest interval between hits,
so every segment holds one hit and as much of its decay as the hit rate allows. The segments
are averaged into H1, H2 (paper Eq. 16) and the coherence; modes are the FRF peaks confirmed
by a phase turn (:func:`twin.signals.modes.modal_peaks`). A hammer excites only the structure,
so every confirmed peak is a mode; its confidence is its coherence times how far it clears
the noise.
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


def analyse_impacts(force, response, fs: float, *, fmin: float | None = None,
                    fmax: float | None = None) -> ModalSurvey:
    """Modes [Hz] with damping ratios from a hammer record (force [N], response [unit])."""
    force = as_signal(force, "force")
    response = as_signal(response, "response")
    same_length(force, response, "force", "response")
    fs = positive(fs, "fs")
    hits = find_impacts(force, fs)
    if hits.size < 2:
        raise SignalError(f"found {hits.size} impact(s) in the force channel; an FRF needs at least 2 "
                          "(several hits, each followed by the response's decay)")
    length = int(0.95 * np.min(np.diff(hits)))
    pre = max(1, length // 100)
    starts = [h - pre for h in hits if h - pre >= 0 and h - pre + length <= force.size]
    if len(starts) < 2 or length < 64:
        raise SignalError(f"the hits are {np.min(np.diff(hits)) / fs:.3g} s apart: too close for an FRF "
                          "(need at least 64 samples and 2 whole segments)")
    fx = np.concatenate([force[s:s + length] for s in starts])
    fy = np.concatenate([response[s:s + length] for s in starts])
    f, _, h2, coh = frf_h1_h2(fx, fy, fs, nperseg=length)
    df = f[1] - f[0]
    fmin = float(4 * df if fmin is None else fmin)
    fmax = float(min(0.4 * fs, 10_000.0) if fmax is None else fmax)
    ok = np.isfinite(h2) & (f > 0)
    f, h2, coh = f[ok], h2[ok], coh[ok]
    freqs, damping = modal_peaks(f, h2, n=200, fmin=fmin, fmax=fmax, prominence_db=3.0)
    level = 20 * np.log10(np.maximum(np.abs(h2), np.finfo(float).tiny))
    band = (f >= fmin) & (f <= fmax)
    floor = float(np.median(level[band]))
    modes = []
    for fn, zeta in zip(freqs, damping):
        k = int(np.argmin(np.abs(f - fn)))
        prom = float(level[k] - floor)
        c = float(np.clip(coh[k], 0.0, 1.0))
        conf = c * (1.0 - np.exp(-max(prom, 0.0) / 6.0))
        modes.append(Mode(float(fn), float(zeta), float(conf), prom,
                          {"coherence": round(c, 3), "hits": len(starts), "resolution_hz": round(float(df), 4),
                           "frequency_sd_hz": round(float(df) / 4, 4),
                           "reason": "FRF peak with a phase turn (hammer test)"}))
    return ModalSurvey("hammer", tuple(modes), (), (), (fmin, fmax), float(df), f[band], level[band] - floor)
