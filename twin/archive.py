"""The degradation archive: labelled vibration records for each damage stage (source domain).

``build_archive(scenario)``:

1. runs the scenario's degradation (:func:`twin.degradation_run.run_degradation`) from the
   healthy mesh to its stop criterion; each update gives the damage measure (pitting density,
   or mean wear depth in m) and the FMU mesh parameters at that damage;
2. for every stage [lo, hi) of ``archive.stages``, draws ``records_per_stage`` damage values
   uniformly in the stage, interpolates the mesh parameters at each value between the
   updates around it, and scatters the operating point (speed and load, relative normal
   scatter) with a per-record seed;
3. optionally gives each record its own pinion (``pitch_error``, ``runout``,
   ``tooth_damage_scatter``; :func:`tooth_errors`): random manufacturing errors and an uneven
   spread of the damage over the teeth, drawn from a stream of its own, so an archive without
   these keys is unchanged by them.  Each record keeps its drawn pinion as ``gear_*`` record
   attributes (:func:`gear_attributes`), so a record names the gear it was simulated with;
   likewise each record can get a gear (wheel) of its own (``wheel_pitch_error``,
   ``wheel_runout``; :func:`draw_wheel`), from a third stream, kept as ``gear_wheel_*``;
4. simulates the records in parallel (local processes by default, Dask when the scenario's
   ``executor`` says so), each ``settle_time`` + ``record_duration`` seconds long, keeps the
   last ``record_duration`` seconds, and adds white measurement noise relative to the record's RMS.

The result is deterministic for a given scenario and seed, whatever the executor and worker
count. It is written atomically to HDF5 in the measurement layout (one group per record).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twin.errors import ScenarioError, SimulationError
from twin.executor import make_executor
from twin.operating import operating_point
from twin.scenario import Scenario

ARCHIVE_FORMAT = "gear-twin-archive"


@dataclass(frozen=True)
class RecordTask:
    """Everything one worker needs to simulate one record (picklable)."""

    index: int
    fmu_path: str
    parameters: dict
    inputs: dict
    settle_time: float
    duration: float
    output_interval: float
    channels: tuple
    noise: float
    seed: int


def simulate_record(task: RecordTask) -> dict[str, np.ndarray]:
    """Simulate one archive record; returns channel -> (n,) float32 array (noise added)."""
    from twin.fmu import FMU
    from twin.plausibility import checked_capture
    with FMU(task.fmu_path) as fmu:
        fmu.setup(0.0, parameters=task.parameters, inputs=task.inputs)
        if task.settle_time > 0:
            fmu.capture(task.settle_time, task.output_interval, list(task.channels))
        block = checked_capture(fmu, task.settle_time + task.duration, task.output_interval, task.channels,
                                load=task.inputs.get("load_torque"), constant_inputs=True)
    rng = np.random.default_rng(task.seed)
    out = {}
    for j, c in enumerate(task.channels):
        x = block[:, j]
        if task.noise > 0:
            x = x + rng.normal(0.0, task.noise * float(np.sqrt(np.mean(x ** 2))), size=x.shape)
        out[c] = x.astype(np.float32)
    return out


@dataclass(frozen=True)
class Archive:
    labels: np.ndarray          # (n,) stage index
    damage: np.ndarray          # (n,) damage measure of each record
    speed: np.ndarray           # (n,) shaft speed [Hz]
    load: np.ndarray            # (n,) load torque [N.m]
    signals: dict               # channel -> (n, samples) float32
    sample_rate: float
    stages: tuple               # stage boundaries
    damage_kind: str            # "pitting_density" or "wear_depth"
    path: Path | None = None
    # per record, the drawn pinion and wheel when the archive has tooth errors: their ``gear_*``
    # record attributes (PinionDraw.attributes plus the per-tooth arrays set in the FMU,
    # WheelDraw.attributes); None without
    gears: tuple | None = None


def interpolate_parameters(damages: np.ndarray, parameter_sets: list[dict], value: float) -> dict:
    """Mesh parameters at damage ``value``, linear between the two updates that bracket it."""
    damages = np.asarray(damages, dtype=float)
    if value > damages[-1] + 1e-12 or value < damages[0] - 1e-12:
        raise SimulationError(f"damage {value:.4g} is outside the simulated range "
                              f"[{damages[0]:.4g}, {damages[-1]:.4g}]; extend the degradation stop criterion")
    i = int(np.clip(np.searchsorted(damages, value, side="right") - 1, 0, len(damages) - 2))
    d0, d1 = damages[i], damages[i + 1]
    w = 0.0 if d1 == d0 else (value - d0) / (d1 - d0)
    a, b = parameter_sets[i], parameter_sets[i + 1]
    return {k: (1 - w) * a[k] + w * b[k] for k in a}


def stage_damage(draw: np.random.Generator, lo: float, hi: float, spec) -> float:
    """Damage of one record in the stage [lo, hi), per the archive's ``damage_sampling``.

    ``uniform`` (default) spreads the records over the stage, so records near a boundary look like
    the next stage. ``snapshot`` centres them on the stage with a normal scatter of
    ``damage_scatter`` x the stage width, clipped to the stage: an endurance test records its
    vibration at inspection points, which is what the paper's stages are.
    """
    if spec.get("damage_sampling", "uniform") == "snapshot":
        sd = float(spec.get("damage_scatter", 0.1)) * (hi - lo)
        return float(np.clip(0.5 * (lo + hi) + sd * draw.standard_normal(), lo, np.nextafter(hi, lo)))
    return float(draw.uniform(lo, hi))


TOOTH_ERROR_KEYS = ("pitch_error", "runout", "tooth_damage_scatter")
PITTING_LOSS_CAP = 0.95     # a tooth keeps at least 5 % of its pair stiffness, as a pitted flank does


def runout_deviation(runout: float, phase: float, teeth: int) -> np.ndarray:
    """(teeth,) extra material loss [m] of an eccentric pinion's teeth: a once-per-revolution
    sinusoid, ``runout`` peak to peak, >= 0, tooth 1 at angle ``phase`` [rad]."""
    return 0.5 * runout * (1.0 - np.cos(2 * np.pi * np.arange(teeth) / teeth + phase))


@dataclass(frozen=True)
class PinionDraw:
    """One record's drawn pinion (:func:`draw_pinion`), before it meets the record's damage.

    Attributes
    ----------
    pitch_error_sd : float
        Drawn sd of the per-tooth pitch deviations [m].
    runout : float
        Drawn peak-to-peak run-out [m].
    runout_phase : float
        Angle of tooth 1 on the run-out sinusoid [rad].
    tooth_damage_scatter : float
        Drawn relative sd of the per-tooth damage factors [-].
    pitch_deviation : ndarray (teeth,)
        Per-tooth pitch deviations [m] (unshifted).
    damage_factors : ndarray (teeth,)
        Per-tooth damage factors c_i [-], mean 1 in distribution.
    """

    pitch_error_sd: float
    runout: float
    runout_phase: float
    tooth_damage_scatter: float
    pitch_deviation: np.ndarray
    damage_factors: np.ndarray

    def attributes(self) -> dict:
        """The drawn magnitudes as record attributes (``gear_`` prefix, SI units)."""
        return {"gear_pitch_error_sd": self.pitch_error_sd, "gear_runout": self.runout,
                "gear_runout_phase": self.runout_phase, "gear_tooth_damage_scatter": self.tooth_damage_scatter}


def draw_pinion(draw: np.random.Generator, spec, teeth: int) -> PinionDraw:
    """Draw one record's pinion within the archive block's bounds (see :func:`tooth_errors`)."""
    pitch_bound, runout_bound, scatter_bound = (float(spec.get(k, 0.0)) for k in TOOTH_ERROR_KEYS)
    pitch_sd = draw.uniform(0.0, pitch_bound)
    pitch = pitch_sd * draw.standard_normal(teeth)
    runout = draw.uniform(0.0, runout_bound)
    phase = draw.uniform(0.0, 2 * np.pi)
    scatter = draw.uniform(0.0, scatter_bound)
    c = draw.gamma(1.0 / scatter ** 2, scatter ** 2, teeth) if scatter > 0 else np.ones(teeth)
    return PinionDraw(float(pitch_sd), float(runout), float(phase), float(scatter), np.asarray(pitch, float),
                      np.asarray(c, float))


WHEEL_ERROR_KEYS = ("wheel_pitch_error", "wheel_runout")


@dataclass(frozen=True)
class WheelDraw:
    """One record's drawn gear (the wheel, 52 teeth in the rig): its tooth positions.

    Attributes
    ----------
    pitch_error_sd : float
        Drawn sd of the single pitch deviations [m].
    runout : float
        Drawn peak-to-peak run-out [m].
    runout_phase : float
        Angle of tooth 1 on the run-out sinusoid [rad].
    deviation : ndarray (teeth,)
        ``wheel_tooth_deviation_offset`` [m]: cumulative pitch deviation plus run-out, shifted so
        that the least-cut tooth has zero.
    """

    pitch_error_sd: float
    runout: float
    runout_phase: float
    deviation: np.ndarray

    def attributes(self) -> dict:
        """The drawn gear as record attributes (``gear_wheel_`` prefix, SI units)."""
        return {"gear_wheel_pitch_error_sd": self.pitch_error_sd, "gear_wheel_runout": self.runout,
                "gear_wheel_runout_phase": self.runout_phase,
                "gear_wheel_tooth_deviation_offset": np.asarray(self.deviation, float)}

    def parameters(self) -> dict[str, float]:
        """The FMU parameters ``wheel_tooth_deviation_offset[1..teeth]`` [m]."""
        return {f"wheel_tooth_deviation_offset[{i + 1}]": float(v) for i, v in enumerate(self.deviation)}


def draw_wheel(draw: np.random.Generator, spec, teeth: int) -> WheelDraw:
    """Draw one record's gear within the archive block's bounds (``wheel_pitch_error``,
    ``wheel_runout`` [m], absent = 0), each magnitude uniform between zero and its bound.

    The pinion's tooth positions are drawn independent from tooth to tooth
    (:func:`draw_pinion`).  The gear's follow ISO 1328's definition instead: the single pitch
    deviations (tooth to tooth spacing) are independent normal, and a tooth's position deviation
    is their sum from tooth 1, the cumulative pitch deviation, which closes over the revolution
    (the spacings sum to the circumference).  Its energy sits at the gear's first few shaft
    orders, which is where a hobbed gear's errors are, with run-out on top at the first.
    """
    pitch_sd = draw.uniform(0.0, float(spec.get("wheel_pitch_error", 0.0)))
    single = pitch_sd * draw.standard_normal(teeth)
    runout = draw.uniform(0.0, float(spec.get("wheel_runout", 0.0)))
    phase = draw.uniform(0.0, 2 * np.pi)
    cumulative = np.cumsum(single - single.mean())      # closed: tooth z + 1 is tooth 1 again
    dev = cumulative + runout_deviation(runout, phase, teeth)
    return WheelDraw(float(pitch_sd), float(runout), float(phase), dev - dev.min())


def _profile(parameters: dict, name: str) -> np.ndarray:
    """The FMU array ``name[1..n]`` of ``parameters`` in index order (empty when absent).

    Unlike :func:`twin.degradation._nodes.node_array` it accepts a single node, as a flank
    that is the same all along the path is written in the tests."""
    keys = sorted((k for k in parameters if k.startswith(name + "[")), key=lambda k: int(k[len(name) + 1:-1]))
    return np.array([parameters[k] for k in keys], dtype=float)


def tooth_compliance_factors(k_healthy: np.ndarray, k_damaged: np.ndarray, damage_factors: np.ndarray,
                             samples_per_segment: int = 50) -> np.ndarray:
    """Per-tooth stiffness multipliers of a pinion whose teeth are pitted unevenly.

    The uniform damage lowers the pair stiffness along the path of contact from ``k_healthy`` to
    ``k_damaged`` (the FMU's ``k_pair`` nodes, equally spaced in roll, interpolated piecewise
    linearly as the FMU does), a local loss ``d(u) = 1 - k_damaged(u) / k_healthy(u)``.  Tooth i is
    pitted ``c_i`` times as much in the same zone: its pair stiffness would be
    ``k_healthy(u) (1 - min(c_i d(u), 0.95))``.  The FMU scales the common profile by one number per
    tooth, so the number chosen keeps the tooth's *mean compliance* along the path, 1/k averaged
    over u: that is the tooth's mean quasi-static deflection under a given mesh force, whose
    differences from tooth to tooth are what puts energy at the shaft-order sidebands.  (Keeping
    the mean stiffness instead, the rule before 2026-11-24, underestimates how far a badly pitted
    tooth gives way: where its local loss nears the cap, its compliance grows as 1 / (1 - loss).)
    For uniform damage (``c_i = 1``), or a loss that is the same all along the path, both rules
    agree: (1 - min(c_i L, 0.95)) / (1 - L).

    Parameters
    ----------
    k_healthy, k_damaged : ndarray, shape (n,)
        Pair stiffness nodes [N/m] of the healthy and of the uniformly damaged flank.
    damage_factors : ndarray, shape (teeth,)
        c_i [-], >= 0.
    samples_per_segment : int
        Points per node interval of the grid the compliance is averaged on.

    Returns
    -------
    ndarray, shape (teeth,)
        ``tooth_stiffness_factor`` [-]; all ones when the damaged flank is nowhere softer.
    """
    from twin.degradation._nodes import interp_nodes, node_xi

    c = np.asarray(damage_factors, dtype=float)
    kh, kd = np.asarray(k_healthy, dtype=float), np.asarray(k_damaged, dtype=float)
    if kh.size == 0 or not np.any(kd < kh):
        return np.ones(c.size)
    u = node_xi(max(1, (kh.size - 1) * samples_per_segment) + 1)
    kh_u = interp_nodes(kh, u)
    # A flank the uniform damage has stripped bare (k_damaged 0 at a node) would make every
    # tooth's compliance infinite; the cap keeps the comparison finite for it too.
    loss = np.minimum(1.0 - interp_nodes(kd, u) / kh_u, PITTING_LOSS_CAP)      # (U,)
    common_k = kh_u * (1.0 - loss)
    tooth_k = kh_u * (1.0 - np.minimum(c[:, None] * loss, PITTING_LOSS_CAP))       # (teeth, U)
    return np.mean(1.0 / common_k) / np.mean(1.0 / tooth_k, axis=1)


def pinion_parameters(pinion: PinionDraw, healthy: dict, damaged: dict) -> dict[str, float]:
    """Per-tooth FMU parameters of a drawn pinion at a record's damage (see :func:`tooth_errors`)."""
    teeth = pinion.pitch_deviation.size
    c = pinion.damage_factors
    offset = pinion.pitch_deviation + runout_deviation(pinion.runout, pinion.runout_phase, teeth)
    factor = tooth_compliance_factors(_profile(healthy, "k_pair"), _profile(damaged, "k_pair"), c)
    depth = _profile(damaged, "profile_deviation")
    mean_depth = float(depth.mean()) if depth.size else 0.0
    if mean_depth > 0:
        offset = offset + (c - 1.0) * mean_depth
    offset = offset - offset.min()
    out = {f"tooth_deviation_offset[{i + 1}]": float(v) for i, v in enumerate(offset)}
    out.update({f"tooth_stiffness_factor[{i + 1}]": float(v) for i, v in enumerate(factor)})
    return out


