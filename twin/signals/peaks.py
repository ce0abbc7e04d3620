"""Peaks of a stationary dB spectrum told apart: lines against resonances, and a resonance's fit.

Steps 4 and 5 of :func:`twin.signals.runup.analyse_runup` (see :mod:`twin.signals.runup`): a
peak's -3 dB width, its fluctuation from slice to slice (is it deterministic, a line, or a
randomly excited resonance?), the cut of lines out of the spectrum as wide as their Hann leakage
reaches, and the single-mode fit of a resonance's hump (frequency, damping, their scatter).
:mod:`twin.signals.fdd` reads the same helpers on its singular-value spectra.

Frequencies in Hz, levels in dB.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy import signal as sps
from scipy.optimize import least_squares

from twin.signals.survey import Line, Mode

if TYPE_CHECKING:
    from twin.signals.runup import _View


#: Robust (MAD-based) sd [dB] of one periodogram bin of a Gaussian random process about a fitted
#: trend (a log-exponential variable: 5.0 dB, a little less once the trend is fitted).
RANDOM_BIN_SD_DB = 4.6
#: -3 dB width of a sinusoid's peak under a Hann window, in bins, off-bin worst case about 2.
LINE_WIDTH_BINS = 2.5


def _robust_sd(v: np.ndarray) -> float:
    v = v[np.isfinite(v)]
    if v.size < 3:
        return float("nan")
    return float(1.4826 * np.median(np.abs(v - np.median(v))))


def _fluctuation_db(raw_db: np.ndarray, masked: np.ndarray, k: int) -> float:
    """Robust sd [dB] of bin k's level over the unmasked slices, about a quadratic trend in time."""
    v = raw_db[k].copy()
    v[masked[k]] = np.nan
    t = np.arange(v.size, dtype=float)
    ok = np.isfinite(v)
    if ok.sum() < 5:
        return float("nan")
    coef = np.polyfit(t[ok], v[ok], 2)
    return _robust_sd(v[ok] - np.polyval(coef, t[ok]))


def _half_power_width(f: np.ndarray, z: np.ndarray, k: int) -> float:
    """-3 dB width [Hz] of the peak at bin k of a dB spectrum (inf if it never falls 3 dB)."""
    target = z[k] - 3.0103
    edges = []
    for step in (-1, 1):
        i = k
        while 0 <= i + step < z.size and z[i + step] > target:
            i += step
        j = i + step
        if not 0 <= j < z.size:
            return float("inf")
        edges.append(f[i] + (z[i] - target) / (z[i] - z[j]) * (f[j] - f[i]))
    return float(edges[1] - edges[0])


_KERNEL_STEP = 0.125
_KERNEL_OFFSETS = np.arange(-4.0, 4.0 + _KERNEL_STEP / 2, _KERNEL_STEP)


def _hann_power_kernel(delta: np.ndarray) -> np.ndarray:
    """|W(delta)|^2 of the Hann window at ``delta`` bins from a line, normalised to unit sum."""
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.sinc(delta) / (1.0 - delta ** 2)
    w[np.isclose(np.abs(delta), 1.0)] = 0.5
    k = w ** 2
    return k / k.sum()


_KERNEL = _hann_power_kernel(_KERNEL_OFFSETS)


def _sdof_fit(f: np.ndarray, z: np.ndarray, k: int, lo: int, hi: int, df: float
              ) -> tuple[float, float, float, float]:
    """Single-mode fit of a hump in a dB spectrum over bins [lo, hi): (fn [Hz], zeta, R^2, sd of fn [Hz]).

    Model: 10 log10(a^2 |1 / (1 - r^2 + 2j zeta r) + beta|^2 + n), r = f / fn, seen through the
    Hann window (the model power is convolved with the window's power kernel before it is
    compared with the bins, so a hump narrower than a bin still gives its centre). ``beta`` is
    the other modes' contribution near this one, nearly real away from their own resonances (in
    or out of phase); it shifts the response peak away from the natural frequency, by up to a few
    per cent when modes are close, so it is fitted rather than ignored. ``n`` is the floor of
    incoherent content. ``zeta`` is NaN when the hump is not resolved (narrower than a bin).
    """
    ff, zz = f[lo:hi], z[lo:hi]
    if ff.size < 6:
        return float(f[k]), float("nan"), 0.0, float(df)
    fpk = f[k]
    width = _half_power_width(f, z, k)
    zeta0 = float(np.clip(width / (2 * fpk) if np.isfinite(width) else 0.02, 2e-3, 0.2))
    peak = 10 ** (z[k] / 10)
    floor0 = max(10 ** (np.min(zz) / 10), peak * 1e-6)
    la0 = np.log10(max(peak - floor0, peak * 1e-3) * (2 * zeta0) ** 2)
    grid = ff[:, None] + _KERNEL_OFFSETS[None, :] * df

    def model(p):
        fn, zeta, la, beta, ln = p
        r = grid / fn
        h = 1.0 / (1 - r * r + 2j * zeta * r) + beta
        return 10 * np.log10((10 ** la * np.abs(h) ** 2) @ _KERNEL + 10 ** ln)

    reach = max(3 * df, 2 * zeta0 * fpk)
    p0 = np.array([_parabolic(f, z, k), zeta0, la0, 0.0, np.log10(floor0)])
    lb = np.array([fpk - reach, 1e-4, la0 - 6, -0.25 / zeta0, p0[4] - 6])
    ub = np.array([fpk + reach, 0.3, la0 + 6, 0.25 / zeta0, p0[4] + 3])
    p0 = np.clip(p0, lb + 1e-9, ub - 1e-9)
    sol = least_squares(lambda p: model(p) - zz, p0, bounds=(lb, ub), x_scale=[df, 0.01, 1.0, 1.0, 1.0])
    ss = float(np.sum((zz - zz.mean()) ** 2)) or 1.0
    r2 = 1.0 - float(np.sum(sol.fun ** 2)) / ss
    fn, zeta = float(sol.x[0]), float(sol.x[1])
    # standard error of fn from the fit's Jacobian and residual scatter (bins are correlated by
    # the window and the smoothing, about 3 to one independent value, hence the factor)
    dof = max(ff.size - 5, 1)
    try:
        cov = np.linalg.pinv(sol.jac.T @ sol.jac) * (float(np.sum(sol.fun ** 2)) / dof) * 3.0
        fn_sd = float(np.sqrt(max(cov[0, 0], 0.0)))
    except np.linalg.LinAlgError:
        fn_sd = float(df)
    # a half-power band narrower than half a bin is not resolved by these slices
    return fn, (zeta if 2 * zeta * fn >= 0.5 * df else float("nan")), r2, max(fn_sd, 0.05 * df)


