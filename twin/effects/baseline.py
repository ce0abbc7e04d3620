"""The calibrated model's own discrepancy, learned on records of the gearbox as it was calibrated.

A twin calibrated to a gearbox it did not generate keeps a model-form error: modes it lacks, a
transfer path that is not the gearbox's, mesh lines at other levels. That error is in every
record of the gearbox, and on a rig it dwarfs what one missing effect adds (the calibrated
base stands 9-14 dB from the rigs' records, a run-out adds ~14 dB at a few sidebands), so a
flexible candidate fitted to the whole discrepancy absorbs the base's error instead of finding
the effect. A record of the same gearbox taken before the effect (a record the twin was
calibrated on) measures that error. For each record diagnosed, at its own operating point:

    delta(f) = L[B_baseline(f) + Lambda_baseline(f s_b / s)] - L_model(f)   [dB]

the baseline's measured PSD as it would read at the record's speed: its lines (Lambda, the power
6 dB or more above a 30 Hz running median) carried in shaft orders, since what is locked to a
shaft moves with it, and the rest (B: the floor, the path's resonance humps, fixed in frequency)
left where it is (carrying everything in orders moves a resonance as much as the lines: a Q = 8
path resonance at 1500 Hz stood 2.4 dB RMS off over 1300-1700 Hz between records 1.6 % apart in
speed, 1.7 dB with the split, which is the two records' own estimation scatter). That is set
against the model simulated at the record's own operating point, the levels those the diagnosis
compares (:func:`twin.compare.spectral_levels`: Welch PSDs floored 3 dB above the measured noise,
the model with that noise added and its gain aligned; where the measurement is only noise, delta
is 0). The diagnosis then compares the record's levels less delta with the model's (in the
comparison's own level domain, so that a record no different from its baseline stands exactly at
the model: taking delta out of the signal instead moved the median the noise floor is read from,
and left the record 5-7 dB from the model in quiet bands where nothing had changed): what is left
is what the measurement changed since the baseline, the model's form error and its own
dependence on the operating point cancelling; the candidates are fitted and judged on that. This
is a model-discrepancy term learned on reference data (Kennedy and O'Hagan, J. R. Stat. Soc. B
63, 2001, 425-464), kept fixed while the effect is sought: learned on the calibrated model, it
anchors every later model (an effect added) to the calibrated one.

**Several records of the healthy gearbox.** One baseline record cannot say how much two healthy
records differ: on the rigs the encoder's line at the gear's speed reads -59 and -53 dB re 1 rad
in two healthy records of one gearbox, so a +7 dB change there is no effect. Further steady
baseline records at the same operating point (:func:`repeated`) are repeats: the largest level
difference between the paired baseline record and each repeat, per bin of each channel
(``Discrepancy.scatter_db``, ``AngularDiscrepancy.scatter_db``; both read at the record's speed
in shaft orders, as the comparison reads them), is added to the line threshold of the
comparison's findings (:func:`twin.compare.compare_signals`, :func:`twin.angular.compare_angles`).
The distance and the candidates' fit are unchanged.

Frequencies in Hz, speeds in Hz (pinion), levels in dB.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from twin.effects.records import HeldOutSpec

#: Bound of the learned discrepancy [dB]: beyond it a bin holds no information the
#: correction could use (a model line 60 dB under the measured floor, say).
MAX_DB = 60.0


@dataclass(frozen=True)
class Discrepancy:
    """The model's discrepancy for one record (baseline measured minus model level [dB]).

    ``frequencies`` (m,) [Hz] and ``level_db`` (m,) on the Welch grid of the diagnosis's
    objective, learned with the model at the record's own operating point (so read at the
    record's frequencies as they are); ``record`` names the baseline record it was learned from.
    """

    record: str
    frequencies: np.ndarray = field(repr=False)
    level_db: np.ndarray = field(repr=False)
    # the encoder channel's (twin.angular.AngularDiscrepancy), when both records have an encoder
    angle: object = field(default=None, repr=False)
    # fundamentals [pinion orders] of the harmonic series in the baseline's envelope
    # (twin.signals.envelope): repeated impacts the gearbox had when calibrated are not a change
    envelope_orders: tuple[float, ...] = ()
    # (m,) [dB] how far repeated baseline records of the same operating point differ at each bin
    # (largest over the repeats; None with one baseline record): a line changed by no more than
    # that is within the healthy gearbox's record-to-record scatter (twin.compare)
    scatter_db: np.ndarray | None = field(default=None, repr=False)
    repeats: tuple[str, ...] = ()      # the names of those repeats

    def scatter_at(self, frequencies: np.ndarray) -> np.ndarray:
        """The baseline's record-to-record scatter [dB] at ``frequencies`` (m,) [Hz] (0 without
        repeated baseline records)."""
        from twin.angular import read_scatter
        return read_scatter(frequencies, self.frequencies, self.scatter_db)

    def at(self, frequencies: np.ndarray) -> np.ndarray:
        """The discrepancy [dB] at ``frequencies`` (m,) [Hz] of the record's analysis (linear
        between the learned bins; a shorter stretch's coarser grid reads it there)."""
        return np.interp(np.asarray(frequencies, float), self.frequencies, self.level_db)