def tooth_errors(draw: np.random.Generator, spec, teeth: int, healthy: dict, damaged: dict) -> dict[str, float]:
    """Per-pinion-tooth FMU parameters of one record's gear: manufacturing errors and uneven damage.

    Every real pinion has pitch errors and some run-out, and its damage is not the same on every
    tooth (pits start on single teeth).  Both make the vibration differ from tooth to tooth, i.e.
    put energy at shaft-order sidebands of the mesh harmonics, which a twin with identical teeth
    does not have.  Each record draws a pinion of its own, with each magnitude uniform between
    zero and the archive's bound, so the archive covers gears from perfect to the bound:

    * ``pitch_error`` [m]: bound of the sd of the per-tooth pitch deviations (normal, independent);
    * ``runout`` [m]: bound of the peak-to-peak run-out, a once-per-revolution sinusoid of random
      phase over the teeth;
    * ``tooth_damage_scatter`` [-]: bound of the relative sd of per-tooth damage factors c_i
      (gamma distributed, mean 1, so the stage's mean damage is kept).  Pitting: where the uniform
      damage loses d(u) of the pair stiffness, tooth i loses min(c_i d(u), 0.95); the FMU takes
      one ``tooth_stiffness_factor[i]`` per tooth on top of the uniform ``k_pair``, chosen to keep
      the tooth's mean compliance along the path (:func:`tooth_compliance_factors`).  Wear: tooth
      i is worn c_i times the mean depth, written as the extra offset (c_i - 1) x mean
      ``profile_deviation``.  Either way one number per tooth stands in for the damage's shape
      along that tooth's flank, which is taken to be the uniform damage's.

    The offsets are ``tooth_deviation_offset[1..teeth]`` [m], shifted so that the least-cut tooth
    has zero (a common offset only moves the static deflection).

    Parameters
    ----------
    draw : the generator of the gear draws (one call per record).
    spec : the archive block (the three keys above, each >= 0; absent = 0).
    teeth : pinion tooth count (the FMU's ``tooth_deviation_offset`` array size).
    healthy, damaged : FMU mesh parameters (``k_pair[j]``, ``profile_deviation[j]``) of the healthy
        flank and at the record's damage.

    Returns
    -------
    dict: ``tooth_deviation_offset[i]`` [m] and ``tooth_stiffness_factor[i]`` [-], i = 1..teeth.
    """
    return pinion_parameters(draw_pinion(draw, spec, teeth), healthy, damaged)


