"""A mode's shape at the sensors: relative level and phase between channels, from cross-spectra.

Near a lightly damped resonance the response at every sensor is dominated by that one mode, so
the ratio of two channels' spectra in the bins of its hump is the ratio of the mode's shape at the
two sensors, whatever excites it. Over the run-up slices ``s`` and the hump's bins ``k``, with
``X_a`` the complex spectrum of channel a (Hann slices, as the survey's):

* ``G_ab = sum_{s,k} conj(X_a) X_b`` (cross-spectral sums);
* the reference ``r`` is the channel with the largest ``G_rr`` (the mode shows best there);
* level of channel c: ``10 log10(G_cc / G_rr)`` [dB re the reference]; phase ``angle(G_rc)`` [deg];
* coherence ``|G_rc|^2 / (G_rr G_cc)`` in [0, 1]: near 1 when one mode drives both channels
  (the shape is trustworthy), low when independent noise, another mode or an uncorrelated
  source fills the hump at one of them.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import signal as sps

from twin.signals._checks import SignalError, as_signal, positive, positive_int


@dataclass(frozen=True)
class ChannelShape:
    """One mode at the sensors: per channel, level [dB re reference], phase [deg], coherence [-]."""

    reference: str
    channels: tuple[str, ...]
    level_db: tuple[float, ...]
    phase_deg: tuple[float, ...]
    coherence: tuple[float, ...]
    averages: int                     # slices x bins summed

    @property
    def min_coherence(self) -> float:
        """Lowest coherence of a channel with the reference (1 with one channel)."""
        others = [c for n, c in zip(self.channels, self.coherence) if n != self.reference]
        return float(min(others)) if others else 1.0

    def vector(self) -> np.ndarray:
        """(c,) complex shape, 1 at the reference, in the order of ``channels``."""
        return np.array([10 ** (lv / 20) * np.exp(1j * np.radians(ph)) for lv, ph in zip(self.level_db, self.phase_deg)])

    def to_dict(self) -> dict:
        return {"reference": self.reference, "averages": self.averages, "min_coherence": round(self.min_coherence, 4),
                "channels": {c: {"level_db": round(lv, 2), "phase_deg": round(ph, 1), "coherence": round(co, 4)}
                             for c, lv, ph, co in zip(self.channels, self.level_db, self.phase_deg, self.coherence)}}


def complex_slices(x, fs: float, nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """(f (nf,) [Hz], X (nf, nt) complex) of Hann slices with 50 % overlap, as the run-up survey's."""
    x = as_signal(x, "x", min_length=16)
    nperseg = positive_int(nperseg, "nperseg")
    if nperseg > x.size:
        raise SignalError(f"nperseg={nperseg} is longer than the record ({x.size} samples)")
    step = nperseg // 2
    f, _, X = sps.spectrogram(x, fs=positive(fs, "fs"), window="hann", nperseg=nperseg, noverlap=nperseg - step,
                              detrend="constant", scaling="density", mode="complex")
    return f, X


def channel_shapes(xs: Sequence, names: Sequence[str], fs: float, frequencies, half_widths, *, nperseg: int,
                   exclude_hz=()) -> list[ChannelShape]:
    """Shape of each mode at the channels (see the module docstring).

    Parameters
    ----------
    xs : sequence of (n,) arrays
        The channels [same unit], sampled together.
    names : channel names, as many as ``xs``.
    fs : sampling rate [Hz].
    frequencies, half_widths : (m,) arrays
        Each mode's frequency [Hz] and the half-width of its hump [Hz] (at least 1.5 bins is used).
    nperseg : samples per slice (the survey's).
    exclude_hz : frequencies [Hz] of fixed lines; their bins (+-2) are left out of every hump.
    """
    if len(xs) != len(names) or not xs:
        raise SignalError(f"need one name per channel, got {len(xs)} channels and {len(names)} names")
    spectra = [complex_slices(x, fs, nperseg) for x in xs]
    f = spectra[0][0]
    if any(X.shape != spectra[0][1].shape for _, X in spectra):
        raise SignalError("the channels must have the same length")
    X = np.stack([s[1] for s in spectra])          # (c, nf, nt)
    df = f[1] - f[0]
    excluded = np.zeros(f.size, dtype=bool)
    for fl in np.atleast_1d(np.asarray(exclude_hz, float)):
        excluded |= np.abs(f - fl) <= 2 * df
    out = []
    for fn, hw in zip(np.atleast_1d(np.asarray(frequencies, float)), np.atleast_1d(np.asarray(half_widths, float))):
        width = max(float(hw) if np.isfinite(hw) else 0.0, 1.5 * df)
        bins = np.flatnonzero((np.abs(f - fn) <= width) & ~excluded)
        if bins.size == 0:
            bins = np.array([int(np.argmin(np.abs(f - fn)))])
        seg = X[:, bins, :].reshape(len(xs), -1)            # (c, bins * slices)
        G = seg.conj() @ seg.T                               # G[a, b] = sum conj(X_a) X_b
        auto = np.real(np.diag(G))
        r = int(np.argmax(auto))
        tiny = np.finfo(float).tiny
        level = 10 * np.log10(np.maximum(auto, tiny) / max(auto[r], tiny))
        phase = np.degrees(np.angle(G[r]))
        coh = np.abs(G[r]) ** 2 / np.maximum(auto[r] * auto, tiny)
        out.append(ChannelShape(names[r], tuple(names), tuple(float(v) for v in level),
                                tuple(float(v) for v in phase), tuple(float(min(1.0, v)) for v in coh),
                                int(seg.shape[1])))
    return out
