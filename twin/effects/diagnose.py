"""Which physical effect is the model missing? Rank the catalogue by actually trying each effect.

For one measured record:

1. **Baseline.** Simulate the current model at the measured operating point. The drive is set
   so that the model's pinion turns at the *measured* shaft speed (from the gear-mesh line),
   because a 1 % speed error moves the 10th mesh harmonic by several bins. Compare
   (:func:`twin.compare.compare_signals`): headline log-spectral distance (LSD, dB) and findings.
2. **Try every candidate.** In ``GearTwin.Variants.Gearbox21Candidates``, the base model with
   every catalogue effect switched off, turn one effect on and refit its few parameters by
   minimising the LSD. Starting values come from the physics of the measured spectrum: an
   unlocked line gives a ripple frequency, a lifted band a resonance, a slow sideband spacing a
   load fluctuation period. Amplitudes are searched on a log grid, then polished (bounded Brent
   or Nelder-Mead).
3. **Refit the related base parameters.** The ``related_leaders`` leading candidates (2 by
   default) are fitted once more together with the base parameters that shape the same
   signature (``Effect.related``, e.g. the mesh stiffness for a run-out), each within +-10 % of
   its calibrated value. The result replaces the candidate's when it lowers the LSD, and the
   moved base values are reported with the fitted parameters.
4. **Judge.** A candidate's score is the relative cut of the LSD it achieves. A baseline finding
   is *explained* by a candidate when the squared dB error in its band falls by at least half
   (an ``impulsive`` finding: when it is gone). The top candidate is reported as missing only if
   it cuts the LSD by at least ``min_cut`` and by ``min_db`` dB; findings it does not explain
   are reported as unexplained. No finding and no useful candidate means nothing is missing.
   When no candidate is useful and most of the discrepancy is broadband level off in two or
   more bands (modes in the wrong place), the verdict is that the base model is not calibrated
   well enough to diagnose, naming the bands to calibrate (:func:`twin.effects.verdict.judge`).

5. **Several records** (:mod:`twin.effects.records`). The candidates are fitted on the first
   steady record. Each one that passes 4. is run on every other record, which it was not fitted
   on (another steady record at its own operating point; the end of a run-up along its measured
   speed), and must still cut the LSD there (``HELD_OUT_DB``): this held-out test is the
   penalty for a candidate's added freedom. Its physical signature must not be absent from the
   data (:mod:`twin.effects.signatures`: shaft-order sidebands for a run-out, a band fixed in
   frequency across the run-up for a resonance, a fixed narrow line for a drive ripple). Two
   that earn their place and explain the same findings are a tie.

Candidates are fitted in parallel on an :class:`twin.executor.Executor` (local processes or
Dask), and the held-out runs too (candidates x records). All evaluations use one FMU, so there is one build (seconds, cached) per catalogue.
"""
from __future__ import annotations

import functools
import math
import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from twin.compare import Comparison, compare_signals
from twin.effects.catalogue import CATALOGUE, Effect, effect as get_effect
# the fit runs in the workers; its names stay importable from here
from twin.effects.fit import (TrialSpec, _guarded_fit, _Objective, channels, fit_effect,  # noqa: F401
                              simulate, starting_values)
from twin.operating import Operating, simulate_settled
from twin.effects.verdict import MIN_CUT, MIN_DB, Candidate, Diagnosis, _explained, fits, judge

HELD_OUT_RUNUP_S = 2.0   # s of the end of a run-up simulated as a held-out record
# The candidates' search runs on the last SEARCH_S s of the record at the RK4 step SEARCH_STEP
# (0.80 s of wall time per trial instead of 2.02 s); the values it finds are scored on the whole
# record (``duration``) at the operating point's step, which is what the verdict is judged on.
SEARCH_S = 1.0
SEARCH_STEP = 2e-5


def fmu_outputs(fmu_path) -> frozenset:
    """The output names an FMU declares (read once per file version: the baseline, the
    candidates and the verdict all ask)."""
    try:
        st = os.stat(fmu_path)
    except (OSError, TypeError, ValueError):
        return _fmu_outputs.__wrapped__(fmu_path, 0, 0)     # the FMU loader names what is wrong
    return _fmu_outputs(os.path.realpath(fmu_path), st.st_mtime_ns, st.st_size)