GEAR_ARRAYS = ("tooth_deviation_offset", "tooth_stiffness_factor")


def gear_attributes(pinion: PinionDraw, parameters: dict, teeth: int) -> dict:
    """A record's ``gear_*`` attributes: the drawn magnitudes and the (teeth,) arrays set in the FMU
    (``gear_tooth_deviation_offset`` [m], ``gear_tooth_stiffness_factor`` [-])."""
    out = pinion.attributes()
    for name in GEAR_ARRAYS:
        out[f"gear_{name}"] = np.array([parameters[f"{name}[{i}]"] for i in range(1, teeth + 1)])
    return out


def tooth_error_bounds(scenario: Scenario, keys: tuple = TOOTH_ERROR_KEYS) -> tuple[float, ...]:
    """The archive block's bounds of ``keys`` (default ``pitch_error``, ``runout``,
    ``tooth_damage_scatter``; or :data:`WHEEL_ERROR_KEYS`), absent = 0.

    The scenario schema checks them in a file; a block built in code (``with_overrides``) is
    checked here, so a negative or non-numeric bound is a :class:`ScenarioError` naming every bad
    key rather than a silently flipped gear.
    """
    spec = scenario.archive or {}
    bounds, problems = [], []
    for key in keys:
        value = spec.get(key, 0.0)
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value >= 0
        if not ok:
            problems.append((str(scenario.source), f"archive.{key}", f"must be a finite number >= 0, got {value!r}"))
        bounds.append(float(value) if ok else 0.0)
    if problems:
        raise ScenarioError(problems)
    return tuple(bounds)


