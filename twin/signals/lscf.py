"""Modes from a matrix of FRFs by the poly-reference least-squares complex frequency-domain method.

Peak picking reads one mode per hump of one FRF. Two modes a few per cent apart whose half-power
bands overlap (a shaft's two lateral modes, a pair of casing panels) make one hump, so one of them is
lost. A parametric fit of all FRFs at once separates them: the FRF matrix ``H(f)`` (outputs x
references) is modelled as a right matrix fraction

    H_o(w) = B_o(w) A(w)^-1,   A(w) = sum_r Omega_r(w) alpha_r,   B_o(w) = sum_r Omega_r(w) beta_o,r

with the z-domain basis ``Omega_r = exp(i w r dt)`` (dt = 1 / (2 f_b) for a band ending at f_b),
real matrix coefficients ``alpha_r`` (references x references) and ``beta_o,r`` (1 x references).
The linearised error ``W_o (B_o - H_o A)`` is least squares in the coefficients; the numerator is
eliminated per output (the reduced normal equations), ``alpha_p = I`` fixes the scale, and the poles
are the eigenvalues of the block companion matrix of ``A``: ``z = exp(lambda dt)``. This is the
LSCF estimator (Guillaume, Verboven, Vanlanduit, Van der Auweraer, Peeters, Proc. IMAC XXI, 2003) in
its poly-reference form (Peeters, Van der Auweraer, Guillaume, Leuridan, Shock and Vibration 11
(2004) 395-409).

A fit of order p gives p x references poles, most of them mathematical (they fit noise). Physical
poles come back at the same frequency and damping as the order grows (the stabilisation diagram):
a pole at order p is *stable* when order p - 1 has one within ``FREQ_TOL`` in frequency and
``DAMP_TOL`` (relative) in damping. Stable poles are grouped by frequency; a group seen at a share
``MIN_STABLE`` or more of the orders is a mode, at the median frequency and damping of its poles.

The band is fitted in overlapping sub-bands (each ``BAND_RATIO`` wide, every frequency in
``BAND_OVERLAP`` of them) so that a moderate order covers the modes of each; a mode found in
several sub-bands is kept once, from the band where it was the most stable.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.signals._checks import SignalError

#: Highest matrix-polynomial order of the stabilisation diagram (poles: order x references).
MAX_ORDER = 24
#: Lowest order of the diagram.
MIN_ORDER = 4
#: A pole is stable when the previous order has one within this relative frequency ...
FREQ_TOL = 0.005
#: ... and this relative damping.
DAMP_TOL = 0.10
#: Share of the diagram's orders a group of stable poles must be seen at to be a mode.
MIN_STABLE = 0.4
#: Width of one sub-band, as the ratio of its upper to its lower edge.
BAND_RATIO = 1.6
#: Damping ratios outside (0, MAX_DAMPING] are not structural modes of a gearbox.
MAX_DAMPING = 0.15


@dataclass(frozen=True)
class StablePole:
    """A mode from the stabilisation diagram: frequency [Hz], damping ratio [-], the share of
    orders it was stable at (0..1), the band [Hz] it was fitted in and the spread (sd) of its
    stable poles' frequencies [Hz]."""

    frequency: float
    damping: float
    stability: float
    band: tuple[float, float]
    frequency_sd: float = 0.0


def lscf_poles(f: np.ndarray, H: np.ndarray, weight: np.ndarray, order: int, f_top: float) -> np.ndarray:
    """Continuous-time poles [rad/s] of a poly-reference LSCF fit of ``order``.

    f : (n_f,) frequencies [Hz] of the band fitted; H : (n_f, n_out, n_ref) complex FRFs;
    weight : (n_f, n_out) non-negative weights of each output's equations; f_top : the band's upper
    edge [Hz] (sets dt = 1 / (2 f_top)). Returns the order x n_ref poles (complex, any sign).
    """
    n_f, n_out, n_ref = H.shape
    dt = 0.5 / f_top
    omega = np.exp(1j * 2 * np.pi * np.outer(f, np.arange(order + 1)) * dt)          # (n_f, p+1)
    size = (order + 1) * n_ref
    M = np.zeros((size, size))
    for o in range(n_out):
        w = weight[:, o][:, None]
        X = w * omega                                                                  # (n_f, p+1)
        # Y row k: -w_k [Omega_0 H_o, ..., Omega_p H_o] (each H_o is 1 x n_ref)
        Y = -(w[:, :, None] * omega[:, :, None] * H[:, o, None, :]).reshape(n_f, size)
        R = np.real(X.conj().T @ X)
        S = np.real(X.conj().T @ Y)
        T = np.real(Y.conj().T @ Y)
        M += T - S.T @ np.linalg.solve(R, S)
    k = order * n_ref
    alpha = -np.linalg.lstsq(M[:k, :k], M[:k, k:], rcond=None)[0]                      # (p n_ref, n_ref)
    companion = np.zeros((k, k))
    if order > 1:
        companion[:-n_ref, n_ref:] = np.eye(k - n_ref)
    # last block row: -[alpha_0, ..., alpha_(p-1)] side by side (A(z) v = 0 with alpha_p = I)
    companion[-n_ref:, :] = -alpha.reshape(order, n_ref, n_ref).transpose(1, 0, 2).reshape(n_ref, k)
    z = np.linalg.eigvals(companion)
    z = z[np.abs(z) > 0]
    return np.log(z) / dt