@functools.lru_cache(maxsize=32)
def _fmu_outputs(path: str, mtime_ns: int, size: int) -> frozenset:
    from twin.fmu import FMU
    with FMU(path) as fmu:
        return frozenset(v.name for v in fmu.outputs)


def require_running(block: np.ndarray, record: str, op: Operating) -> np.ndarray:
    """The base model's run ``block`` at a record's operating point, refused when it holds NaN
    or Inf (a model that diverges there gives no comparison and no starting values)."""
    if not np.all(np.isfinite(block)):
        from twin.errors import ParameterError
        raise ParameterError(f"the model does not run at the operating point of record {record} "
                             f"({op.shaft_hz:.2f} Hz, {op.load:g} N.m): its signal holds NaN or Inf")
    return block


def uses_encoder(records: Sequence, baseline, outputs) -> bool:
    """Whether the diagnosis compares the encoder channel too (:mod:`twin.angular`): the model
    has the encoder output, every record has an encoder angle, and so has every baseline record
    (or every learned baseline discrepancy its encoder part)."""
    from twin.angular import ANGLE_OUTPUT
    if ANGLE_OUTPUT not in outputs or any(r.angle is None for r in records):
        return False
    if baseline is None:
        return True
    if isinstance(baseline, Mapping):
        return all(getattr(baseline.get(r.name), "angle", None) is not None for r in records)
    return all(b.angle is not None for b in baseline)


def active_effects(parameter_names: Sequence[str]) -> list[str]:
    """Catalogue effects present in an FMU, from its parameter names (``<id>.<param>``)."""
    ids = {n.split(".", 1)[0] for n in parameter_names if "." in n}
    return [e for e in CATALOGUE if e in ids]


def split_fitted(effect_id: str, fitted: Mapping[str, float]) -> tuple[dict[str, float], dict[str, float]]:
    """Fitted FMU values -> (the effect's own, by component name; the moved base parameters)."""
    prefix = effect_id + "."
    own = {k[len(prefix):]: v for k, v in fitted.items() if k.startswith(prefix)}
    return own, {k: v for k, v in fitted.items() if not k.startswith(prefix)}


def related_values(eff: Effect, parameters: Mapping[str, float], current: Mapping[str, float]) -> dict[str, float]:
    """Calibrated values of the effect's related base parameters: the scenario's, else the FMU's."""
    return {k: float(parameters.get(k, current[k])) for k in eff.related if k in parameters or k in current}


def _trials(eff: Effect) -> int:
    """Rough number of trial runs of an effect's fit (:func:`twin.effects.fit.fit_effect`): a grid
    and a polish per amplitude-like parameter, a joint polish with more than one parameter."""
    free = [p for p in eff.fit if p.guess is None]
    return sum(p.grid + 8 for p in free) + (15 if len(eff.fit) > 1 else 0)


def compare_record(sim: np.ndarray, measured: np.ndarray, angle: np.ndarray | None, fs: float, shaft_hz: float,
                   z1: int, z2: int, discrepancy=None) -> Comparison:
    """The casing channel's comparison (``sim`` (n,) or its first column), with the encoder's
    folded in when the record has an ``angle`` (n,) [rad] and ``sim`` is (n, 2) (:func:`twin.angular.joint`)."""
    from twin.angular import compare_angles, joint
    casing = compare_signals(sim[:, 0] if sim.ndim == 2 else sim, measured, fs, shaft_hz, z1=z1, z2=z2,
                             discrepancy=discrepancy)
    if angle is None:
        return casing
    return joint(casing, compare_angles(sim[:, 1], angle, fs, shaft_hz, z1=z1, z2=z2,
                                        discrepancy=getattr(discrepancy, "angle", None)))


def _candidate(eff: Effect, before: Comparison, fitted: dict, n_eval: int, sim: np.ndarray, measured: np.ndarray,
               op: Operating, z1: int, z2: int, discrepancy=None, angle: np.ndarray | None = None) -> Candidate:
    """Score a fitted candidate against the baseline comparison (``discrepancy``: the record's
    known model-form error, taken out of the compared levels as in ``before``; ``angle``: the
    record's encoder angle, compared as in ``before``)."""
    after = compare_record(sim, measured, angle, op.sample_rate, op.shaft_hz, z1, z2, discrepancy)
    score = max(0.0, (before.lsd_db - after.lsd_db) / before.lsd_db) if before.lsd_db > 0 else 0.0
    return Candidate(eff.id, eff.title, score, after.lsd_db, fitted, _explained(before, after, eff), after.findings,
                     n_eval)