def _parameter_names(fmu_path) -> set[str]:
    from twin.fmu import FMU
    with FMU(fmu_path) as fmu:
        return {v.name for v in fmu.parameters}


def _pinion_teeth(names: set[str], fmu_path) -> int:
    teeth = sum(1 for n in names if n.startswith("tooth_deviation_offset["))
    if teeth == 0 or any(f"tooth_stiffness_factor[{i}]" not in names for i in range(1, teeth + 1)):
        raise SimulationError(f"the FMU {fmu_path} has no per-tooth parameters (tooth_deviation_offset[i], "
                              f"tooth_stiffness_factor[i]); remove {', '.join(TOOTH_ERROR_KEYS)} from the archive "
                              "block or use a model that has them")
    return teeth


def _wheel_teeth(names: set[str], fmu_path) -> int:
    teeth = sum(1 for n in names if n.startswith("wheel_tooth_deviation_offset["))
    if teeth == 0:
        raise SimulationError(f"the FMU {fmu_path} has no per-gear-tooth parameters "
                              f"(wheel_tooth_deviation_offset[i]); remove {', '.join(WHEEL_ERROR_KEYS)} from the "
                              "archive block or use a model that has them, such as "
                              "fmu: GearTwin.Variants.Gearbox21WheelErrors")
    return teeth


