"""The benchmark's "measured" target domain: the twin's damage stages seen through a rig the
twin does not model.

:func:`make_target_domain` simulates records of the same damage stages as the source archive
(``scenario.archive.stages``; the damage is drawn within each stage by the archive's own rule,
:func:`twin.archive.stage_damage`) on a *variant* of the model, then passes the acceleration through a measurement chain
that the source simulation does not have.  Every effect is physically motivated and none of
them is known to the assessor:

===========================  ==================================================================
effect                       how it is emulated (defaults in :class:`TargetShift`)
===========================  ==================================================================
pinion run-out               ``tooth_deviation_offset[i] = runout/2 * (1 - cos(2 pi (i-1)/z1 +
                             phi))``: an eccentric pinion's transmission error, once per pinion
                             revolution, with a random phase ``phi`` per record
                             (4 um peak to peak, a precision-ground test-rig pinion)
sensor orientation           ``sensor_angle_pinion`` = 0.2 rad (11 deg off vertical), so the
                             horizontal pedestal motion leaks into the channel
softer pedestal              ``kx6``, ``ky6`` scaled by 0.85 (a different foundation)
sensor-mount resonance       2nd-order base-excitation transmissibility of the accelerometer
                             mount, ``H(s) = (w0/Q s + w0^2) / (s^2 + w0/Q s + w0^2)``,
                             ``f0`` = 4 kHz, Q = 5 (a magnetic-base mount), bilinear transform at
                             the simulation rate: a different transfer path
sensor gain error            per-record log-normal gain, 10 % standard deviation
measurement noise            white, 8 % of the record RMS (the archive has 5 %)
operating scatter            speed and load scattered by 2 % and 10 % (the scenarios'
                             archives: 1 % and 5 %; the benchmark's source archive: 3 % and
                             15 %)
===========================  ==================================================================

A first, harsher default (10 um run-out, 3 kHz / Q 8 mount, 0.3 rad, 0.8 stiffness, 10 % noise)
buried the pitting stages: a linear classifier of normalised log spectra trained and tested
*within* that target reached 31 % (chance 17 %, 63 % within the source), and in a 20-epoch trial
the source-only CNN stayed at chance (17 %) and the proposed method reached 52 %.  The defaults
were moderated once to the values above (within-target 53 %), on 2026-11-22.
No method hyperparameter was changed for it.

The records keep their stage ``label`` and ``damage`` **for evaluation only**: the assessor's
``fit`` never reads a target label (see ``twin/transfer/README.md``).  The simulation itself
reuses the archive's pieces (:class:`twin.archive.RecordTask`, :func:`twin.archive.simulate_record`,
:func:`twin.archive.interpolate_parameters`) and the scenario's executor, so it is as
deterministic and as parallel as ``twin archive``.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from twin.errors import ParameterError, ScenarioError

__all__ = ["TargetShift", "make_target_domain", "resonator", "runout_offsets"]

N_PINION_TEETH = 19


@dataclass(frozen=True)
class TargetShift:
    """The unmodelled effects of the target rig (see the module docstring for their physics).

    Attributes
    ----------
    runout : float
        Peak-to-peak pinion run-out expressed as per-tooth material loss [m].
    sensor_angle : float
        Accelerometer axis ``sensor_angle_pinion`` [rad].
    pedestal_stiffness_factor : float
        Multiplier of ``kx6`` and ``ky6`` [-].
    resonance_hz : float
        Sensor-mount resonance frequency [Hz]; 0 switches the resonator off.
    resonance_q : float
        Its quality factor [-].
    gain_error : float
        Standard deviation of the log of the per-record sensor gain [-].
    noise : float
        White measurement noise, relative to the record RMS [-].
    speed_scatter, load_scatter : float
        Relative standard deviations of the shaft speed and the load [-].
    """

    runout: float = 4e-6
    sensor_angle: float = 0.2
    pedestal_stiffness_factor: float = 0.85
    resonance_hz: float = 4000.0
    resonance_q: float = 5.0
    gain_error: float = 0.10
    noise: float = 0.08
    speed_scatter: float = 0.02
    load_scatter: float = 0.10

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
                raise ParameterError(f"TargetShift.{name} must be a finite number >= 0, got {value!r}")
        if self.resonance_hz > 0 and self.resonance_q <= 0:
            raise ParameterError(f"TargetShift.resonance_q must be > 0, got {self.resonance_q!r}")


def runout_offsets(runout: float, phase: float, teeth: int = N_PINION_TEETH) -> dict[str, float]:
    """``tooth_deviation_offset[1..teeth]`` [m] of an eccentric pinion (>= 0, ``runout`` peak to peak)."""
    from twin.record_gears import runout_deviation
    dev = runout_deviation(runout, phase, teeth)
    return {f"tooth_deviation_offset[{k + 1}]": float(d) for k, d in enumerate(dev)}


def resonator(x: np.ndarray, sample_rate: float, f0: float, q: float) -> np.ndarray:
    """Filter ``x`` (..., n) through the base-excitation transmissibility of a mount at ``f0`` [Hz].

    ``H(s) = (w0/Q s + w0^2) / (s^2 + w0/Q s + w0^2)``: unity at DC, about ``Q`` at ``f0``, a
    -20 dB/decade roll-off above.  Discretised by the bilinear transform with the resonance
    pre-warped, so ``f0`` stays where it is even close to Nyquist.
    """
    from scipy.signal import bilinear, lfilter

    if not 0 < f0 < sample_rate / 2:
        raise ParameterError(f"resonance frequency {f0!r} Hz must lie in (0, {sample_rate / 2:g}) Hz")
    w0 = 2 * sample_rate * math.tan(math.pi * f0 / sample_rate)   # pre-warped [rad/s]
    b, a = bilinear([w0 / q, w0 ** 2], [1.0, w0 / q, w0 ** 2], fs=sample_rate)
    return lfilter(b, a, x, axis=-1)


def check_target_request(source_scenario, output, records_per_stage, record_duration):
    """Check what every target-domain simulator is asked, before any simulation; return the
    scenario's archive block and the checked output path (``.h5``/``.hdf5``)."""
    from twin.measurements.write import _check_h5_path

    if not isinstance(records_per_stage, int) or records_per_stage < 1:
        raise ParameterError(f"records_per_stage must be a positive integer, got {records_per_stage!r}")
    if not (isinstance(record_duration, (int, float)) and record_duration > 0):
        raise ParameterError(f"record_duration must be > 0 [s], got {record_duration!r}")
    spec = source_scenario.archive
    if spec is None:
        raise ScenarioError([(str(source_scenario.source), "archive", "the scenario has no archive block")])
    return spec, _check_h5_path(output)     # fail on a bad path before minutes of simulation