@dataclass(frozen=True)
class Conditions:
    """A record in model terms: what both the diagnosis and add-effect simulate against."""

    measured: np.ndarray = field(repr=False)   # (n,) the compared stretch [m/s2]
    current: dict                               # Real parameters of the current model's FMU
    z1: int                                     # pinion teeth
    z2: int                                     # gear teeth
    operating: Operating
    structural: dict = field(default_factory=dict)   # the FMU's build-time Integers (n_path_sections, ...)
    outputs: frozenset = frozenset()                 # the FMU's output names


def record_conditions(fmu_path, measured: np.ndarray, sample_rate: float, nominal_speed: float, load: float,
                      parameters: Mapping[str, float], *, record: str = "record", duration: float = 2.0,
                      solver_step: float | None = 1e-5, shaft_speed: np.ndarray | None = None) -> Conditions:
    """Check the record and the model, keep the last ``duration`` s, and find the operating point.

    ``shaft_speed`` (n,) [Hz], the pinion speed per sample from the record's encoder, tachometer or
    speed channel (:attr:`twin.effects.records.Record.shaft_hz`), gives the pinion speed (its mean
    over the stretch kept); without it the speed is read off the gear-mesh line, which a strong
    sideband can take for it (a local tooth fault's 20th order stood above the 19th on a rig record:
    20.94 Hz read for 19.89 Hz).

    Raises :class:`MeasurementError` for a record that is not 1-D, shorter than 0.25 s or not
    finite, and :class:`ParameterError` for a ``duration`` under 0.25 s or a model that is not
    ``GearTwin.Gearbox21`` or a variant of it.
    """
    from twin.errors import MeasurementError, ParameterError
    from twin.fmu import FMU
    from twin.operating import measured_operating, stretch_speed

    if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration >= 0.25):
        raise ParameterError(f"duration must be at least 0.25 s of the record, got {duration!r}")
    measured = np.asarray(measured, float)
    if measured.ndim != 1 or measured.size < int(0.25 * sample_rate):
        raise MeasurementError("<array>", record, f"diagnosis needs a 1-D record of at least 0.25 s, got shape "
                                                  f"{measured.shape} at {sample_rate} Hz")
    if not np.all(np.isfinite(measured)):
        raise MeasurementError("<array>", record, "the measured signal holds NaN or Inf values")
    keep = int(round(min(duration, measured.size / sample_rate) * sample_rate))
    measured = measured[-keep:]
    shaft_hz = stretch_speed(shaft_speed, keep)
    if shaft_hz is not None and not shaft_hz > 0:
        raise MeasurementError("<array>", record, f"the record's pinion speed is {shaft_hz:g} Hz over the "
                                                  "stretch diagnosed; the gearbox must turn")
    with FMU(fmu_path) as fmu:
        current = fmu.parameter_values()
        structural = fmu.structural_values()
        outputs = frozenset(v.name for v in fmu.outputs)
        teeth = {**{k: v for k, v in current.items() if k in ("z1", "z2")}, **structural}
    missing = [h for h in ("z1", "z2") if h not in teeth] + [h for h in ("c_motor",) if h not in current]
    if missing:
        raise ParameterError(f"{fmu_path} is not a GearTwin.Gearbox21 model (no parameter(s) "
                             f"{', '.join(missing)}); the effect catalogue extends that model")
    z1, z2 = int(round(float(teeth["z1"]))), int(round(float(teeth["z2"])))
    op = measured_operating(measured, sample_rate, nominal_speed, load, teeth=z1, gear_teeth=z2,
                            c_motor=float(parameters.get("c_motor", current["c_motor"])),
                            solver_step=solver_step if "solver.step_size" in current else None, shaft_hz=shaft_hz)
    return Conditions(measured, current, z1, z2, op, structural, outputs)


