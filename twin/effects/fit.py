"""Fitting one candidate effect: the objective, the search, and physics-based starting values.

Runs in the diagnosis's workers (:func:`twin.effects.diagnose.diagnose`): one
:class:`TrialSpec` per candidate, fitted by :func:`fit_effect` on the candidate model's FMU.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from twin.compare import Comparison, spectral_levels
from twin.effects.catalogue import CATALOGUE, FitParameter
from twin.operating import Operating, simulate_at
from twin.signals.spectral import padded_spectrum

# ---------------------------------------------------------------------------------------------
# Evaluation of one parameter set (runs in a worker)

@dataclass(frozen=True)
class TrialSpec:
    """Everything a worker needs to fit one candidate (picklable)."""

    effect: str
    fmu_path: str
    channel: str
    measured: np.ndarray = field(repr=False)   # (n,) measured signal
    operating: Operating
    parameters: dict                            # base + active effects + neutral candidates
    guesses: dict                               # fit parameter name -> starting value
    max_evals: int = 30
    # related base parameters (FMU name -> calibrated value) refitted jointly with the effect, and
    # the evaluations that joint step may take; ``polish_only`` starts it from ``guesses`` directly
    related: dict = field(default_factory=dict)
    related_evals: int = 12
    polish_only: bool = False
    # calibrated values the related parameters stay within +-RELATED_SPAN of (default: ``related``)
    related_anchor: dict = field(default_factory=dict)
    # the search runs on the last ``search_samples`` samples of ``measured`` at the RK4 step
    # ``search_step`` [s], without the drive's retuning run; the values it finds are then scored
    # once on the whole stretch at the operating point's step (None, None: search on that directly)
    search_samples: int | None = None
    search_step: float | None = None
    # the record's known model-form error (twin.effects.baseline.Discrepancy), taken out of its levels
    discrepancy: object = None
    # the record's pinion encoder angle (n,) [rad], a second channel (twin.angular), or None
    angle: np.ndarray | None = field(default=None, repr=False)

    @property
    def channels(self) -> str | list[str]:
        """What a trial simulates: the casing channel, and the encoder's angle with an encoder."""
        return channels(self.channel, self.angle)


def channels(channel: str, angle) -> str | list[str]:
    """The FMU outputs a record is compared on: ``channel``, and the encoder angle when ``angle`` is given."""
    from twin.angular import ANGLE_OUTPUT
    return channel if angle is None else [channel, ANGLE_OUTPUT]


class _Objective:
    """LSD [dB] between a simulated and the measured signal, the measured PSD computed once.

    With the record's encoder ``angle`` (n,) [rad] the simulation is (n, 2), the casing channel
    and the model's encoder angle, and the objective is both channels' joint LSD
    (:func:`twin.angular.joint_lsd`); ``discrepancy.angle`` is the encoder's known model-form error.
    """

    def __init__(self, measured: np.ndarray, fs: float, fmin: float = 10.0, fmax: float = 5000.0,
                 resolution: float = 2.0, discrepancy=None, angle: np.ndarray | None = None):
        from twin.signals import welch_psd
        self.fs, self.n = fs, measured.size
        self.resolution = max(resolution, 4.0 * fs / self.n)
        # the whole Welch grid and PSD [Hz, units^2/Hz] kept for a discrepancy learned on this grid
        self.frequencies, self.psd = welch_psd(measured, fs, resolution=self.resolution)
        self.band = (self.frequencies >= fmin) & (self.frequencies <= min(fmax, fs / 2))
        self.pp = self.psd[self.band]
        # a known model-form error (twin.effects.baseline.Discrepancy) taken out of the measured levels
        self.offset = discrepancy.at(self.frequencies[self.band]) if discrepancy is not None else 0.0
        self.angular = None
        if angle is not None:
            from twin.angular import AngularObjective
            self.angular = AngularObjective(np.asarray(angle, float)[-self.n:], fs, self.resolution,
                                            getattr(discrepancy, "angle", None))

    def __call__(self, simulated: np.ndarray) -> float:
        from twin.angular import joint_lsd
        from twin.signals import welch_psd
        if not np.all(np.isfinite(simulated)):
            return 1e3
        casing = simulated[:, 0] if simulated.ndim == 2 else simulated
        _, pm = welch_psd(casing[: self.n], self.fs, resolution=self.resolution)
        lp, lm, _ = spectral_levels(pm[self.band], self.pp)
        lsd = float(np.sqrt(np.mean((lp - self.offset - lm) ** 2)))
        if self.angular is None:
            return lsd
        return joint_lsd(lsd, self.angular(simulated[:, 1]))


def simulate(fmu_path, parameters: Mapping[str, float], op: Operating, n: int, channel, *,
             retune: bool = True) -> np.ndarray:
    """Model signal (n,) at the measured operating point (:func:`twin.operating.simulate_at`);
    (n, k) for a list of k channels."""
    return simulate_at(fmu_path, parameters, op, n, channel, retune=retune)


