"""The calibrated model's own discrepancy, learned on records of the gearbox as it was calibrated.

A twin calibrated to a gearbox it did not generate keeps a model-form error: modes it lacks, a
transfer path that is not the gearbox's, mesh lines at other levels. That error is in every
record of the gearbox, and on a rig it dwarfs what one missing effect adds (the calibrated
base stands 9-29 dB from the rigs' records, a run-out adds ~14 dB at a few sidebands), so a
flexible candidate fitted to the whole discrepancy absorbs the base's error instead of finding
the effect. Records of the same gearbox taken before the effect (the records the twin was
calibrated on) measure that error:

    delta(f) = L_measured,baseline(f) - L_model,baseline(f)   [dB]

with the model simulated at the baseline record's own operating point, the levels those the
diagnosis compares (:func:`twin.compare.spectral_levels`: Welch PSDs floored 3 dB above the
measured noise, the model with that noise added and its gain aligned): where the measurement is
only noise, delta is 0. A later record is then
read through the model's eyes: its spectrum less delta, so that what stands between it and the
model is what changed since (the missing effect) plus the estimates' scatter, and the candidates
are fitted and judged on that. This is a model-discrepancy term learned on reference data
(Kennedy and O'Hagan, J. R. Stat. Soc. B 63, 2001, 425-464), kept fixed while the effect is
sought.

Speeds differ between records (a drive's speed scatters by a few 0.1 %, which moves the 10th
mesh harmonic by several 2 Hz bins), so delta is carried in shaft orders: at frequency f of a
record turning at s, the correction is delta(f s_baseline / s). Content fixed in frequency
(resonances) then moves by the speed ratio, a few 0.1 %, well inside a resonance's half-power
band.

Frequencies in Hz, speeds in Hz (pinion), levels in dB.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

#: Bound of the learned discrepancy [dB]: beyond it a bin holds no information the
#: correction could use (a model line 60 dB under the measured floor, say).
MAX_DB = 60.0


@dataclass(frozen=True)
class Discrepancy:
    """The model's discrepancy on one baseline record (measured minus model level [dB]).

    ``frequencies`` (m,) [Hz] and ``level_db`` (m,) on the Welch grid of the diagnosis's
    objective; ``shaft_hz`` the baseline stretch's mean pinion speed [Hz].
    """

    record: str
    shaft_hz: float
    frequencies: np.ndarray = field(repr=False)
    level_db: np.ndarray = field(repr=False)

    def remove(self, x: np.ndarray, sample_rate: float, shaft_hz: float) -> np.ndarray:
        """``x`` (n,) [m/s2] of a record turning at ``shaft_hz`` [Hz] with the discrepancy taken
        out (zero-phase, in shaft orders): what the model should show if only the effect is missing."""
        x = np.asarray(x, float)
        spectrum = np.fft.rfft(x)
        f = np.fft.rfftfreq(x.size, 1.0 / sample_rate)
        d = np.interp(f * self.shaft_hz / shaft_hz, self.frequencies, self.level_db)
        return np.fft.irfft(spectrum * 10.0 ** (-d / 20.0), x.size)


@dataclass(frozen=True)
class DiscrepancySpec:
    """One baseline record to simulate (picklable, runs in a worker).

    ``operating`` for a steady stretch (simulated with :func:`twin.operating.simulate_settled`),
    or ``shaft_hz`` (n,) [Hz] for a run-up stretch (:func:`twin.effects.records.simulate_runup`);
    ``measured`` (n,) the stretch.
    """

    record: str
    fmu_path: str
    parameters: dict
    channel: str
    measured: np.ndarray = field(repr=False)
    sample_rate: float
    load: float
    operating: object = None
    shaft_hz: np.ndarray | None = field(default=None, repr=False)
    slip_hz: float = 0.0
    solver_step: float | None = 1e-5


def learn(spec: DiscrepancySpec) -> Discrepancy:
    """Simulate the model on the baseline stretch and return its :class:`Discrepancy`."""
    from twin.compare import spectral_levels
    from twin.effects.fit import _Objective
    from twin.effects.records import simulate_runup
    from twin.errors import ParameterError
    from twin.operating import simulate_settled
    from twin.signals import welch_psd

    if spec.shaft_hz is not None:
        model = simulate_runup(spec.fmu_path, spec.parameters, spec.shaft_hz, spec.load, spec.sample_rate,
                               spec.channel, slip_hz=spec.slip_hz, solver_step=spec.solver_step)
        speed = float(np.mean(spec.shaft_hz))
    else:
        _, model = simulate_settled(spec.fmu_path, spec.parameters, spec.operating, spec.measured.size, spec.channel)
        speed = float(spec.operating.shaft_hz)
    if not np.all(np.isfinite(model)):
        raise ParameterError(f"the current model does not run on baseline record {spec.record}")
    # on the objective's grid, band and levels (floored at the measured noise, the gain aligned),
    # so that a bin where the measurement is only noise is left alone rather than pulled down to
    # the model's numerical silence
    objective = _Objective(spec.measured, spec.sample_rate)
    f, pp = welch_psd(spec.measured, spec.sample_rate, resolution=objective.resolution)
    _, pm = welch_psd(model[: spec.measured.size], spec.sample_rate, resolution=objective.resolution)
    lp, lm, _ = spectral_levels(pm[objective.band], pp[objective.band])
    level = np.zeros(f.size)
    level[objective.band] = lp - lm
    return Discrepancy(spec.record, speed, f, np.clip(level, -MAX_DB, MAX_DB))


def guarded_learn(spec: DiscrepancySpec):
    try:
        return learn(spec)
    except Exception as exc:  # reported by name in the caller, never a worker's traceback
        return exc


#: A baseline record stands for a record taken within this relative distance of its drive speed
#: and load: the discrepancy is carried in shaft orders, which holds for a few per cent of speed
#: (a resonance moves by as much), not for another operating point.
SPEED_TOL = 0.05
LOAD_TOL = 0.10


def pair(records: Sequence, baseline: Sequence) -> dict[str, object]:
    """Each record's baseline: the baseline record of the same name, else the first of the same
    kind (steady or run-up). Raises :class:`~twin.errors.ParameterError` naming a record without
    one, a baseline at another operating point (drive speed beyond +-``SPEED_TOL``, load beyond
    +-``LOAD_TOL``), or a record that is its own baseline (nothing could change)."""
    from twin.errors import ParameterError
    by_name = {b.name: b for b in baseline}
    out = {}
    for r in records:
        b = by_name.get(r.name)
        if b is None or b.runup != r.runup:
            b = next((c for c in baseline if c.runup == r.runup), None)
        if b is None:
            kind = "run-up" if r.runup else "steady record"
            raise ParameterError(f"no baseline for record {r.name}: the baseline records "
                                 f"({', '.join(c.name for c in baseline) or 'none'}) hold no {kind}")
        if abs(r.nominal_speed / b.nominal_speed - 1) > SPEED_TOL or abs(r.load - b.load) > LOAD_TOL * max(b.load, 1e-9):
            raise ParameterError(f"baseline {b.name} was taken at {b.nominal_speed:g} Hz, {b.load:g} N.m and record "
                                 f"{r.name} at {r.nominal_speed:g} Hz, {r.load:g} N.m: a baseline stands for records "
                                 f"within {100 * SPEED_TOL:.0f} % of its speed and {100 * LOAD_TOL:.0f} % of its load")
        if r.signal.shape == b.signal.shape and r.sample_rate == b.sample_rate and np.array_equal(r.signal, b.signal):
            raise ParameterError(f"record {r.name} is its own baseline {b.name}: the model's discrepancy on it would "
                                 "take out everything; give a record taken later, or no baseline")
        out[r.name] = b
    return out


def learn_all(fmu_path, parameters: Mapping[str, float], records: Sequence, baseline: Sequence, channel: str, *,
              duration: float, solver_step: float | None = 1e-5, held_out_runup: float = 2.0, slip_hz: float = 0.0,
              fit_load: float = 0.0, executor=None, progress: bool = False) -> dict[str, Discrepancy]:
    """The model's :class:`Discrepancy` on each record's baseline, by record name (the steady
    baselines over their last ``duration`` s, run-ups over their last ``held_out_runup`` s,
    driven with the loaded motor's ``slip_hz`` at ``fit_load`` [N.m], scaled to their load).
    ``baseline`` may also be a mapping of record name to :class:`Discrepancy` already learned
    (:func:`twin.effects.loop.improve` learns it once, on the calibrated model, and keeps it
    while effects are added): it is then checked to cover every record and returned."""
    from twin.effects.diagnose import record_conditions
    from twin.errors import ParameterError

    if isinstance(baseline, Mapping):
        missing = [r.name for r in records if not isinstance(baseline.get(r.name), Discrepancy)]
        if missing:
            raise ParameterError(f"no learned discrepancy for record {missing[0]} (it has "
                                 f"{', '.join(baseline) or 'none'})")
        return {r.name: baseline[r.name] for r in records}
    pairs = pair(records, baseline)
    specs, names = [], {}
    for b in {id(b): b for b in pairs.values()}.values():
        if b.runup:
            if b.shaft_hz is None:
                raise ParameterError(f"baseline run-up {b.name} has no tachometer, encoder or speed channel")
            m = int(round(min(held_out_runup, b.signal.size / b.sample_rate) * b.sample_rate))
            slip = slip_hz * b.load / fit_load if fit_load else slip_hz
            spec = DiscrepancySpec(b.name, str(fmu_path), dict(parameters), channel, b.signal[-m:], b.sample_rate,
                                   b.load, shaft_hz=b.shaft_hz[-m:], slip_hz=slip, solver_step=solver_step)
        else:
            c = record_conditions(fmu_path, b.signal, b.sample_rate, b.nominal_speed, b.load, parameters,
                                  record=b.name, duration=duration, solver_step=solver_step)
            spec = DiscrepancySpec(b.name, str(fmu_path), dict(parameters), channel, c.measured, b.sample_rate,
                                   b.load, operating=c.operating, solver_step=solver_step)
        names[b.name] = len(specs)
        specs.append(spec)
    out = (executor.map(guarded_learn, specs, progress=progress, desc="baseline records") if executor is not None
           else [guarded_learn(sp) for sp in specs])
    bad = [(s.record, v) for s, v in zip(specs, out) if isinstance(v, Exception)]
    if bad:
        raise ParameterError(f"baseline record {bad[0][0]}: {bad[0][1]}")
    return {r: out[names[b.name]] for r, b in pairs.items()}