def diagnose(fmu_path, measured, sample_rate: float | None = None, nominal_speed: float | None = None,
             load: float | None = None, *,
             parameters: Mapping[str, float] | None = None, channel: str = "accel_pinion_casing",
             effects: Sequence[str] | None = None, executor=None, record: str = "record",
             candidates_fmu=None, duration: float = 2.0, max_evals: int = 30,
             min_cut: float = MIN_CUT, min_db: float = MIN_DB, solver_step: float | None = 1e-5,
             related_leaders: int = 2, anchors: Mapping[str, float] | None = None,
             held_out_runup: float = HELD_OUT_RUNUP_S, search: float | None = SEARCH_S,
             search_step: float | None = SEARCH_STEP, baseline=None, progress: bool = False,
             encoder: bool = True) -> Diagnosis:
    """Diagnose one record, or several records of the same gearbox (see the module docstring).

    Parameters
    ----------
    fmu_path : the current model's FMU (the base gearbox or a variant of it).
    measured : (n,) measured acceleration [m/s2] at ``sample_rate`` [Hz] (with ``nominal_speed``
        [Hz] and ``load`` [N.m], the drive setting and brake torque), or a sequence of
        :class:`twin.effects.records.Record` (:func:`~twin.effects.records.read_records`). The
        candidates are fitted on the first steady record; every other steady record and the
        last ``held_out_runup`` s of each run-up are held out (each candidate that fits is
        simulated there, in parallel), and the first run-up is read for the effects'
        signatures (:mod:`twin.effects.signatures`). The last ``duration`` s of a steady
        record are used (2 s give 2 Hz bins, which separate sidebands at the gear speed, 7 Hz
        at 20 Hz input, from their mesh harmonic).
    parameters : the current model's (calibrated) parameters.
    effects : candidate ids (default: every catalogue effect the current model lacks).
    candidates_fmu : the built candidate model of the current model's base (``Gearbox21Candidates``,
        ``Gearbox21MeasuredCandidates`` for a model with a sensor path); built on demand when None.
    related_leaders : how many of the leading candidates are refitted once more together with
        their related base parameters (:attr:`Effect.related`); 0 switches that off.
    anchors : calibrated values of base parameters (a scenario's ``diagnosis.calibrated``): the
        related parameters stay within +-``RELATED_SPAN`` of these (default: their current values).
    search, search_step : the candidates' search runs on the last ``search`` s of the record at
        the RK4 step ``search_step`` [s] (None: on the whole record, at the operating point's
        step); the values found are scored on the whole record at the operating point's step.
    baseline : records of the same gearbox as it was calibrated, without the effect sought (a
        sequence of :class:`~twin.effects.records.Record`, matched to the records by name, else
        by kind, at the same operating point): the model's discrepancy on them is learned and
        taken out of every record before anything is fitted or judged
        (:mod:`twin.effects.baseline`), so the candidates meet what changed since, not what the
        calibrated model never matched. Or a mapping of record name to an already learned
        :class:`~twin.effects.baseline.Discrepancy`.
    encoder : compare the records' pinion encoder as a second channel (:mod:`twin.angular`) when
        the model has the encoder output and every record (and baseline record) an encoder angle:
        the candidates are fitted and held out on both channels' joint LSD, and a run-out's
        signature may be the encoder's line at its shaft's speed. False: the casing channel alone.

    Raises :class:`~twin.errors.ParameterError` for records that hold no steady record (a
    run-up alone cannot be fitted) or a run-up without a shaft speed.
    """
    from twin.effects.records import HeldOutSpec, as_records, guarded_held_out
    from twin.effects.signatures import survey_records
    from twin.errors import ParameterError
    from twin.executor import LocalExecutor

    t0 = time.perf_counter()
    parameters = dict(parameters or {})
    recs = as_records(measured, sample_rate, nominal_speed, load, record)
    steady = [r for r in recs if not r.runup]
    runups = [r for r in recs if r.runup]
    if not steady:
        raise ParameterError(f"records {', '.join(r.name for r in recs)} are all run-ups; the candidates are "
                             "fitted on a steady record: give one too")
    fit_rec = steady[0]
    if baseline is not None and not isinstance(baseline, Mapping):
        from twin.effects.baseline import pair
        pair(recs, as_records(baseline))          # a record without a fitting baseline is refused first
    conds = {r.name: record_conditions(fmu_path, r.signal, r.sample_rate, r.nominal_speed, r.load, parameters,
                                       record=r.name, duration=duration, solver_step=solver_step,
                                       shaft_speed=r.shaft_hz) for r in steady}
    cond = conds[fit_rec.name]
    measured, current, z1, z2, op = cond.measured, cond.current, cond.z1, cond.z2, cond.operating
    sample_rate = fit_rec.sample_rate
    shaft = op.shaft_hz
    active = active_effects(current)
    ids = [e for e in (effects or CATALOGUE) if e not in active]
    for e in ids:
        get_effect(e)
    given = None if baseline is None else baseline if isinstance(baseline, Mapping) else as_records(baseline)
    encoder = encoder and uses_encoder(recs, given, cond.outputs)

    def angle_of(r, n: int) -> np.ndarray | None:
        return r.angle[-n:] if encoder else None

    fit_angle = angle_of(fit_rec, measured.size)
    # the trials start from the drive command that gave the base model the measured speed: without
    # it a model whose slip differs from the estimate runs every trial twice (simulate_at)
    op, base_model = simulate_settled(fmu_path, parameters, op, measured.size, channels(channel, fit_angle))
    require_running(base_model, fit_rec.name, op)
    ex = executor or LocalExecutor()
    discrepancy: dict = {}
    if given is not None:
        from twin.effects.baseline import learn_all
        discrepancy = learn_all(fmu_path, parameters, recs, given, channel, duration=duration,
                                solver_step=solver_step, held_out_runup=held_out_runup,
                                slip_hz=op.drive_hz - op.shaft_hz, fit_load=op.load, executor=ex, progress=progress,
                                encoder=encoder)
    known = discrepancy.get(fit_rec.name)
    before = compare_record(base_model, measured, fit_angle, sample_rate, shaft, z1, z2, known)
    if base_model.ndim == 2:
        base_model = base_model[:, 0]

    if candidates_fmu is None:
        from twin.effects.variant import _REPO_MODELICA, base_of, build_like, candidates_model
        candidates_fmu = build_like(candidates_model(base_of(current)), _REPO_MODELICA,
                                    _REPO_MODELICA.parent / "build", cond.structural)
    # the candidate model starts from the current model: base parameters, the active effects at
    # their values in the current FMU, every other effect neutral
    probe = dict(parameters)
    for e in active:
        probe.update({k: v for k, v in current.items() if k.startswith(e + ".")})
    for e in CATALOGUE.values():
        if e.id not in active:
            probe.update({e.parameter(k): v for k, v in e.neutral.items()})
    guesses = starting_values(before, measured, base_model, sample_rate, shaft, z1, z2)
    short = dict(search_samples=int(round(search * sample_rate)) if search else None, search_step=search_step)
    specs = [TrialSpec(e, str(candidates_fmu), channel, measured, op, probe, guesses.get(e, {}), max_evals, **short,
                       discrepancy=known, angle=fit_angle)
             for e in ids]
    # the candidates with the most trials first, so that no worker is left with a long one at the end
    specs.sort(key=lambda sp: -_trials(CATALOGUE[sp.effect]))
    results = ex.map(_guarded_fit, specs, progress=progress, desc="candidate effects")

    cands = []
    for spec, r in zip(specs, results):
        eff = CATALOGUE[spec.effect]
        if isinstance(r, Exception):
            cands.append(Candidate(eff.id, eff.title, 0.0, before.lsd_db, {}, (), (), 0, str(r)))
            continue
        fitted, _, n_eval, sim = r
        if sim is None:
            cands.append(Candidate(eff.id, eff.title, 0.0, before.lsd_db, fitted, (), (), n_eval,
                                   "every trial of this effect failed to simulate"))
            continue
        cands.append(_candidate(eff, before, fitted, n_eval, sim, measured, op, z1, z2, known, fit_angle))
    cands.sort(key=lambda c: -c.score)
    # the leading candidates are tried again with their related base parameters refitted too
    lead = [c for c in cands[:related_leaders] if c.error is None and c.score > 0 and CATALOGUE[c.effect].related]
    specs2 = [TrialSpec(c.effect, str(candidates_fmu), channel, measured, op, probe, split_fitted(c.effect, c.fitted)[0],
                        max_evals, related=related_values(CATALOGUE[c.effect], probe, current), polish_only=True,
                        related_anchor=dict(anchors or {}), **short, discrepancy=known, angle=fit_angle)
              for c in lead]
    for c, r in zip(lead, ex.map(_guarded_fit, specs2, progress=progress, desc="related base parameters")
                    if specs2 else ()):
        if isinstance(r, Exception) or r[3] is None:
            continue
        joint = _candidate(CATALOGUE[c.effect], before, r[0], c.n_evaluations + r[2], r[3], measured, op, z1, z2,
                           known, fit_angle)
        if joint.lsd_after_db < c.lsd_after_db:
            cands[cands.index(c)] = joint
    cands.sort(key=lambda c: -c.score)

    held_names: tuple[str, ...] = ()
    runup_name = None
    if len(recs) > 1:
        # held-out records: the other steady ones at their own operating points, the end of each
        # run-up along its measured speed; the base model and every candidate that fits are run
        # there, all in parallel (candidates x records)
        slip = op.drive_hz - op.shaft_hz
        held: list[tuple[str, dict]] = []
        for r in steady[1:]:
            c2 = conds[r.name]
            held.append((r.name, dict(measured=c2.measured, sample_rate=r.sample_rate, load=r.load,
                                      operating=c2.operating, discrepancy=discrepancy.get(r.name),
                                      angle=angle_of(r, c2.measured.size))))
        for r in runups:
            if r.shaft_hz is None:
                raise ParameterError(f"run-up {r.name} has no tachometer, encoder or speed channel: its speed "
                                     "profile is needed to simulate it")
            m = int(round(min(held_out_runup, r.signal.size / r.sample_rate) * r.sample_rate))
            held.append((r.name, dict(measured=r.signal[-m:], sample_rate=r.sample_rate, load=r.load,
                                      shaft_hz=r.shaft_hz[-m:], slip_hz=slip * r.load / op.load if op.load else slip,
                                      discrepancy=discrepancy.get(r.name), angle=angle_of(r, m))))
        fitting = [c for c in cands if fits(before, c, min_cut, min_db)]
        # nothing to test when no candidate fits: the base model is not run on the held-out records
        tasks = [HeldOutSpec(name, str(candidates_fmu), dict(probe), channel, solver_step=solver_step, **kw)
                 for name, kw in held] if fitting else []
        tasks += [HeldOutSpec(name, str(candidates_fmu), {**probe, **c.fitted}, channel, solver_step=solver_step, **kw)
                  for c in fitting for name, kw in held]
        out = ex.map(guarded_held_out, tasks, progress=progress, desc="held-out records") if tasks else []
        base_lsd = {name: out[i] for i, (name, _) in enumerate(held)} if fitting else {}
        bad = [f"{n}: {v}" for n, v in base_lsd.items() if isinstance(v, Exception)]
        if bad:
            raise ParameterError("the current model does not run on the held-out record " + bad[0])
        for j, c in enumerate(fitting):
            vals = out[len(held) * (j + 1): len(held) * (j + 2)]
            ho = tuple((name, float(base_lsd[name]), float(v) if not isinstance(v, Exception) else math.inf)
                       for (name, _), v in zip(held, vals))
            cands[cands.index(c)] = replace(c, held_out=ho)
        held_names = tuple(name for name, _ in held)
        shafts = {r.name: conds[r.name].operating.shaft_hz for r in steady}
        base_recs = None
        if encoder and given is not None and not isinstance(given, Mapping):
            from twin.effects.baseline import pair
            base_recs = pair(recs, given)
        survey = survey_records(steady, runups[0] if runups else None, channel, z1, z2, shafts,
                                encoder=encoder, baseline=base_recs)
        runup_name = survey.runup
        from twin.effects.signatures import signature
        cands = [replace(c, **dict(zip(("signature_present", "signature"), signature(c.effect, c.fitted, survey))))
                 if c.error is None else c for c in cands]

    verdict, missing, unexplained, msg, tied = judge(before, cands, min_cut=min_cut, min_db=min_db)
    return Diagnosis(fit_rec.name, before.lsd_db, before.findings, tuple(cands), verdict, missing, unexplained, msg,
                     op, time.perf_counter() - t0, held_names, runup_name, tied,
                     tuple(sorted({d.record for d in discrepancy.values()})), encoder,
                     tuple(sorted({n for d in discrepancy.values() for n in d.repeats})))