def make_target_domain(source_scenario, output: str | Path, *, records_per_stage: int = 12,
                       record_duration: float = 0.4, seed: int = 1, shift: TargetShift | None = None,
                       run=None, fmu_path: Path | None = None, executor=None, progress: bool = True) -> Path:
    """Simulate the "measured" target domain of ``source_scenario`` and write it as measurements.

    Parameters
    ----------
    source_scenario : twin.scenario.Scenario
        The scenario of the source archive (degradation and archive blocks); its stage
        boundaries, nominal operating point, parameters, FMU and executor are reused.
    output : path
        Measurement HDF5 file to write (atomically), ``.h5``/``.hdf5``.
    records_per_stage : int
        Records simulated per damage stage.
    record_duration : float
        Length of each record [s] (after ``settle_time`` of the scenario's archive block).
    seed : int
        Seed of every random draw (damage, operating point, run-out phase, gain, noise).
    shift : TargetShift, optional
        The unmodelled effects; default :class:`TargetShift()`.
    run : twin.degradation_run.DegradationRun, optional
        The scenario's degradation run, if already computed (saves re-running it).

    Returns
    -------
    Path
        The written file: one record per simulation, channel ``accel_pinion_casing`` [m/s2] at the
        scenario's sample rate, attributes ``label`` (stage), ``damage``, ``nominal_speed``, ``load``
        (evaluation only), file metadata ``stages``, ``damage_kind``, ``target_shift`` (JSON).
    """
    from twin.archive import (RecordTask, check_stages_reached, interpolate_parameters, nominal_operating_point,
                              simulate_records, stage_damage)
    from twin.fmu import FMU
    from twin.measurements import MeasurementSet, Record, write_measurements
    from twin.operating import operating_point

    shift = shift or TargetShift()
    spec, target = check_target_request(source_scenario, output, records_per_stage, record_duration)
    fmu_file = fmu_path or source_scenario.fmu_path()
    if run is None:
        from twin.degradation_run import run_degradation
        run = run_degradation(source_scenario, None, fmu_path=fmu_file, progress=progress,
                              channels=("accel_pinion_casing",))
    damages = run.damage
    params = [s.parameters for s in run.stages]
    bounds = [float(b) for b in spec["stages"]]
    check_stages_reached(damages, bounds)
    settle = float(spec.get("settle_time", 0.05))
    sample_rate = float(source_scenario.sample_rate)
    nominal_speed, nominal_load = nominal_operating_point(source_scenario)
    with FMU(fmu_file) as fmu:
        defaults = fmu.parameter_values()
    variant = {"sensor_angle_pinion": shift.sensor_angle}
    for k in ("kx6", "ky6"):
        variant[k] = source_scenario.parameters.get(k, defaults[k]) * shift.pedestal_stiffness_factor

    seq = np.random.SeedSequence(seed)
    draw = np.random.default_rng(seq.spawn(1)[0])
    tasks, meta = [], []
    for s, (lo, hi) in enumerate(zip(bounds, bounds[1:])):
        for _ in range(records_per_stage):
            d = stage_damage(draw, lo, hi, source_scenario.archive or {})
            f = nominal_speed * (1 + shift.speed_scatter * float(draw.standard_normal()))
            t_load = nominal_load * (1 + shift.load_scatter * float(draw.standard_normal()))
            phase = float(draw.uniform(0, 2 * np.pi))
            gain = float(np.exp(shift.gain_error * draw.standard_normal()))
            start, inputs = operating_point(f, t_load)
            p = {**source_scenario.parameters, **interpolate_parameters(damages, params, d), **variant,
                 **runout_offsets(shift.runout, phase), **start}
            k = len(tasks)
            # noise=0: the noise is added after the mount and the gain, as a real sensor's would be.
            tasks.append(RecordTask(k, str(fmu_file), p, inputs, settle, float(record_duration),
                                    source_scenario.output_interval, ("accel_pinion_casing",), 0.0, k))
            meta.append((s, d, f, t_load, gain))
    results = simulate_records(tasks, source_scenario, executor=executor, progress=progress, what="target domain")
    noise_rng = np.random.default_rng(seq.spawn(2)[1])
    records = []
    for k, (res, (s, d, f, t_load, gain)) in enumerate(zip(results, meta)):
        x = res["accel_pinion_casing"].astype(np.float64)
        if shift.resonance_hz > 0:
            x = resonator(x, sample_rate, shift.resonance_hz, shift.resonance_q)
        x = gain * x
        x = x + noise_rng.normal(0.0, shift.noise * float(np.sqrt(np.mean(x ** 2))), size=x.shape)
        records.append(Record(f"rec{k:05d}", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"},
                              sample_rate, nominal_speed=f, load=t_load, label=s, damage=d))
    kind = "pitting_density" if run.model == "pitting" else "wear_depth"
    metadata = {"stages": np.asarray(bounds), "damage_kind": kind, "target_shift": json.dumps(asdict(shift)),
                "seed": int(seed), "source_scenario": source_scenario.name,
                "note": "labels and damage are for evaluation only"}
    return write_measurements(MeasurementSet(tuple(records), None, (), metadata), target)
