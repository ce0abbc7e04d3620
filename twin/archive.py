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
   ``tooth_damage_scatter``; :func:`twin.record_gears.tooth_errors`): random manufacturing errors and an uneven
   spread of the damage over the teeth, drawn from a stream of its own, so an archive without
   these keys is unchanged by them.  A worn record's teeth are worn from the drawn pinion under
   the record's quasi-static load sharing (:mod:`twin.degradation.tooth_wear`), so its pitch
   errors and run-out wear in as the depth grows.  Each record keeps its drawn pinion as ``gear_*`` record
   attributes (:func:`twin.record_gears.gear_attributes`), so a record names the gear it was simulated with;
   likewise each record can get a gear (wheel) of its own (``wheel_pitch_error``,
   ``wheel_runout``; :func:`twin.record_gears.draw_wheel`), from a third stream, kept as ``gear_wheel_*``;
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
from twin.record_gears import (TOOTH_ERROR_KEYS, WHEEL_ERROR_KEYS, draw_pinion, draw_wheel, gear_attributes,
                                pinion_parameters, tooth_error_bounds)

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
    # record attributes (twin.record_gears.PinionDraw.attributes plus the per-tooth arrays set in the FMU,
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


def load_sharing(run, mesh: dict, load_torque: float):
    """The quasi-static mesh of a worn record (its pair stiffness, worn profile and brake torque
    [N.m]), under which its pinion's teeth are worn (twin.record_gears.pinion_parameters); None
    for a pitting run, whose teeth do not wear."""
    from twin.degradation._nodes import node_array
    from twin.degradation.tooth_wear import ToothLoadSharing

    if run.model != "wear" or run.geometry is None:
        return None
    if not load_torque > 0:
        raise SimulationError(f"a worn record needs a brake torque > 0 N.m to wear its teeth, got {load_torque!r}")
    k = run.mesh_stiffness_scale * node_array(mesh, "k_pair")
    return ToothLoadSharing.for_gears(run.geometry, k, load_torque / run.geometry.base_radius_gear,
                                      node_array(mesh, "profile_deviation"))


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
                gear = pinion_parameters(pinion, params[0], mesh, load_sharing(run, mesh, t_load))
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
