"""The modes objective and its least-squares fit in log-parameters, with the physical bounds as prior.

Each measured mode ``i`` (uncertainty ``s_i``, relative) is compared with the model mode paired
with it (:func:`twin.calibration.sensitivity.match_measured`; by default the nearest visible model
mode by frequency): ``z_i = ln(f_model / f_measured) / s_i``. With the opt-in shape pairing
(``pairing="shape"``), when the measured mode's shape at the sensors is known, ``z_i^2`` gains
``(m_i * 0.15 / s_i)^2`` with ``m_i = coherence_i (1 - MAC)`` the pairing's shape mismatch: a model mode of the wrong shape near the right frequency costs as much as one of
the right shape 15 % off, so the objective does not reward the wrong physics. A measured mode left
without a model mode within 15 % costs ``(0.15 / s_i)^2``, so a candidate cannot improve by losing
a mode.

The objective of a population member pairs the modes at that member. The fit instead
matches once, at its start, and follows each model mode by its shape (MAC) from step to step:
re-matching by frequency at every step would let two modes swap identities whenever that lowers
the cost, and the fit would then chase the wrong mode. It re-matches at its own solution and
goes on if the match changed there.

The fit works in ``u_j = ln(p_j / p_nominal_j)`` inside the physical bounds and adds one prior
residual per parameter, ``u_j / h_j`` (``h_j`` half the log-range of its bounds): a parameter the
modes do not pin down stays near its nominal value instead of drifting to a bound, and one that
ends on a bound does so because the modes pull it there -- which the report flags, since it
means the model's structure cannot reach the rig's modes within physics.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from twin.calibration.pairing import MeasuredShapes, Pairing, shape_mismatch
from twin.calibration.model_modes import ModelModes, model_modes
from twin.calibration.sensitivity import MATCH_REACH, follow_index, match_measured


def mode_errors(model: ModelModes, measured: np.ndarray, rel_sd: np.ndarray, shapes: MeasuredShapes | None = None,
                *, pairing: str = "frequency") -> tuple[np.ndarray, np.ndarray]:
    """(z (k,), matched model frequency (k,) [Hz], NaN where unmatched); ``shapes`` count only with
    ``pairing="shape"``."""
    idx = match_measured(model, measured, rel_sd, pairing=pairing, shapes=shapes)
    matched = np.where(idx >= 0, model.frequency[np.maximum(idx, 0)], np.nan)
    z = np.where(idx >= 0, np.log(np.where(idx >= 0, matched, 1.0) / measured) / rel_sd, MATCH_REACH / rel_sd)
    if pairing == "shape" and shapes is not None and (idx >= 0).any():
        ok = np.flatnonzero(idx >= 0)
        m = shape_mismatch(model, shapes, idx[ok])[ok, np.arange(ok.size)]
        z[ok] = np.where(z[ok] >= 0, 1.0, -1.0) * np.hypot(z[ok], m * MATCH_REACH / rel_sd[ok])
    return z, matched


def modes_objective(fmu_path, values: Mapping[str, float], measured, rel_sd, *, speed_hz: float, load_nm: float,
                    channels=("accel_pinion_casing",), shapes: MeasuredShapes | None = None,
                    pairing: str = "frequency", visibility: str = "mesh") -> tuple[float, np.ndarray]:
    """Mean squared z over the measured modes, and the matched model frequencies [Hz]."""
    mm = model_modes(fmu_path, values, speed_hz=speed_hz, load_nm=load_nm, channels=channels, visibility=visibility)
    z, matched = mode_errors(mm, np.asarray(measured, float), np.asarray(rel_sd, float), shapes, pairing=pairing)
    return float(np.mean(z ** 2)), matched


def fit_modes(fmu_path, names, lower, upper, nominal, x0, measured, rel_sd, *, fixed: Mapping[str, float],
              speed_hz: float, load_nm: float, channels=("accel_pinion_casing",), max_iter: int = 15,
              shapes: MeasuredShapes | None = None, pairing: str = "frequency",
              start_pairing: Pairing | None = None, visibility: str = "mesh") -> np.ndarray:
    """Fit of the parameters ``names`` to the measured modes by damped Gauss-Newton (Levenberg-
    Marquardt) in log-parameters with the bounds' prior; returns the values (d,).

    The modes are paired at ``x0`` (by the rule ``pairing``, see :func:`mode_errors`) and followed
    step by step from there: each accepted step becomes the reference for the next, so a mode
    keeps its identity through changes far larger than one step, where a single shape comparison
    could confuse two modes that veer. At the solution the pairing is made again; if it differs,
    the fit goes on from there with the new pairing (at most twice). ``start_pairing`` (from the
    shape pairing's sensitivity study, where each model mode's reach is known) replaces the first
    pairing: it may pair a measured mode with a model mode further than 15 % away that the bounds
    let reach it.
    """
    lower, upper, nominal = (np.asarray(v, float) for v in (lower, upper, nominal))
    lo, hi = np.log(lower / nominal), np.log(upper / nominal)
    half = 0.5 * (hi - lo)
    measured = np.asarray(measured, float)
    rel_sd = np.asarray(rel_sd, float)
    kw = dict(speed_hz=speed_hz, load_nm=load_nm, channels=channels, visibility=visibility)

    def at(u):
        return model_modes(fmu_path, {**fixed, **{n: float(v) for n, v in zip(names, nominal * np.exp(u))}}, **kw)

    def residual(ref, which, model):
        z = np.full(measured.size, 0.0)
        ok = which >= 0
        z[~ok] = MATCH_REACH / rel_sd[~ok]
        idx = follow_index(ref, model, which[ok]) if ok.any() else np.array([], int)
        z[ok] = np.log(model.frequency[idx] / measured[ok]) / rel_sd[ok]
        return z, idx

    u = np.clip(np.log(np.asarray(x0, float) / nominal), lo, hi)
    ref = at(u)
    which = (start_pairing.at(ref) if start_pairing is not None
             else match_measured(ref, measured, rel_sd, pairing=pairing, shapes=shapes))
    for _ in range(3):
        u, ref, which = _levenberg_marquardt(at, residual, u, ref, which, lo, hi, half, max_iter)
        again = match_measured(ref, measured, rel_sd, pairing=pairing, shapes=shapes)
        if np.array_equal(again, which):
            break
        which = again
    return nominal * np.exp(u)


def _levenberg_marquardt(at, residual, u, ref, which, lo, hi, half, max_iter, h: float = 0.01):
    """Projected Levenberg-Marquardt on [z; u / half], the modes followed from accepted step to step."""
    def full(z, v):
        return np.concatenate([z, v / half])

    z, _ = residual(ref, which, ref)
    r = full(z, u)
    cost = float(r @ r)
    lam = 1e-2
    for _ in range(max_iter):
        J = np.empty((r.size, u.size))
        for j in range(u.size):
            step = h if u[j] + h <= hi[j] else -h
            v = u.copy()
            v[j] += step
            zj, _ = residual(ref, which, at(v))
            J[:, j] = (full(zj, v) - r) / step
        g = J.T @ r
        H = J.T @ J
        improved = False
        for _ in range(6):
            du = np.linalg.solve(H + lam * np.diag(np.diag(H) + 1e-9), -g)
            v = np.clip(u + du, lo, hi)
            trial = at(v)
            zt, idx = residual(ref, which, trial)
            rt = full(zt, v)
            if float(rt @ rt) < cost:
                new_which = which.copy()
                new_which[which >= 0] = idx
                u, ref, which, r = v, trial, new_which, rt
                improved = float(rt @ rt) < cost * (1 - 1e-4)
                cost = float(rt @ rt)
                lam = max(lam / 3, 1e-6)
                break
            lam *= 5
        if not improved:
            break
    return u, ref, which


def on_bounds(names, values, lower, upper, *, tol: float = 0.01) -> list[str]:
    """Names of the parameters within ``tol`` (relative, in log) of a bound."""
    out = []
    for n, v, lo, hi in zip(names, values, lower, upper):
        span = math.log(hi / lo)
        if math.log(v / lo) <= tol * span or math.log(hi / v) <= tol * span:
            out.append(n)
    return out