def pinion_teeth(fmu_path) -> int:
    """Number of ``tooth_deviation_offset[i]`` parameters of the FMU; SimulationError if it has none."""
    return _pinion_teeth(_parameter_names(fmu_path), fmu_path)


def wheel_teeth(fmu_path) -> int:
    """Number of ``wheel_tooth_deviation_offset[i]`` parameters of the FMU; SimulationError if none."""
    return _wheel_teeth(_parameter_names(fmu_path), fmu_path)


def nominal_operating_point(scenario: Scenario) -> tuple[float, float]:
    """Drive speed [Hz] and brake load [N.m] at the scenario's start (20 Hz / 20 N.m if not given)."""
    t0 = scenario.start_time
    speed = scenario.inputs["motor_speed_ref"](t0) / (2 * math.pi) if "motor_speed_ref" in scenario.inputs else 20.0
    load = scenario.inputs["load_torque"](t0) if "load_torque" in scenario.inputs else 20.0
    return speed, load


def check_stages_reached(damages: np.ndarray, bounds: list[float]) -> None:
    """Raise :class:`SimulationError` if the degradation run stops short of the last stage boundary."""
    if bounds[-1] > damages[-1] * (1 + 1e-9):
        raise SimulationError(f"the degradation run reached {damages[-1]:.4g}, short of the last stage boundary "
                              f"{bounds[-1]:.4g}; raise its stop criterion or max_updates")