def _physical(poles: np.ndarray, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [Hz] and damping ratios of the poles that can be modes in [lo, hi]."""
    poles = poles[np.imag(poles) > 0]
    fn = np.abs(poles) / (2 * np.pi)
    zeta = -np.real(poles) / np.maximum(np.abs(poles), np.finfo(float).tiny)
    keep = (fn >= lo) & (fn <= hi) & (zeta > 0) & (zeta <= MAX_DAMPING)
    order = np.argsort(fn[keep])
    return fn[keep][order], zeta[keep][order]


def stable_modes_in_band(f: np.ndarray, H: np.ndarray, weight: np.ndarray, lo: float, hi: float, *,
                         min_order: int = MIN_ORDER, max_order: int = MAX_ORDER) -> list[StablePole]:
    """The stable modes of the stabilisation diagram of band [lo, hi] [Hz] (see the module docstring)."""
    band = (f >= lo) & (f <= hi)
    n_out, n_ref = H.shape[1], H.shape[2]
    # the denominator has order x n_ref^2 unknowns, fitted to n_bins x n_out x n_ref complex values
    # (after eliminating the numerators): a diagram needs at least a few equations per unknown
    max_order = min(max_order, int(band.sum()) * n_out // n_ref // 2)
    if max_order < min_order + 4:
        return []
    fb, Hb, wb = f[band], H[band], weight[band]
    previous: tuple[np.ndarray, np.ndarray] | None = None
    stable_f, stable_z = [], []
    orders = range(min_order, max_order + 1)
    for p in orders:
        try:
            fn, zeta = _physical(lscf_poles(fb, Hb, wb, p, hi), lo, hi)
        except np.linalg.LinAlgError:
            previous = None
            continue
        if previous is not None and fn.size and previous[0].size:
            for a, b in zip(fn, zeta):
                j = int(np.argmin(np.abs(previous[0] - a)))
                if abs(previous[0][j] - a) <= FREQ_TOL * a and abs(previous[1][j] - b) <= DAMP_TOL * b:
                    stable_f.append(a)
                    stable_z.append(b)
        previous = (fn, zeta)
    if not stable_f:
        return []
    idx = np.argsort(stable_f)
    sf, sz = np.asarray(stable_f)[idx], np.asarray(stable_z)[idx]
    groups, start = [], 0
    for i in range(1, sf.size + 1):
        if i == sf.size or sf[i] - sf[i - 1] > FREQ_TOL * sf[i - 1]:
            groups.append((start, i))
            start = i
    n_orders = len(orders) - 1
    modes = []
    for a, b in groups:
        share = min(1.0, (b - a) / n_orders)
        if share >= MIN_STABLE:
            modes.append(StablePole(float(np.median(sf[a:b])), float(np.median(sz[a:b])), float(share),
                                    (float(lo), float(hi)), float(np.std(sf[a:b]))))
    return modes


#: Sub-bands start every BAND_RATIO ** (1 / BAND_OVERLAP): each frequency lies in that many bands.
BAND_OVERLAP = 3


def sub_bands(fmin: float, fmax: float, ratio: float = BAND_RATIO) -> list[tuple[float, float]]:
    """Overlapping sub-bands [Hz] covering [fmin, fmax], each ``ratio`` wide, starting every
    ``ratio ** (1 / BAND_OVERLAP)``: a mode near one band's edge (where a fit is poor) lies well
    inside another."""
    if not (0 < fmin < fmax):
        raise SignalError(f"the band must satisfy 0 < fmin < fmax, got {fmin!r}, {fmax!r}")
    bands, lo = [], fmin
    while True:
        hi = min(lo * ratio, fmax)
        bands.append((lo, hi))
        if hi >= fmax:
            return bands
        lo *= ratio ** (1.0 / BAND_OVERLAP)


def lscf_modes(f, H, coherence, fmin: float, fmax: float, *, max_order: int = MAX_ORDER) -> list[StablePole]:
    """Stable modes [Hz] of the FRF matrix over [fmin, fmax], one per physical pole.

    f : (n_f,) [Hz]; H : (n_f, n_out, n_ref) complex FRFs (a 1-D or 2-D array is one output / one
    reference); coherence : like H but real in [0, 1] (each FRF's ordinary coherence), or None.
    Each output's equations are weighted by sqrt(coherence) over its median FRF magnitude in the
    band, so every sensor counts alike and incoherent bins little. Modes found in two overlapping
    sub-bands within ``FREQ_TOL`` are kept once (the more stable).
    """
    f = np.asarray(f, float)
    H = np.asarray(H, complex)
    while H.ndim < 3:
        H = H[..., None]
    if H.shape[0] != f.size:
        raise SignalError(f"the FRFs have {H.shape[0]} frequencies, f has {f.size}")
    coh = np.ones(H.shape) if coherence is None else np.asarray(coherence, float).reshape(H.shape)
    ok = np.all(np.isfinite(H), axis=(1, 2)) & np.all(np.isfinite(coh), axis=(1, 2)) & (f > 0)
    f, H, coh = f[ok], H[ok], coh[ok]
    found: list[StablePole] = []
    for lo, hi in sub_bands(fmin, fmax):
        band = (f >= lo) & (f <= hi)
        if not band.any():
            continue
        scale = np.median(np.abs(H[band]), axis=0).mean(axis=1)                       # (n_out,)
        weight = np.sqrt(np.clip(coh, 0.0, 1.0)).mean(axis=2) / np.maximum(scale, np.finfo(float).tiny)
        for m in stable_modes_in_band(f, H, weight, lo, hi, max_order=max_order):
            same = [i for i, o in enumerate(found) if abs(o.frequency - m.frequency) <= 2 * FREQ_TOL * m.frequency]
            if not same:
                found.append(m)
            elif m.stability > found[same[0]].stability:
                found[same[0]] = m
    return sorted(found, key=lambda m: m.frequency)
