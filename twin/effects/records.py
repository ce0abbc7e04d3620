"""Several records of one gearbox: steady records to fit on, run-ups to test on and to read from.

A steady record is where candidates are fitted (one operating point, 2 Hz bins). A run-up sweeps
the shaft speed, which separates what a single steady record cannot: content locked to a shaft
moves with the speed (an order), content fixed in frequency stays (a drive line, a structural
resonance). The run-up is read with the project's run-up analysis
(:func:`twin.modes.survey_record`, :func:`twin.signals.runup.analyse_runup`), and its last
stretch is simulated as a record a candidate was not fitted on (:func:`simulate_runup`).

Frequencies in Hz, speeds in Hz (pinion), signals in the record's unit (m/s2).
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

#: A record whose pinion speed changes by this factor or more is a run-up (as in
#: :func:`twin.signals.runup.analyse_runup`, below which orders and fixed lines cannot be told apart).
RUNUP_SWEEP = 1.2


@dataclass(frozen=True)
class Record:
    """One record of the gearbox with the conditions it was taken at.

    ``shaft_hz`` (n,) is the pinion speed per sample [Hz] when the record has a tachometer, an
    encoder or a speed channel (None otherwise); ``raw`` is the loaded record (for the run-up
    analysis); ``angle`` (n,) [rad] the pinion encoder's angle when the tachometer is an angle
    encoder (``tachometer_kind: angle``; a pulse train or a speed channel gives no angular
    vibration): the diagnosis's second channel (:mod:`twin.angular`).
    """

    name: str
    signal: np.ndarray = field(repr=False)      # (n,) [m/s2]
    sample_rate: float                          # Hz
    nominal_speed: float                        # drive setting [Hz]
    load: float                                 # brake load [N.m]
    shaft_hz: np.ndarray | None = field(default=None, repr=False)
    raw: object = field(default=None, repr=False, compare=False)
    angle: np.ndarray | None = field(default=None, repr=False)

    @property
    def sweep(self) -> float:
        """Ratio of the highest to the lowest pinion speed over the record (1 without a speed)."""
        if self.shaft_hz is None:
            return 1.0
        s = _smoothed(self.shaft_hz, int(self.sample_rate * 0.05))
        lo = float(np.nanpercentile(s, 2))
        return float(np.nanpercentile(s, 98) / lo) if lo > 0 else math.inf

    @property
    def runup(self) -> bool:
        return self.sweep >= RUNUP_SWEEP


def _smoothed(v: np.ndarray, width: int) -> np.ndarray:
    width = max(1, width)
    return np.convolve(v, np.ones(width) / width, mode="valid") if v.size > width else v


def shaft_speed(angle: np.ndarray, sample_rate: float, window: float = 0.01) -> np.ndarray:
    """Shaft speed (n,) [Hz] from an unwrapped angle (n,) [rad]: a central difference over
    ``window`` s, since a quantised encoder angle differentiated sample by sample is a staircase."""
    w = max(1, int(round(0.5 * window * sample_rate)))
    n = angle.size
    if n <= 2 * w:
        return np.full(n, (angle[-1] - angle[0]) / max(n - 1, 1) * sample_rate / (2 * np.pi))
    mid = (angle[2 * w:] - angle[:-2 * w]) / (2 * w / sample_rate) / (2 * np.pi)
    return np.concatenate([np.full(w, mid[0]), mid, np.full(w, mid[-1])])


def read_records(measurements, channel: str = "accel_pinion_casing", names: Sequence[str] | None = None, *,
                 every: bool = False) -> list[Record]:
    """Records of a measurement file: those ``names`` gives (in that order), every record with
    ``every``, else the first.

    Raises :class:`~twin.errors.MeasurementError` naming a record the file lacks (and listing the
    ones it has), a name given twice, or a record without its ``nominal_speed`` and ``load``.
    """
    from twin.errors import MeasurementError
    from twin.measurements import load_measurements
    from twin.modes import shaft_angle

    mset = load_measurements(measurements)          # every channel: a speed channel gives a run-up's profile
    for note in mset.notes:
        print(f"note: {note}")
    names = list(names or ())
    for nm in names:
        if nm not in mset.names:
            raise MeasurementError(str(measurements), nm, f"no such record; the file has: {', '.join(mset.names)}")
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise MeasurementError(str(measurements), dup, "record given twice")
    chosen = names or (list(mset.names) if every else [mset.names[0]])
    out = []
    for nm in chosen:
        rec = mset[nm]
        if channel not in rec.channel_names:
            raise MeasurementError(str(measurements), nm, f"no channel {channel!r} (it has "
                                                          f"{', '.join(rec.channel_names)})")
        missing = [a for a in ("nominal_speed", "load") if getattr(rec, a) is None]
        if missing:
            raise MeasurementError(str(measurements), rec.name, f"lacks {', '.join(missing)} (the drive speed [Hz] "
                                                                "and brake load [N.m] the record was taken at)")
        angle = shaft_angle(rec)
        speed = encoder = None
        if angle is not None and np.all(np.isfinite(angle)):
            speed = shaft_speed(angle, float(rec.sample_rate))
            if rec.tachometer is not None and rec.tachometer_kind == "angle":
                encoder = angle
        out.append(Record(rec.name, np.asarray(rec[channel], float), float(rec.sample_rate),
                          float(rec.nominal_speed), float(rec.load), speed, rec, encoder))
    return out


def as_records(records, sample_rate: float | None = None, nominal_speed: float | None = None,
               load: float | None = None, record: str = "record") -> list[Record]:
    """The diagnosis's input as a list of :class:`Record`: a sequence of them, one, or a bare
    array (n,) with its ``sample_rate``, ``nominal_speed`` and ``load``."""
    from twin.errors import ParameterError
    if isinstance(records, Record):
        return [records]
    if isinstance(records, np.ndarray) or (isinstance(records, Sequence) and records
                                           and not isinstance(records[0], Record)):
        if sample_rate is None or nominal_speed is None or load is None:
            raise ParameterError("a bare signal needs its sample_rate, nominal_speed and load")
        return [Record(record, np.asarray(records, float), float(sample_rate), float(nominal_speed), float(load))]
    recs = list(records)
    if not recs:
        raise ParameterError("diagnosis needs at least one record")
    bad = [r for r in recs if not isinstance(r, Record)]
    if bad:
        raise ParameterError(f"records must be twin.effects.records.Record, got {type(bad[0]).__name__}")
    names = [r.name for r in recs]
    if len(set(names)) != len(names):
        raise ParameterError(f"record names must differ, got {names}")
    return recs


# ---------------------------------------------------------------------------------------------
# The model on a run-up

#: Knot spacing [s] of the speed trend: a cubic spline with knots this far apart follows a drive's
#: run-up ramp and leaves out what changes within a revolution (the gear's at 20 Hz lasts 0.14 s).
TREND_KNOTS_S = 0.5


def speed_trend(shaft_hz: np.ndarray, sample_rate: float, knots_s: float = TREND_KNOTS_S) -> np.ndarray:
    """The trend (n,) [Hz] of a pinion-speed profile (n,): its least-squares cubic spline with
    interior knots every ``knots_s`` s (a profile shorter than two knot spans: its cubic)."""
    from scipy.interpolate import make_lsq_spline
    v = np.asarray(shaft_hz, float)
    n = v.size
    t = np.arange(n) / sample_rate
    inner = np.arange(knots_s, t[-1] - 0.5 * knots_s, knots_s) if n > 1 else np.empty(0)
    if n < 8 or inner.size == 0:
        return np.polyval(np.polyfit(t, v, min(3, n - 1)), t) if n > 1 else v.copy()
    k = 3
    knots = np.concatenate([np.full(k + 1, t[0]), inner, np.full(k + 1, t[-1])])
    return make_lsq_spline(t, v, knots, k=k)(t)


def simulate_runup(fmu_path, parameters: Mapping[str, float], shaft_hz: np.ndarray, load: float, sample_rate: float,
                   channel, *, slip_hz: float = 0.0, settle: float = 0.15, chunk: float = 0.005,
                   solver_step: float | None = 1e-5) -> np.ndarray:
    """The model's ``channel`` (n,) with its drive following a measured pinion-speed profile
    ((n, k) for a list of k channels).

    The drive follows the profile's trend (:func:`speed_trend`), not the profile itself: a
    speed read off an encoder carries the shafts' vibration too (a run-out's once-per-turn
    wobble, a ripple), which the drive did not command, and a model driven with it would be
    handed the very effect it is asked to explain.

    ``shaft_hz`` (n,) [Hz] per sample; the drive command is it plus ``slip_hz`` (the loaded
    motor's slip), updated every ``chunk`` s (linear within the record's speed profile). The run
    starts ``settle`` s before the stretch at the first speed, so it begins without a transient.
    """
    from twin.fmu_pool import reused
    from twin.operating import operating_point
    from twin.plausibility import check_parameters

    shaft_hz = speed_trend(np.asarray(shaft_hz, float), sample_rate)
    n = shaft_hz.size
    dt = 1.0 / sample_rate
    params = dict(parameters)
    if solver_step is not None:
        params["solver.step_size"] = solver_step
    start, inputs = operating_point(shaft_hz[0] + slip_hz, load)
    per = max(1, int(round(chunk * sample_rate)))
    names = [channel] if isinstance(channel, str) else list(channel)
    out = np.empty((n, len(names)))
    with reused(fmu_path) as fmu:
        params = {**params, **start}
        check_parameters(fmu, params)
        fmu.setup(0.0, parameters=params, inputs=inputs)
        fmu.capture(settle, dt, names)
        t = settle
        for i0 in range(0, n, per):
            i1 = min(n, i0 + per)
            w = 2 * math.pi * (float(np.mean(shaft_hz[i0:i1])) + slip_hz)
            fmu.set({"motor_speed_ref": w})
            t = settle + i1 * dt
            out[i0:i1] = fmu.capture(t, dt, names)[: i1 - i0]
    return out[:, 0] if isinstance(channel, str) else out


# ---------------------------------------------------------------------------------------------
# A record a candidate was not fitted on

@dataclass(frozen=True)
class HeldOutSpec:
    """One model run scored on a held-out record (picklable, runs in a worker).

    ``operating`` for a steady record (simulated with :func:`twin.operating.simulate_at`), or
    ``shaft_hz`` (n,) [Hz] for a run-up stretch (:func:`simulate_runup`); ``measured`` (n,) is
    the stretch scored.
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
    discrepancy: object = None          # the record's known model-form error (twin.effects.baseline)
    angle: np.ndarray | None = field(default=None, repr=False)   # (n,) encoder angle [rad]: a second channel


def held_out_lsd(spec: HeldOutSpec) -> float:
    """LSD [dB] of the model run against the held-out stretch (the diagnosis's fit objective:
    both channels' joint LSD when the stretch has an encoder ``angle``)."""
    from twin.effects.fit import _Objective, channels
    from twin.operating import simulate_at
    objective = _Objective(spec.measured, spec.sample_rate, discrepancy=spec.discrepancy, angle=spec.angle)
    names = channels(spec.channel, spec.angle)
    if spec.shaft_hz is not None:
        sim = simulate_runup(spec.fmu_path, spec.parameters, spec.shaft_hz, spec.load, spec.sample_rate,
                             names, slip_hz=spec.slip_hz, solver_step=spec.solver_step)
    else:
        sim = simulate_at(spec.fmu_path, spec.parameters, spec.operating, spec.measured.size, names)
    return objective(sim)


def guarded_held_out(spec: HeldOutSpec):
    try:
        return held_out_lsd(spec)
    except Exception as exc:  # a run that fails is reported per candidate, never ends the diagnosis
        return exc