def simulate_records(tasks: list[RecordTask], scenario: Scenario, *, executor=None, progress: bool = True,
                     what: str = "archive") -> list[dict]:
    """Simulate record tasks on ``executor`` (default: the scenario's); raise if any failed."""
    ex = executor or make_executor(scenario.executor)
    try:
        results = ex.map(simulate_record, tasks, progress=progress, desc=f"{scenario.name} {what}")
    finally:
        if executor is None:
            ex.close()
    failed = [(t.index, r) for t, r in zip(tasks, results) if isinstance(r, Exception)]
    if failed:
        i, err = failed[0]
        raise SimulationError(f"{len(failed)} of {len(tasks)} {what} records failed; first (record {i}): {err}")
    return results


def build_archive(scenario: Scenario, output: str | Path | None = None, *, progress: bool = True,
                  fmu_path: Path | None = None, executor=None) -> Archive:
    """Build the archive described by ``scenario.archive`` (see the module docstring)."""
    from twin.degradation_run import run_degradation

    spec = scenario.archive
    if spec is None:
        raise ScenarioError([(str(scenario.source), "archive", "the scenario has no archive block")])
    path = Path(output) if output is not None else None
    if path is not None:
        from twin.results import check_hdf5_path
        check_hdf5_path(path, "an archive")
    fmu_file = fmu_path or scenario.fmu_path()
    # the gear checks come before the degradation run, which takes a while
    gear_bounds = tooth_error_bounds(scenario)
    wheel_bounds = tooth_error_bounds(scenario, WHEEL_ERROR_KEYS)
    pinion_errors, wheel_errors = any(b > 0 for b in gear_bounds), any(b > 0 for b in wheel_bounds)
    names = _parameter_names(fmu_file) if pinion_errors or wheel_errors else set()    # the FMU opened once
    teeth = _pinion_teeth(names, fmu_file) if pinion_errors else 0
    z_wheel = _wheel_teeth(names, fmu_file) if wheel_errors else 0
    if z_wheel and round(float(scenario.parameters.get("z2", z_wheel))) != z_wheel:
        raise ScenarioError([(str(scenario.source), "parameters.z2",
                              f"the FMU's gear has {z_wheel} teeth (wheel_tooth_deviation_offset), "
                              f"got z2 = {scenario.parameters['z2']!r}")])
    run = run_degradation(scenario, None, fmu_path=fmu_file, progress=progress, channels=("accel_pinion_casing",))
    damages = run.damage
    if np.any(np.diff(damages) < 0):
        raise SimulationError("the damage measure decreased during the degradation run")
    params = [s.parameters for s in run.stages]
    bounds = [float(b) for b in spec["stages"]]
    check_stages_reached(damages, bounds)
    per_stage = int(spec.get("records_per_stage", 50))
    duration = float(spec.get("record_duration", 0.2))
    settle = float(spec.get("settle_time", 0.05))
    speed_sd = float(spec.get("speed_scatter", 0.0))
    load_sd = float(spec.get("load_scatter", 0.0))
    noise = float(spec.get("noise", 0.0))
    channels = tuple(scenario.outputs or ("accel_pinion_casing",))
    nominal_speed, nominal_load = nominal_operating_point(scenario)

    seq = np.random.SeedSequence(scenario.seed)
    draw = np.random.default_rng(seq.spawn(1)[0])
    record_seeds = seq.spawn(len(bounds) * per_stage + 1)[1:]
    # The pinions and the wheels have streams of their own: turning their errors on or off leaves
    # every other draw.
    gear_draw = np.random.default_rng(seq.spawn(1)[0])
    wheel_draw = np.random.default_rng(seq.spawn(1)[0])
    tasks, labels, dmg, speeds, loads, gears = [], [], [], [], [], []
    k = 0
    for s, (lo, hi) in enumerate(zip(bounds, bounds[1:])):
        for _ in range(per_stage):
            d = stage_damage(draw, lo, hi, spec)
            f = nominal_speed * (1 + speed_sd * float(draw.standard_normal()))
            t_load = nominal_load * (1 + load_sd * float(draw.standard_normal()))
            start, inputs = operating_point(f, t_load)   # each record starts at its own steady point
            mesh = interpolate_parameters(damages, params, d)
            p = {**scenario.parameters, **mesh, **start}
            if teeth:
                pinion = draw_pinion(gear_draw, spec, teeth)
                gear = pinion_parameters(pinion, params[0], mesh)
                # on top of any per-tooth damage the scenario itself sets
                gear = {n: v * scenario.parameters.get(n, 1.0) if n.startswith("tooth_stiffness")
                        else v + scenario.parameters.get(n, 0.0) for n, v in gear.items()}
                p.update(gear)
            if z_wheel:
                wheel = draw_wheel(wheel_draw, spec, z_wheel)
                p.update({n: v + scenario.parameters.get(n, 0.0) for n, v in wheel.parameters().items()})
            if teeth or z_wheel:
                gears.append({**(gear_attributes(pinion, gear, teeth) if teeth else {}),
                              **(wheel.attributes() if z_wheel else {})})
            tasks.append(RecordTask(k, str(fmu_file), p, inputs, settle, duration, scenario.output_interval,
                                    channels, noise, int(record_seeds[k].generate_state(1)[0])))
            labels.append(s)
            dmg.append(d)
            speeds.append(f)
            loads.append(t_load)
            k += 1
    results = simulate_records(tasks, scenario, executor=executor, progress=progress)
    signals = {c: np.stack([r[c] for r in results]) for c in channels}
    kind = "pitting_density" if run.model == "pitting" else "wear_depth"
    archive = Archive(np.array(labels), np.array(dmg), np.array(speeds), np.array(loads), signals,
                      scenario.sample_rate, tuple(bounds), kind, path, tuple(gears) if gears else None)
    if path is not None:
        write_archive(archive, path, scenario, run)
    return archive


