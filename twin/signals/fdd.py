"""Close modes from several channels: the frequency-domain decomposition (FDD) of a run-up.

Two modes a few per cent apart, each damped by 1.5-2.5 %, merge into one hump at a single sensor,
and the per-channel search (:mod:`twin.signals.runup`) reports one mode for the two. If the two
modes have different shapes at the sensors, the channels' cross-spectral matrix tells them apart
(Brincker, Zhang & Andersen 2001):

1. **Cross-spectral matrix.** ``G(f) = mean_s X_s(f) X_s(f)^H`` over the run-up's Hann slices
   ``s`` (those of the survey), with each slice scaled by its own local floor (the running median
   of the channels' summed power over one octave, as the survey reads levels), the orders' tracks
   masked as the survey masks them, and bins where one slice stands far above the others (an
   order sweeping through, a transient) left out. The fixed lines are cut (each element
   interpolated across the line's bins).
2. **Singular values.** Per bin ``G = U S U^H``; ``s1`` is the power of the dominant shape
   ``u1``. A peak of ``s1`` is a mode; one of a single shape (MAC of ``u1`` between the hump's
   half-power flanks >= 0.9) that the per-channel search lacks is added.
3. **Close modes.** Inside each hump of ``s1``, the dominant mode is cancelled by projecting the
   matrix off its shape ``phi = u1`` at the peak: ``r(f) = trace(P G P)``, ``P = I - phi phi^H``.
   What a mode of another shape contributes survives the projection, so a second mode under the
   hump stands out as a peak of ``r`` away from the first (a modal filter built from the data; unlike
   the per-bin ``s2`` it does not peak where the two modes cross over). The first singular vector
   changes across such a hump: the MAC between ``u1`` at its two half-power flanks is reported.
   The hump's own mode is then refitted on the power of its shape, ``u1^H G u1``, with the second
   mode's response as a coherent neighbour; the pair replaces the per-channel fits inside the hump
   (which sit between the two modes).

Frequency and damping of the other new modes by the survey's single-mode fit to the dB curve they
were found on (``s1`` or ``r``), confidence as the survey's. Frequencies in Hz, levels in dB re the
local floor.
"""
from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from scipy import signal as sps
from scipy.optimize import least_squares

from twin.signals import peaks as pk
from twin.signals import runup as ru
from twin.signals._checks import SignalError
from twin.signals.shapes import complex_slices
from twin.signals.survey import ModalSurvey, Mode

#: A slice's power in a bin more than this many times the bin's median over the slices is left
#: out (a randomly excited bin exceeds it about once in 10^6 slices).
OUTLIER_RATIO = 20.0
#: A second mode under a hump must lie at least this far from the hump's peak (relative).
MIN_SPLIT = 0.02
#: A hump whose first singular vector keeps this MAC between its flanks is of one shape.
MAC_ONE_SHAPE = 0.9


def _mac(a: np.ndarray, b: np.ndarray) -> float:
    den = float(np.real(np.vdot(a, a) * np.vdot(b, b)))
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


def _same_mode(f1: float, f2: float, df: float) -> bool:
    """The merge rule of :func:`twin.modes.merge_surveys`: within 1 % or two bins."""
    return abs(f1 - f2) <= max(0.01 * f2, 2 * df)