def _cut_lines(f: np.ndarray, z: np.ndarray, lines) -> np.ndarray:
    """z with each line's bins replaced by a straight line between its neighbours (see _line_cuts)."""
    out = z.copy()
    for lo, hi in _line_cuts(f, z, lines):
        out[lo:hi] = np.interp(f[lo:hi], [f[lo - 1], f[hi]], [out[lo - 1], out[hi]])
    return out


def _line_cuts(f: np.ndarray, z: np.ndarray, lines) -> list[tuple[int, int]]:
    """Bins [lo, hi) each line of a dB spectrum z covers.

    The cut is as wide as the line's window leakage reaches above the level around it: a
    line 40 dB above a resonance hump leaks over +-5 bins of a Hann window, one 10 dB above it
    over +-2.
    """
    df = f[1] - f[0]
    cuts = []
    for ln in lines:
        p = int(round(ln.frequency / df))
        if not 1 <= p < f.size - 1:
            continue
        height = max(_excess_db(z, p), 0.0)
        reach = _KERNEL_OFFSETS[_KERNEL_OFFSETS >= 0]
        leak = 10 * np.log10(np.maximum(_KERNEL[_KERNEL_OFFSETS >= 0] / _KERNEL.max(), 1e-30)) + height
        h = int(np.ceil(reach[np.flatnonzero(leak > 0.0)].max() if (leak > 0.0).any() else 1.0))
        h = max(2, min(h + 1, 8))
        cuts.append((max(p - h, 1), min(p + h + 1, f.size - 1)))
    return cuts


def _shaft_harmonic(fc: float, speed, df: float) -> float | None:
    """The integer order at fc for a (nearly) constant speed, if fc sits on one; else None."""
    if speed is None:
        return None
    s = float(np.median(speed))
    k = round(fc / s)
    if k >= 1 and abs(fc - k * s) <= 1.5 * df + 0.5 * k * float(np.ptp(speed)):
        return float(k)
    return None


def _parabolic(f, z, k) -> float:
    if 0 < k < z.size - 1:
        a, b, c = z[k - 1], z[k], z[k + 1]
        den = a - 2 * b + c
        if den < 0:
            return float(f[k] + 0.5 * (a - c) / den * (f[1] - f[0]))
    return float(f[k])


def _excess_db(z: np.ndarray, k: int) -> float:
    """Height [dB] of bin k above its neighbourhood (bins 3-8 away on both sides)."""
    near = np.r_[z[max(k - 8, 0):max(k - 2, 0)], z[k + 3:k + 9]]
    return float(z[k] - np.median(near)) if near.size else 0.0


def _steadiness(raw, masked, z, k) -> tuple[bool, float, float]:
    """Is the narrow peak at bin k deterministic? (steady, measured sd [dB], sd a line would have [dB]).

    A line of power A^2 over random content of power N in its bin fluctuates by about
    6.14 / sqrt(A^2 / N) dB from slice to slice; a randomly excited bin by about 4.6 dB (robust
    sd of a log-exponential variable about a fitted trend). The peak is taken as steady when its
    measured fluctuation is nearer (geometrically) to the line's than to the random bin's.
    """
    fluct = _fluctuation_db(raw, masked, k)
    snr = 10 ** (max(_excess_db(z, k), 0.0) / 10)
    line_sd = min(6.14 / np.sqrt(max(snr - 1.0, 1e-3)), RANDOM_BIN_SD_DB)
    limit = float(np.sqrt(line_sd * RANDOM_BIN_SD_DB))
    return bool(np.isfinite(fluct) and fluct < limit), fluct, line_sd