def fit_effect(spec: TrialSpec) -> tuple[dict[str, float], float, int, np.ndarray]:
    """Fit one effect's parameters, then (with ``spec.related``) them and the related base ones.

    1. amplitude-like parameters on a coarse grid, then Brent;
    2. all effect parameters together (Nelder-Mead);
    3. the effect parameters and the related base parameters together (Nelder-Mead, the base
       ones within +-``RELATED_SPAN`` of their calibrated values), kept only if it lowers the LSD.

    Returns (FMU parameters: the effect's and any moved base ones, LSD [dB], evaluations, the
    simulated signal (n,) at the fit), so the caller compares the fitted model without
    simulating it again.
    """
    from scipy.optimize import minimize, minimize_scalar

    from twin.effects.catalogue import RELATED_SPAN

    eff = CATALOGUE[spec.effect]
    n = spec.measured.size
    n_search = min(n, spec.search_samples or n)
    op = spec.operating
    if spec.search_step is not None and op.solver_step is not None:
        op = replace(op, solver_step=spec.search_step)
    short = n_search < n or op != spec.operating        # search on a shorter or coarser run, score on the whole
    objective = _Objective(spec.measured[-n_search:], spec.operating.sample_rate, discrepancy=spec.discrepancy,
                           angle=None if spec.angle is None else spec.angle[-n_search:])
    fixed = dict(spec.parameters)
    params = list(eff.fit)
    free = [p for p in params if p.guess is None]
    count = 0
    cache: dict[tuple, tuple[float, np.ndarray | None]] = {}   # values -> (LSD, simulated signal)

    def start(p: FitParameter) -> float:
        default = math.sqrt(p.lower * p.upper) if p.log else 0.5 * (p.lower + p.upper)
        return float(np.clip(spec.guesses.get(p.name, default), p.lower, p.upper))

    def to_x(p: FitParameter, v: float) -> float:
        return (math.log(v / p.lower) / math.log(p.upper / p.lower)) if p.log else (v - p.lower) / (p.upper - p.lower)

    def from_x(p: FitParameter, z: float) -> float:
        z = min(max(z, 0.0), 1.0)
        return p.lower * (p.upper / p.lower) ** z if p.log else p.lower + z * (p.upper - p.lower)

    def key_of(values: Mapping[str, float], base: Mapping[str, float]) -> tuple:
        return tuple(sorted((k, round(v, 12)) for k, v in values.items())) + \
            tuple(sorted((k, round(v, 12)) for k, v in base.items()))

    def lsd(values: Mapping[str, float], base: Mapping[str, float] | None = None) -> float:
        nonlocal count
        base = base or {}
        key = key_of(values, base)
        if key not in cache:
            count += 1
            try:
                sim = simulate(spec.fmu_path, {**fixed, **base, **{eff.parameter(k): v for k, v in values.items()}},
                               op, n_search, spec.channels, retune=not short)
                cache[key] = (objective(sim), sim)
            except Exception:  # a diverging trial scores badly; it does not end the diagnosis
                cache[key] = (1e3, None)
        return cache[key][0]

    values = {p.name: start(p) for p in params} if spec.polish_only else \
        {p.name: start(p) for p in params if p.guess is not None}
    if not spec.polish_only:
        # 1) amplitude-like parameters on a coarse grid with the guessed ones held, then Brent
        for p in free:
            grid = np.linspace(0.0, 1.0, p.grid)
            scores = [lsd({**values, p.name: from_x(p, z)}) for z in grid]
            j = int(np.argmin(scores))
            lo, hi = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]
            res = minimize_scalar(lambda z: lsd({**values, p.name: from_x(p, z)}), bounds=(lo, hi),
                                  method="bounded", options={"xatol": 0.01, "maxiter": 8})
            best_z = res.x if res.fun < scores[j] else grid[j]
            values[p.name] = from_x(p, best_z)
        # 2) all parameters together (frequency-like ones move within +-5 % of their range)
        if len(params) > 1 and count < spec.max_evals:
            z0 = np.array([to_x(p, values[p.name]) for p in params])
            res = minimize(lambda z: lsd({p.name: from_x(p, zi) for p, zi in zip(params, z)}), z0,
                           method="Nelder-Mead",
                           options={"maxfev": max(spec.max_evals - count, 4), "xatol": 2e-3, "fatol": 0.01,
                                    "initial_simplex": np.vstack([z0] + [z0 + 0.05 * np.eye(len(params))[i]
                                                                         for i in range(len(params))])})
            if res.fun < lsd(values):
                values = {p.name: from_x(p, zi) for p, zi in zip(params, res.x)}
    base: dict[str, float] = {}
    # 3) the effect and its related base parameters together
    if spec.related:
        names = list(spec.related)
        anchor = np.array([float(spec.related_anchor.get(k, spec.related[k])) for k in names])
        now = np.array([float(spec.related[k]) for k in names])
        m = len(params)

        def unpack(z):
            eff_values = {p.name: from_x(p, zi) for p, zi in zip(params, z[:m])}
            rel = np.clip(z[m:], -1.0, 1.0)
            return eff_values, {k: float(v * (1 + RELATED_SPAN * r)) for k, v, r in zip(names, anchor, rel)}

        # start from the current values (an earlier step may have moved them), inside the band
        r0 = np.clip((now / np.where(anchor != 0, anchor, 1.0) - 1.0) / RELATED_SPAN, -1.0, 1.0)
        z0 = np.concatenate([[to_x(p, values[p.name]) for p in params], r0])
        steps = np.concatenate([np.full(m, 0.05), np.full(len(names), 0.5)])   # 5 % of range, 5 % of value
        simplex = np.vstack([z0] + [z0 + steps[i] * np.eye(z0.size)[i] for i in range(z0.size)])
        res = minimize(lambda z: lsd(*unpack(z)), z0, method="Nelder-Mead",
                       options={"maxfev": spec.related_evals, "xatol": 2e-3, "fatol": 0.005,
                                "initial_simplex": simplex})
        # the calibrated base values are the simplex's first vertex, so comparing costs no run
        values, base = unpack(res.x) if res.fun < lsd(*unpack(z0)) else unpack(z0)
    val = lsd(values, base)
    fitted = {eff.parameter(k): float(v) for k, v in values.items()}
    fitted.update(base)
    sim = cache[key_of(values, base)][1]
    if short and sim is not None:
        # the values found are scored on the whole stretch at the operating point's step
        count += 1
        try:
            sim = simulate(spec.fmu_path, {**fixed, **fitted}, spec.operating, n, spec.channels)
            val = _Objective(spec.measured, spec.operating.sample_rate, discrepancy=spec.discrepancy,
                             angle=spec.angle)(sim)
        except Exception:  # a fit that diverges on the whole stretch scores badly, as in the search
            sim, val = None, 1e3
    return fitted, val, count, sim