@dataclass(frozen=True)
class DiscrepancySpec(HeldOutSpec):
    """One record's discrepancy to learn (picklable, runs in a worker): the model simulated at
    the record's operating point against the baseline's measured stretch; the fields of a
    held-out run (:class:`twin.effects.records.HeldOutSpec`: ``operating`` of a steady record,
    or ``shaft_hz`` (n,) [Hz] of a run-up stretch), ``measured`` (n,) the baseline's stretch and
    ``baseline_hz`` its mean pinion speed [Hz].
    """

    baseline_hz: float = 0.0
    # other baseline records of the same operating point: (name, (n,) measured stretch, (n,) angle
    # or None, mean pinion speed [Hz]) each, for the record-to-record scatter
    repeats: tuple = ()


def learn(spec: DiscrepancySpec) -> Discrepancy:
    """Simulate the model at the record's operating point and return its :class:`Discrepancy`
    to the baseline's measured stretch carried there in shaft orders."""
    from twin.compare import spectral_levels
    from twin.effects.fit import _Objective, channels
    from twin.effects.records import simulate_runup
    from twin.errors import ParameterError
    from twin.operating import simulate_settled
    from twin.signals import welch_psd

    n = spec.measured.size
    names = channels(spec.channel, spec.angle)
    if spec.shaft_hz is not None:
        model = simulate_runup(spec.fmu_path, spec.parameters, spec.shaft_hz[-n:], spec.load, spec.sample_rate,
                               names, slip_hz=spec.slip_hz, solver_step=spec.solver_step)
        speed = float(np.mean(spec.shaft_hz[-n:]))
    else:
        _, model = simulate_settled(spec.fmu_path, spec.parameters, spec.operating, n, names)
        speed = float(spec.operating.shaft_hz)
    angle_model = None
    if spec.angle is not None:
        model, angle_model = model[:, 0], model[:, 1]
    if not np.all(np.isfinite(model)):
        raise ParameterError(f"the current model does not run at the operating point of the record "
                             f"diagnosed against baseline {spec.record}")
    # on the objective's grid, band and levels (floored at the measured noise, the gain aligned),
    # so that a bin where the measurement is only noise is left alone rather than pulled down to
    # the model's numerical silence
    objective = _Objective(spec.measured, spec.sample_rate)
    f, pp = objective.frequencies, objective.psd
    _, pm = welch_psd(model[:n], spec.sample_rate, resolution=objective.resolution)
    ratio = spec.baseline_hz / speed if spec.baseline_hz > 0 else 1.0
    pp = at_speed(f, pp, ratio)
    lp, lm, _ = spectral_levels(pm[objective.band], pp[objective.band])
    level = np.zeros(f.size)
    level[objective.band] = lp - lm
    angle = ao = None
    if spec.angle is not None:
        # the encoder's: what the baseline holds beyond the model, added to it (twin.angular)
        from twin.angular import AngularDiscrepancy, AngularObjective
        ao = AngularObjective(spec.angle[-n:], spec.sample_rate, objective.resolution)
        angle = AngularDiscrepancy.learn(spec.record, ao.frequencies[ao.band],
                                         at_speed(ao.frequencies, ao.psd, ratio)[ao.band], ao.model_psd(angle_model))
    scatter = None
    if spec.repeats:
        scatter, angle_scatter = _scatter(spec, objective, pp[objective.band], ao, speed)
        if angle is not None and angle_scatter is not None:
            angle = replace(angle, scatter_db=angle_scatter)
    envelope = ()
    if spec.shaft_hz is None and spec.baseline_hz > 0:      # a run-up's stretch smears its series
        from twin.signals.envelope import envelope_series
        envelope = tuple(s.order for s in envelope_series(spec.measured, spec.sample_rate, spec.baseline_hz))
    return Discrepancy(spec.record, f, np.clip(level, -MAX_DB, MAX_DB), angle, envelope, scatter,
                       tuple(name for name, *_ in spec.repeats))