def write_archive(archive: Archive, path: Path, scenario: Scenario, run=None) -> Path:
    """HDF5, measurement layout: ``/records/<id>`` groups with 1-D channels and record attributes."""
    import h5py

    from twin._atomic import atomic_path
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["format"] = ARCHIVE_FORMAT
            f.attrs["format_version"] = 1
            f.attrs["sample_rate"] = archive.sample_rate
            f.attrs["damage_kind"] = archive.damage_kind
            f.attrs["stages"] = np.asarray(archive.stages)
            # the test's operating point, which the assessor's window length and its checks of rig
            # records follow (twin.transfer.settings)
            f.attrs["nominal_speed"], f.attrs["nominal_load"] = nominal_operating_point(scenario)
            f.attrs["scenario"] = json.dumps(scenario.raw, default=str)
            f.attrs["seed"] = scenario.seed
            recs = f.create_group("records", track_order=True)
            for i in range(archive.labels.size):
                g = recs.create_group(f"{i:06d}")
                g.attrs["label"] = int(archive.labels[i])
                g.attrs["damage"] = float(archive.damage[i])
                g.attrs["sample_rate"] = archive.sample_rate
                g.attrs["nominal_speed"] = float(archive.speed[i])
                g.attrs["load"] = float(archive.load[i])
                for name, value in (archive.gears[i] if archive.gears is not None else {}).items():
                    g.attrs[name] = value
                for c, arr in archive.signals.items():
                    ds = g.create_dataset(c, data=arr[i])
                    ds.attrs["unit"] = "m/s2" if c.startswith("accel") else ""
            if run is not None:
                d = f.create_group("degradation")
                d.create_dataset("cycles", data=run.cycles)
                d.create_dataset("damage", data=run.damage)
    return path


def read_archive(path: str | Path) -> Archive:
    import h5py
    path = Path(path)
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != ARCHIVE_FORMAT:
            raise SimulationError(f"{path} is not a gear-twin archive")
        keys = list(f["records"])
        first = f["records"][keys[0]]
        channels = list(first)
        signals = {c: np.stack([f["records"][k][c][:] for k in keys]) for c in channels}
        attrs = [f["records"][k].attrs for k in keys]
        gears = tuple({n: (a[n] if np.ndim(a[n]) else float(a[n])) for n in a if n.startswith("gear_")}
                      for a in attrs)
        return Archive(np.array([a["label"] for a in attrs]), np.array([a["damage"] for a in attrs]),
                       np.array([a["nominal_speed"] for a in attrs]), np.array([a["load"] for a in attrs]),
                       signals, float(f.attrs["sample_rate"]), tuple(f.attrs["stages"]),
                       str(f.attrs["damage_kind"]), path, gears if any(gears) else None)