class _Matrix:
    """The channels' slices, scaled and masked, and their cross-spectral matrix per bin."""

    def __init__(self, xs, fs: float, nperseg: int, angle, survey: ModalSurvey):
        spectra = [complex_slices(x, fs, nperseg) for x in xs]
        self.f = spectra[0][0]
        X = np.stack([s[1] for s in spectra])                 # (c, nf, nt)
        self.df = float(self.f[1] - self.f[0])
        fmin, fmax = survey.band
        self.band = np.flatnonzero((self.f >= fmin) & (self.f <= fmax))
        nt = X.shape[2]
        masked = np.zeros(X.shape[1:], dtype=bool)
        if angle is not None and survey.orders:
            starts = np.arange(nt) * (nperseg // 2)
            speed, spread = ru._slice_speeds(np.asarray(angle, float), starts, nperseg, fs)
            masked = ru._mask_orders(masked.shape, self.f, speed, spread, survey.orders)
        tiny = np.finfo(float).tiny
        power = np.sum(np.abs(X) ** 2, axis=0)
        floor_db = ru._local_floor(10 * np.log10(np.maximum(power, tiny)), self.f, fmin, fmax)
        X = X / np.sqrt(10 ** (floor_db / 10))[None]
        power = np.sum(np.abs(X) ** 2, axis=0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            typical = np.nanmedian(np.where(masked, np.nan, power), axis=1)
        self.keep = ~masked & ~(power > OUTLIER_RATIO * np.nan_to_num(typical, nan=np.inf)[:, None])
        self.X = X * self.keep[None]
        n = self.keep.sum(axis=1)
        self.n_used = np.maximum(n, 1)
        G = np.einsum("afs,bfs->fab", self.X, self.X.conj()) / self.n_used[:, None, None]
        bad = n == 0
        if bad.all():
            raise SignalError("every bin is covered by an order track; nothing stationary is left")
        trace_db = 10 * np.log10(np.maximum(np.real(np.einsum("faa->f", G)), tiny))
        for lo, hi in pk._line_cuts(self.f, trace_db, survey.lines):
            bad[lo:hi] = True
        good = np.flatnonzero(~bad)
        for a in range(G.shape[1]):
            for b in range(G.shape[2]):
                G[bad, a, b] = (np.interp(self.f[bad], self.f[good], G[good, a, b].real)
                                + 1j * np.interp(self.f[bad], self.f[good], G[good, a, b].imag))
        self.G = G
        w, v = np.linalg.eigh(G)
        self.s1, self.u1 = w[:, -1], v[:, :, -1]
        n_ = self.n_used.astype(float)
        self.threshold = np.maximum(3.0, ru.FALSE_PEAK_SIGMAS * np.maximum(ru.NOISE_SD_DB / np.sqrt(n_), 0.2))

    def curve(self, power: np.ndarray) -> np.ndarray:
        """dB re its local floor, [1 2 1]-smoothed, of a power spectrum (nf,)."""
        raw = 10 * np.log10(np.maximum(power, np.finfo(float).tiny))
        fmin, fmax = float(self.f[self.band[0]]), float(self.f[self.band[-1]])
        return ru._smooth121(raw - ru._local_floor(raw[:, None], self.f, fmin, fmax)[:, 0])

    def peaks(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(bins, prominences [dB]) of the peaks of z in the band that clear the noise threshold."""
        p, props = sps.find_peaks(z[self.band], prominence=0.0)
        ok = props["prominences"] >= self.threshold[self.band[p]]
        return self.band[p[ok]], props["prominences"][ok]

    def slices_db(self, weights: np.ndarray | None) -> np.ndarray:
        """(nf, nt) per-slice power [dB] of the channels seen through ``weights`` (nf, c), or of
        the projection off the fixed shape ``weights`` (c,) when it is 1-D."""
        if weights.ndim == 1:
            phi = weights / np.linalg.norm(weights)
            Y = self.X - phi[:, None, None] * np.einsum("a,afs->fs", phi.conj(), self.X)[None]
            power = np.sum(np.abs(Y) ** 2, axis=0)
        else:
            power = np.abs(np.einsum("fa,afs->fs", weights.conj(), self.X)) ** 2
        return 10 * np.log10(np.maximum(power, np.finfo(float).tiny))

    def projected(self, phi: np.ndarray) -> np.ndarray:
        """r(f) = trace(P G P), P = I - phi phi^H: the power of what is not of shape phi."""
        phi = phi / np.linalg.norm(phi)
        P = np.eye(phi.size) - np.outer(phi, phi.conj())
        return np.real(np.einsum("ab,fbc,ca->f", P, self.G, P))


def _mode(m: _Matrix, z: np.ndarray, p: int, prom: float, lo: int, hi: int, slices_db: np.ndarray,
          evidence: dict) -> Mode | None:
    """A mode from the peak at bin p of the dB curve z (fit over [lo, hi)), or None for a line."""
    f, df = m.f, m.df
    width = pk._half_power_width(f, z, p)
    narrow = np.isfinite(width) and width <= pk.LINE_WIDTH_BINS * df
    masked = ~m.keep
    if narrow:
        steady, fluct, _ = pk._steadiness(slices_db, masked, z, p)
        if steady:
            return None
    else:
        fluct = pk._fluctuation_db(slices_db, masked, p)
    fn, zeta, r2, fn_sd = pk._sdof_fit(f, z, p, lo, hi, df)
    # presence: the share of the slices in which the bin stands clear of the slice's own median
    # level around it (one octave), as the survey counts it
    hw = max(5, int(round(f[p] * (np.sqrt(2) - 1) / df)))
    near = slices_db[max(1, p - hw):p + hw + 1]
    level = slices_db[p] - np.median(near, axis=0)
    used = m.keep[p]
    present = float(np.mean(level[used] > 0.5 * prom)) if used.any() else 0.0
    clear = 1.0 - np.exp(-((prom / (2.0 * m.threshold[p])) ** 2))
    conf = clear * (0.4 + 0.6 * present) * (0.6 + 0.4 * max(r2, 0.0)) * (0.7 if narrow else 1.0)
    return Mode(float(fn), float(zeta), float(np.clip(conf, 0.0, 1.0)), float(prom), {
        **evidence, "width_hz": round(float(width), 3) if np.isfinite(width) else None,
        "slice_level_sd_db": round(float(fluct), 2) if np.isfinite(fluct) else None,
        "persistence": round(present, 3), "fit_r2": round(r2, 3), "frequency_sd_hz": round(fn_sd, 3),
        "resolution_hz": round(float(df), 4)})


def _window(m: _Matrix, z: np.ndarray, p: int, left: int | None, right: int | None) -> tuple[int, int]:
    """Fit window around bin p: the hump, at most half-way to the neighbouring peaks."""
    width = pk._half_power_width(m.f, z, p)
    reach = int(np.clip(np.ceil(2.5 * (width if np.isfinite(width) else 4 * m.df) / m.df), 4, 200))
    lo = max(p - reach, (left + p) // 2 if left is not None else m.band[0], 1)
    hi = min(p + reach + 1, (right + p) // 2 + 1 if right is not None else m.band[-1] + 1)
    return lo, hi


def _flanks(z: np.ndarray, p: int, lo: int, hi: int) -> tuple[int, int]:
    """Bins where the hump at p has fallen 3 dB on either side (within [lo, hi))."""
    i, j = p, p
    while i - 1 >= lo and z[i - 1] > z[p] - 3.0:
        i -= 1
    while j + 1 < hi and z[j + 1] > z[p] - 3.0:
        j += 1
    return max(i - 1, lo), min(j + 1, hi - 1)


def fdd_modes(xs: Sequence, fs: float, angle, survey: ModalSurvey, *, min_confidence: float = 0.3
              ) -> tuple[Mode, ...]:
    """The survey's modes completed by the channels' cross-spectral matrix.

    Parameters
    ----------
    xs : sequence of (n,) arrays, at least two
        The vibration channels, sampled together, as the survey read them.
    fs : sampling rate [Hz].
    angle : (n,) array or None
        Unwrapped shaft angle [rad] the survey used (for the order masks).
    survey : the per-channel survey (its modes, band, resolution, orders and lines are used).
    min_confidence : a hump is split only when its second mode has at least this confidence.

    Returns
    -------
    tuple of Mode, ascending in frequency
        The survey's modes and the new ones, each new one with ``evidence["found_by"]`` and the
        hump's ``flank_mac``: ``"close mode"`` (under the hump of a mode of another shape) and
        ``"close pair: dominant"`` (that hump's own mode, fitted with the close one as its
        neighbour), each with ``evidence["pair_hz"]`` the other's frequency; they replace the
        survey's modes inside the hump (``evidence["replaces_hz"]``: single-channel fits of the
        merged hump, pulled towards the other mode). ``"s1 peak"``: a hump of one shape that no
        channel showed clearly enough.
    """
    if len(xs) < 2:
        raise SignalError(f"the cross-spectral matrix needs at least two channels, got {len(xs)}")
    nperseg = int(round(fs / survey.resolution))
    m = _Matrix(xs, fs, nperseg, angle, survey)
    modes = list(survey.modes)
    z1 = m.curve(m.s1)
    idx, prom = m.peaks(z1)
    s1_slices = None

    def near(fr: float) -> list[int]:
        return [i for i, md in enumerate(modes) if _same_mode(md.frequency, fr, m.df)]

    for j, (p, pr) in enumerate(zip(idx, prom)):
        lo, hi = _window(m, z1, p, idx[j - 1] if j > 0 else None, idx[j + 1] if j + 1 < idx.size else None)
        a, b = _flanks(z1, p, lo, hi)
        mac = _mac(m.u1[a], m.u1[b])
        base = {"flank_mac": round(mac, 3)}
        second = _close_mode(m, p, lo, hi, base)
        dominant = _dominant(m, p, pr, lo, hi, second, base) if second is not None else None
        if dominant is not None and second.confidence >= min_confidence:
            # the hump holds two modes: its single-channel fits (between the two, pulled by the
            # other mode) give way to the pair
            inside = [md for md in modes if m.f[lo] <= md.frequency <= m.f[hi - 1] and "found_by" not in md.evidence]
            gone = [round(md.frequency, 2) for md in inside]
            modes = [md for md in modes if md not in inside]
            for md in (dominant, second):
                if not near(md.frequency):
                    modes.append(replace(md, evidence={**md.evidence, "replaces_hz": gone}))
            continue
        if mac < MAC_ONE_SHAPE or near(float(m.f[p])):
            continue
        if s1_slices is None:
            s1_slices = m.slices_db(m.u1)
        md = _mode(m, z1, p, pr, lo, hi, s1_slices, {
            **base, "found_by": "s1 peak",
            "reason": "a peak of the first singular value of the channels' cross-spectral matrix"})
        if md is not None and not near(md.frequency):
            modes.append(md)
    return tuple(sorted(modes, key=lambda md: md.frequency))


def _close_mode(m: _Matrix, p: int, lo: int, hi: int, base: dict) -> Mode | None:
    """A mode of another shape under the s1 hump at bin p (bins [lo, hi)), or None."""
    # the hump's dominant shape cancelled: what is left under the hump is of another shape
    za = m.curve(m.projected(m.u1[p]))
    ridx, rprom = m.peaks(za)
    inside = (ridx >= lo) & (ridx < hi) & (np.abs(m.f[ridx] - m.f[p]) >= max(MIN_SPLIT * m.f[p], 2 * m.df))
    if not inside.any():
        return None
    k = int(np.argmax(np.where(inside, rprom, -np.inf)))
    q, qp = int(ridx[k]), float(rprom[k])
    qlo, qhi = _window(m, za, q, p if q > p else None, p if q < p else None)
    return _mode(m, za, q, qp, qlo, qhi, m.slices_db(m.u1[p]), {
        **base, "found_by": "close mode",
        "reason": "a hump of another shape under a mode's hump: left when the dominant shape is projected "
                  "out of the cross-spectral matrix"})


def _dominant(m: _Matrix, p: int, prom: float, lo: int, hi: int, second: Mode, base: dict) -> Mode | None:
    """The hump's own mode, fitted on the power of its shape ``u1(p)`` with the close mode
    ``second`` as a neighbour of free complex weight; None if the fit fails or merges the two."""
    z = m.curve(np.real(np.einsum("a,fab,b->f", m.u1[p].conj(), m.G, m.u1[p])))
    zeta_b = second.damping if np.isfinite(second.damping) else 0.02
    fit = _pair_fit(m.f, z, p, lo, hi, m.df, second.frequency, zeta_b)
    if fit is None:
        return None
    fn, zeta, r2 = fit
    if r2 < 0.8 or _same_mode(fn, second.frequency, m.df) or not m.f[lo] <= fn <= m.f[hi - 1]:
        return None
    clear = 1.0 - np.exp(-((prom / (2.0 * m.threshold[p])) ** 2))
    return Mode(fn, zeta if 2 * zeta * fn >= 0.5 * m.df else float("nan"), float(clear * (0.6 + 0.4 * r2)),
                float(prom), {**base, "found_by": "close pair: dominant", "pair_hz": round(second.frequency, 2),
                              "fit_r2": round(r2, 3), "resolution_hz": round(float(m.df), 4),
                              "reason": "the mode of a hump that holds two shapes, fitted on the power of its own "
                                        "shape with the close mode as its neighbour"})


def _pair_fit(f: np.ndarray, z: np.ndarray, p: int, lo: int, hi: int, df: float, fb: float, zeta_b: float
              ) -> tuple[float, float, float] | None:
    """(fn [Hz], zeta, R^2) of the mode at bin p of a dB curve, with a known neighbour (fb [Hz], zeta_b).

    The survey's single-mode model (see :func:`twin.signals.peaks._sdof_fit`) with the neighbour's
    response added at a free complex weight ``c``:
    ``10 log10(a^2 |H(f; fn, zeta) + c H(f; fb, zeta_b) + beta|^2 + n)``.
    """
    ff, zz = f[lo:hi], z[lo:hi]
    if ff.size < 8:
        return None
    grid = ff[:, None] + pk._KERNEL_OFFSETS[None, :] * df
    rb = grid / fb
    hb = 1.0 / (1 - rb * rb + 2j * zeta_b * rb)

    def model(x):
        fn, zeta, la, cr, ci, beta, ln = x
        r = grid / fn
        h = 1.0 / (1 - r * r + 2j * zeta * r) + (cr + 1j * ci) * hb + beta
        return 10 * np.log10((10 ** la * np.abs(h) ** 2) @ pk._KERNEL + 10 ** ln)

    width = pk._half_power_width(f, z, p)
    zeta0 = float(np.clip(width / (2 * f[p]) if np.isfinite(width) else 0.02, 2e-3, 0.2))
    peak = 10 ** (z[p] / 10)
    floor0 = max(10 ** (np.min(zz) / 10), peak * 1e-6)
    la0 = np.log10(max(peak - floor0, peak * 1e-3) * (2 * zeta0) ** 2)
    reach = max(3 * df, 2 * zeta0 * f[p])
    x0 = np.array([f[p], zeta0, la0, 0.0, 0.0, 0.0, np.log10(floor0)])
    lb = np.array([f[p] - reach, 1e-4, la0 - 6, -3.0, -3.0, -0.25 / zeta0, x0[6] - 6])
    ub = np.array([f[p] + reach, 0.3, la0 + 6, 3.0, 3.0, 0.25 / zeta0, x0[6] + 3])
    x0 = np.clip(x0, lb + 1e-9, ub - 1e-9)
    sol = least_squares(lambda x: model(x) - zz, x0, bounds=(lb, ub), x_scale=[df, 0.01, 1.0, 0.1, 0.1, 1.0, 1.0])
    ss = float(np.sum((zz - zz.mean()) ** 2)) or 1.0
    return float(sol.x[0]), float(sol.x[1]), 1.0 - float(np.sum(sol.fun ** 2)) / ss