def _scatter(spec: DiscrepancySpec, objective, base_psd: np.ndarray, angle_objective, speed: float
             ) -> tuple[np.ndarray, np.ndarray | None]:
    """The largest level difference [dB] between the baseline record and each repeat, per bin of
    the casing's objective grid (m,) and of the encoder's band (``angle_objective``, the
    baseline's :class:`twin.angular.AngularObjective`, when every repeat has an angle too), the
    repeats carried to the record's speed ``speed`` [Hz] in shaft orders as the baseline is
    (``base_psd``: its PSD over the objective's band, already carried) and read as the levels the
    comparison reads (floored at the measured noise, the gain aligned)."""
    from twin.angular import AngularObjective
    from twin.compare import spectral_levels
    from twin.signals import welch_psd

    f = objective.frequencies
    scatter = np.zeros(f.size)
    angle_scatter = b_angle = None
    if angle_objective is not None and all(a is not None for _, _, a, _ in spec.repeats):
        ratio = spec.baseline_hz / speed if spec.baseline_hz > 0 else 1.0
        b_angle = at_speed(angle_objective.frequencies, angle_objective.psd, ratio)[angle_objective.band]
        angle_scatter = np.zeros(b_angle.size)
    for _, x, a, hz in spec.repeats:
        n = min(x.size, spec.measured.size)
        _, pr = welch_psd(np.asarray(x, float)[-n:], spec.sample_rate, resolution=objective.resolution)
        lb, lr, _ = spectral_levels(at_speed(f, pr, hz / speed)[objective.band], base_psd)
        scatter[objective.band] = np.maximum(scatter[objective.band], np.abs(lb - lr))
        if b_angle is not None:
            ar = AngularObjective(np.asarray(a, float)[-n:], spec.sample_rate, objective.resolution)
            lb, lr, _ = spectral_levels(at_speed(ar.frequencies, ar.psd, hz / speed)[ar.band], b_angle)
            angle_scatter = np.maximum(angle_scatter, np.abs(lb - lr))
    return scatter, angle_scatter


def at_speed(frequencies: np.ndarray, psd: np.ndarray, ratio: float, *, width_hz: float = 30.0,
             line_db: float = 6.0) -> np.ndarray:
    """A PSD (m,) on ``frequencies`` (m,) [Hz, uniform] as it would read at 1/``ratio`` times
    its speed (``ratio`` = its speed / the new one): its lines (power ``line_db`` or more above a
    ``width_hz`` running median) carried in shaft orders, its broadband rest left in place.
    Unchanged at ``ratio`` 1."""
    from scipy.ndimage import median_filter
    psd = np.asarray(psd, float)
    if ratio == 1.0:
        return psd
    df = float(frequencies[1] - frequencies[0])
    broad = median_filter(psd, size=max(5, int(round(width_hz / df))) | 1, mode="nearest")
    line = np.where(psd > broad * 10 ** (line_db / 10), psd - broad, 0.0)
    return psd - line + np.interp(np.asarray(frequencies, float) * ratio, frequencies, line, right=0.0)


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
        if (b.nominal_speed <= 0 or abs(r.nominal_speed / b.nominal_speed - 1) > SPEED_TOL
                or abs(r.load - b.load) > LOAD_TOL * max(b.load, 1e-9)):
            raise ParameterError(f"baseline {b.name} was taken at {b.nominal_speed:g} Hz, {b.load:g} N.m and record "
                                 f"{r.name} at {r.nominal_speed:g} Hz, {r.load:g} N.m: a baseline stands for records "
                                 f"within {100 * SPEED_TOL:.0f} % of its speed and {100 * LOAD_TOL:.0f} % of its load")
        if r.signal.shape == b.signal.shape and r.sample_rate == b.sample_rate and np.array_equal(r.signal, b.signal):
            raise ParameterError(f"record {r.name} is its own baseline {b.name}: the model's discrepancy on it would "
                                 "take out everything; give a record taken later, or no baseline")
        out[r.name] = b
    return out


def repeated(b, baseline: Sequence) -> list:
    """The other steady baseline records taken at ``b``'s operating point (drive speed within
    ``SPEED_TOL``, load within ``LOAD_TOL``, the same sample rate): repeats of the healthy
    gearbox, whose differences from ``b`` are its record-to-record scatter."""
    return [o for o in baseline if o is not b and not o.runup and o.sample_rate == b.sample_rate
            and b.nominal_speed > 0 and abs(o.nominal_speed / b.nominal_speed - 1) <= SPEED_TOL
            and abs(o.load - b.load) <= LOAD_TOL * max(b.load, 1e-9)]


def _angle(record, n: int, wanted: bool) -> np.ndarray | None:
    """The last n samples of a record's encoder angle [rad], if wanted and it has one."""
    return record.angle[-n:] if wanted and record.angle is not None else None