def _find_lines(view: _View, threshold: np.ndarray, orders) -> tuple[list[Line], np.ndarray]:
    """Narrow, steady peaks; returns (lines, stationary spectrum with the lines cut out)."""
    f, z, df = view.f, view.stationary, view.df
    lines = []
    peaks, props = sps.find_peaks(z[view.band], prominence=0.0)
    for p in view.band[peaks[props["prominences"] >= threshold[view.band[peaks]]]]:
        width = _half_power_width(f, z, p)
        if width > LINE_WIDTH_BINS * df:
            continue
        steady, fluct, line_sd = _steadiness(view.raw, view.masked, z, p)
        if not steady:
            continue
        fc = _parabolic(f, z, p)
        if not orders and _shaft_harmonic(fc, view.speed, df) is not None:
            lines.append(Line(fc, float(z[p]), float(width), {"shaft_harmonic": True}))
            continue
        lines.append(Line(fc, float(z[p]), float(width),
                          {"slice_level_sd_db": round(fluct, 2), "line_sd_db": round(line_sd, 2),
                           "width_bins": round(float(width / df), 2),
                           "reason": "narrow, fixed in frequency and steady from slice to slice (deterministic)"}))
    cleaned = _cut_lines(f, z, lines)
    return [ln for ln in lines if not ln.evidence.get("shaft_harmonic")], cleaned


def _crossing_orders(fn: float, speed, orders) -> list[float]:
    if speed is None:
        return []
    return [o.order for o in orders if o.order * speed.min() < fn < o.order * speed.max()]


def _find_modes(view: _View, cleaned: np.ndarray, shape: np.ndarray, threshold: np.ndarray, orders,
                lines) -> list[Mode]:
    """Resonances: every peak of the line-free stationary spectrum that is not narrow and steady."""
    f, df, band = view.f, view.df, view.band
    peaks, props = sps.find_peaks(cleaned[band], prominence=0.0)
    keep = props["prominences"] >= threshold[band[peaks]]
    idx = band[peaks[keep]]
    prominence = props["prominences"][keep]
    modes = []
    for j, (p, prom) in enumerate(zip(idx, prominence)):
        width = _half_power_width(f, cleaned, p)
        narrow = np.isfinite(width) and width <= LINE_WIDTH_BINS * df
        if narrow:
            steady, fluct, _ = _steadiness(view.raw, view.masked, cleaned, p)
            if steady:
                continue    # narrow and steady: a line, not a mode
        else:
            fluct = _fluctuation_db(view.raw, view.masked, p)
        # fit window: the hump, limited to half-way to the neighbouring peaks
        reach = int(np.clip(np.ceil(2.5 * (width if np.isfinite(width) else 4 * df) / df), 4, 200))
        lo = max(p - reach, (idx[j - 1] + p) // 2 if j > 0 else band[0], 1)
        hi = min(p + reach + 1, (idx[j + 1] + p) // 2 + 1 if j + 1 < idx.size else band[-1] + 1)
        fn, zeta, r2, fn_sd = _sdof_fit(f, shape, p, lo, hi, df)
        unmasked = ~view.masked[p]
        present = float(np.mean(view.norm[p, unmasked] > 0.5 * prom)) if unmasked.any() else 0.0
        # confidence: how far the hump clears the noise of the spectrum, how often it is there,
        # how well one mode explains its shape; a narrow random peak is a weaker case than a hump
        clear = 1.0 - np.exp(-((prom / (2.0 * threshold[p])) ** 2))
        conf = clear * (0.4 + 0.6 * present) * (0.6 + 0.4 * max(r2, 0.0)) * (0.7 if narrow else 1.0)
        evidence = {"width_hz": round(float(width), 3) if np.isfinite(width) else None,
                    "slice_level_sd_db": round(float(fluct), 2) if np.isfinite(fluct) else None,
                    "persistence": round(present, 3), "fit_r2": round(r2, 3),
                    "frequency_sd_hz": round(fn_sd, 3), "resolution_hz": round(float(df), 4),
                    "orders_crossing": _crossing_orders(fn, view.speed, orders),
                    "reason": ("a hump wider than a line, fixed in frequency" if not narrow else
                               "narrow but random from slice to slice: a lightly damped resonance")}
        reach_hz = max(3 * df, 3 * width if np.isfinite(width) else 0.0)
        near = [ln.frequency for ln in lines if abs(ln.frequency - fn) <= reach_hz]
        if near:
            evidence["line_on_top_hz"] = [round(v, 2) for v in near]
        modes.append(Mode(float(fn), float(zeta), float(np.clip(conf, 0.0, 1.0)), float(prom), evidence))
    return sorted(modes, key=lambda m: m.frequency)