def _guarded_fit(spec: TrialSpec):
    try:
        return fit_effect(spec)
    except Exception as exc:  # reported per candidate, never ends the diagnosis
        return exc


# ---------------------------------------------------------------------------------------------
# Physics-based starting values

def starting_values(comp: Comparison, measured: np.ndarray, model: np.ndarray, fs: float,
                    shaft_hz: float, z1: int, z2: int) -> dict[str, dict[str, float]]:
    """Initial values of guessed fit parameters, per effect id, from the measured spectrum."""
    gear_hz = shaft_hz * z1 / z2
    gmf = z1 * shaft_hz
    f, am = padded_spectrum(measured, fs)
    _, ao = padded_spectrum(model, fs)
    excess = 20 * np.log10((am + 1e-30) / (ao + 1e-30))
    lock_tol = max(0.1, 0.3 * fs / measured.size)      # as in twin.compare

    def locked(fr: float) -> bool:
        return any(abs(fr / s - round(fr / s)) * s <= lock_tol for s in (shaft_hz, gear_hz))

    out: dict[str, dict[str, float]] = {}
    # strongest measured line in 20-400 Hz that is locked to no shaft, weighted by its excess
    band = (f >= 20) & (f <= 400)
    idx = np.flatnonzero(band)
    # what the measurement has beyond the model (a ratio would blow up in the model's spectral nulls)
    order = idx[np.argsort(-np.clip(am[idx] - ao[idx], 0, None))]
    for j in order[:200]:
        if not locked(f[j]):
            out["motor_torque_ripple"] = {"frequency": float(f[j])}
            break
    # a torque ripple turns the drive train at its own frequency: a line the encoder shows locked
    # to no shaft, above the model, is the better guess (the casing may hardly see it)
    angular = getattr(comp, "angular", None)
    unlocked = [fd for fd in (angular.findings if angular is not None else ()) if fd.order is None and fd.size_db > 0]
    if unlocked:
        out["motor_torque_ripple"] = {"frequency": float(max(unlocked, key=lambda fd: fd.size_db).frequency_hz)}
    # slow modulation: excess beside the first mesh harmonics at offsets of 0.5-15 Hz
    offsets = np.arange(0.5, 15.0, 0.05)
    score = np.zeros_like(offsets)
    for k in (1, 2, 3):
        for s in (-1, 1):
            fq = k * gmf + s * offsets
            score += np.interp(fq, f, np.clip(excess, 0, None))
    for j in np.argsort(-score):
        if not locked(offsets[j]):
            out["load_torque_fluctuation"] = {"frequency": float(offsets[j])}
            break
    # resonance: centre of the largest lifted band
    # a mode in the path lifts whatever lies in its band: the lifted region, or else the line
    # findings that are most above the model
    res = [fd for fd in comp.findings if fd.kind == "resonance" and fd.size_db > 0]
    lifted = [fd for fd in comp.findings if fd.kind in ("mesh_harmonic", "sideband") and fd.size_db > 0]
    if res:
        fc = max(res, key=lambda fd: fd.share).frequency_hz
    elif lifted:
        fc = max(lifted, key=lambda fd: fd.size_db).frequency_hz
    else:
        sm = np.convolve(excess, np.ones(257) / 257, mode="same")
        win = (f >= 300) & (f <= 4800)
        fc = float(f[win][np.argmax(sm[win])])
    out["housing_mode"] = {"frequency": float(fc)}
    return out