def learn_all(fmu_path, parameters: Mapping[str, float], records: Sequence, baseline: Sequence, channel: str, *,
              duration: float, solver_step: float | None = 1e-5, held_out_runup: float = 2.0, slip_hz: float = 0.0,
              fit_load: float = 0.0, executor=None, progress: bool = False,
              encoder: bool = False) -> dict[str, Discrepancy]:
    """Each record's :class:`Discrepancy` to its baseline, by record name: the model at the
    record's operating point (a steady record's last ``duration`` s; a run-up's last
    ``held_out_runup`` s along its measured speed, driven with the loaded motor's ``slip_hz`` at
    ``fit_load`` [N.m], scaled to its load) against the baseline's stretch as long.
    ``baseline`` may also be a mapping of record name to :class:`Discrepancy` already learned
    (:func:`twin.effects.loop.improve` learns it once, on the calibrated model, and keeps it
    while effects are added): it is then checked to cover every record and returned.
    With ``encoder`` the encoder channel's discrepancy is learned too (``Discrepancy.angle``)
    for each record that has an encoder angle, as its baseline has, when the model has the
    encoder output (:mod:`twin.angular`)."""
    from twin.effects.diagnose import record_conditions
    from twin.errors import ParameterError

    if isinstance(baseline, Mapping):
        missing = [r.name for r in records if not isinstance(baseline.get(r.name), Discrepancy)]
        if missing:
            raise ParameterError(f"no learned discrepancy for record {missing[0]} (it has "
                                 f"{', '.join(baseline) or 'none'})")
        return {r.name: baseline[r.name] for r in records}
    pairs = pair(records, baseline)
    if encoder:
        from twin.angular import ANGLE_OUTPUT
        from twin.effects.diagnose import fmu_outputs
        encoder = ANGLE_OUTPUT in fmu_outputs(fmu_path)
    specs = []
    for r in records:
        b = pairs[r.name]
        if b.sample_rate != r.sample_rate:
            raise ParameterError(f"baseline {b.name} is sampled at {b.sample_rate:g} Hz, record {r.name} at "
                                 f"{r.sample_rate:g} Hz")
        if r.runup:
            for rec in (r, b):
                if rec.shaft_hz is None:
                    raise ParameterError(f"run-up {rec.name} has no tachometer, encoder or speed channel")
            m = int(round(min(held_out_runup, r.signal.size / r.sample_rate, b.signal.size / b.sample_rate)
                          * r.sample_rate))
            slip = slip_hz * r.load / fit_load if fit_load else slip_hz
            specs.append(DiscrepancySpec(b.name, str(fmu_path), dict(parameters), channel, b.signal[-m:], r.sample_rate,
                                         r.load, shaft_hz=r.shaft_hz[-m:], slip_hz=slip, solver_step=solver_step,
                                         angle=_angle(b, m, encoder and r.angle is not None),
                                         baseline_hz=float(np.mean(b.shaft_hz[-m:]))))
        else:
            c = record_conditions(fmu_path, r.signal, r.sample_rate, r.nominal_speed, r.load, parameters,
                                  record=r.name, duration=duration, solver_step=solver_step, shaft_speed=r.shaft_hz)
            cb = record_conditions(fmu_path, b.signal, b.sample_rate, b.nominal_speed, b.load, parameters,
                                   record=b.name, duration=duration, solver_step=solver_step, shaft_speed=b.shaft_hz)
            repeats = []
            for o in repeated(b, baseline):
                co = record_conditions(fmu_path, o.signal, o.sample_rate, o.nominal_speed, o.load, parameters,
                                       record=o.name, duration=duration, solver_step=solver_step,
                                       shaft_speed=o.shaft_hz)
                repeats.append((o.name, co.measured, _angle(o, co.measured.size, encoder and r.angle is not None),
                                float(co.operating.shaft_hz)))
            specs.append(DiscrepancySpec(b.name, str(fmu_path), dict(parameters), channel, cb.measured, r.sample_rate,
                                         r.load, operating=c.operating, solver_step=solver_step,
                                         angle=_angle(b, cb.measured.size, encoder and r.angle is not None),
                                         baseline_hz=float(cb.operating.shaft_hz), repeats=tuple(repeats)))
    out = (executor.map(guarded_learn, specs, progress=progress, desc="baseline records") if executor is not None
           else [guarded_learn(sp) for sp in specs])
    bad = [(s.record, v) for s, v in zip(specs, out) if isinstance(v, Exception)]
    if bad:
        raise ParameterError(f"baseline record {bad[0][0]}: {bad[0][1]}")
    return {r.name: d for r, d in zip(records, out)}
