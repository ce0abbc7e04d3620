"""Degradation runs: the FMU and a degradation model coupled between co-simulation steps.

At each update (stage):

1. co-simulate a short window (``load_window``, default 0.1 s = two pinion revolutions at
   20 Hz) and sample the load each tooth pair carries along the path of contact
   (``roll[i]``, ``pair_force[i]``), the transmitted mesh force and the pinion speed;
2. record a vibration snippet (``record_duration``) for the stage;
3. advance the wear or pitting model by a jump of pinion cycles (cycle jumping: the load is
   assumed steady over the jump). Wear (:class:`~twin.degradation.wear.FlankWear`) shares the
   co-simulated mean mesh force among the tooth pairs by the loaded tooth contact analysis of
   the current worn flanks, both of them; pitting uses the sampled pair forces. The jump is the
   smaller of ``cycles_per_update`` and the cycles after which the largest local damage
   increment reaches ``max_increment`` (default 3 um of wear depth or 0.01 of pitting
   density), so the load is re-sampled as often as the damage needs;
4. turn the damage into the FMU's mesh parameters (``k_pair``, ``profile_deviation`` on the
   FMU's ``n_profile`` nodes; for pitting the per-tooth field ``tooth_pit_field``) and set them on
   the FMU, so the next window runs on the degraded mesh (with ``pair_stiffness: contact``, wear
   sets ``k_pair`` to the LTCA's single-pair secant stiffness at the mean mesh force,
   :func:`twin.degradation.mapping.contact_k_pair`).  The pits' field goes to the FMU whole,
   every tooth's own profile on the nodes (:mod:`twin.degradation.pitting_map`), so its
   tooth-to-tooth differences reach the mesh as shaft-order sidebands; the node fit's relative
   error is the stage's ``truncation_error["tooth_pit_field"]``.

The run stops on the scenario's criterion (pitting density, wear depth or cycles) or after
``max_updates``.  After every stage the stages so far are rewritten atomically to
``<stem>.partial<suffix>`` beside the output; only the complete run replaces the output itself
(and removes the partial file).  An interrupted or killed run therefore leaves an earlier
result untouched, and ``resume=True`` continues from the last stage of the partial file (or,
without one, extends the complete output, e.g. to a later stop criterion).  The
partial file carries the run's identity (:func:`run_identity`, a hash of the scenario and the
FMU); a partial file of another scenario or FMU is refused, never relabelled.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from twin._progress import progress_bar
from twin.errors import ScenarioError
from twin.fmu import FMU
from twin.orchestrator import check_compatibility
from twin.scenario import Scenario

#: Default log-sd of the per-tooth pitting strength factors (``degradation.tooth_scatter``): the
#: tooth-to-tooth life scatter of spur-gear pitting, Weibull slope e = 2.5 (Coy, Townsend &
#: Zaretsky, J. Lubr. Technol. 98 (1976) 267-276, from NASA gear fatigue tests), seen through the
#: law's cycle exponent m = 9/8: ln(lambda) has the sd (m / e) pi / sqrt(6) = 0.58.
DEFAULT_TOOTH_SCATTER = 0.58
ROLL = [f"roll[{i}]" for i in (1, 2, 3)]
FORCE = [f"pair_force[{i}]" for i in (1, 2, 3)]
#: The flank fields written per stage: pinion (``field``) and, for wear, the gear (``gear_field``).


@dataclass(frozen=True)
class Stage:
    """One update of a degradation run."""

    index: int
    cycles: float                       # pinion cycles run so far
    damage: float                       # pitting density (0-1) or mean wear depth [m]
    max_damage: float                   # max over the flank: density or depth [m]
    parameters: dict[str, float]        # mesh parameters in force during this stage's record
    field_xi: np.ndarray                # (n,) roll positions of the damage field
    field: np.ndarray                   # (n,) pitting density or wear depth [m]
    truncation_error: dict[str, float]
    vibration: dict[str, np.ndarray] = field(default_factory=dict)   # snippet per channel
    gear_field: np.ndarray | None = None   # (n,) wear depth of the gear flank [m] (wear runs)


@dataclass(frozen=True)
class DegradationRun:
    scenario: Scenario
    model: str                          # "pitting" or "wear"
    stages: tuple[Stage, ...]
    complete: bool
    sample_rate: float
    geometry: Any = None                # the GearPair the run wore or pitted (twin.degradation.GearPair)
    mesh_stiffness_scale: float = 1.0   # the FMU's factor on k_pair in the run

    @property
    def damage(self) -> np.ndarray:
        return np.array([s.damage for s in self.stages])

    @property
    def cycles(self) -> np.ndarray:
        return np.array([s.cycles for s in self.stages])

    def summary(self) -> str:
        last = self.stages[-1]
        what = (f"pitting density {100 * last.damage:.1f} %" if self.model == "pitting"
                else f"mean wear depth {1e6 * last.damage:.1f} um")
        return f"{what} after {last.cycles:.3g} cycles"


def _model(spec: dict[str, Any]):
    from twin.degradation import FatiguePitting, FlankWear
    coeffs = dict(spec.get("coefficients", {}))
    try:
        if spec["model"] == "pitting":
            return FatiguePitting(**coeffs)
        return FlankWear(**coeffs)
    except TypeError as exc:
        raise ScenarioError([("<scenario>", "degradation.coefficients", str(exc))]) from None


def manufactured_form(state, parameters, n_nodes: int):
    """The wear state with a scenario's ``profile_deviation[1..n]`` (material missing from the pinion
    flank [m], e.g. the as-manufactured profile a calibration fitted, ``mesh_form: fit``) added to the
    pinion flank's form, so the wear runs it in: a wear run rewrites ``profile_deviation`` from the
    flanks at every update, which would otherwise drop it after the first."""
    from twin.degradation import WearState
    from twin.degradation._nodes import interp_nodes
    nodes = [float(parameters.get(f"profile_deviation[{i}]", 0.0)) for i in range(1, n_nodes + 1)]
    if not any(nodes):
        return state
    e = interp_nodes(nodes, state.xi)
    return WearState(state.cycles, state.xi, state.depth, state.geometry, state.gear_depth,
                     state.pinion_form + (e.max() - e), state.gear_form)


def _damage(model_name: str, state) -> tuple[float, float, np.ndarray, np.ndarray]:
    if model_name == "pitting":
        return float(state.pitting_density), float(np.max(state.density)), state.xi, state.density
    return float(state.mean_depth), float(state.max_depth), state.xi, state.depth


def _stop_reached(spec, model_name, damage, cycles) -> bool:
    stop = spec.get("stop", {})
    if "cycles" in stop and cycles >= stop["cycles"]:
        return True
    if model_name == "pitting" and "pitting_density" in stop and damage >= stop["pitting_density"]:
        return True
    if model_name == "wear" and "wear_depth" in stop and damage >= stop["wear_depth"]:
        return True
    return False


#: Scenario keys that do not change the stages a run computes (only where it stops, where it
#: runs or what else the file is used for), so a partial run may be resumed across them.
_IDENTITY_FREE = ("executor", "description", "archive", "calibration")
_IDENTITY_FREE_DEGRADATION = ("stop", "max_updates")


def run_identity(scenario: Scenario, fmu_sha256: str) -> str:
    """SHA-256 of what decides a degradation run's stages: the scenario's content (not its
    executor, description or stop criterion) and the FMU file's SHA-256."""
    import hashlib
    raw = {k: v for k, v in dict(scenario.raw).items() if k not in _IDENTITY_FREE}
    if isinstance(raw.get("degradation"), dict):
        raw["degradation"] = {k: v for k, v in raw["degradation"].items() if k not in _IDENTITY_FREE_DEGRADATION}
    text = json.dumps({"scenario": raw, "parameters": dict(scenario.parameters), "fmu": fmu_sha256},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def run_degradation(scenario: Scenario, output: str | Path | None = None, *, fmu_path: Path | None = None,
                    progress: bool = True, resume: bool = False,
                    channels: tuple[str, ...] | None = None) -> DegradationRun:
    """Run the scenario's degradation block; write the stages to ``output`` (HDF5) if given."""
    from twin import _interrupt
    from twin._atomic import partial_path
    from twin.degradation import GearPair, MeshLoad, TransmittedLoad, contact_k_pair, mesh_parameters
    from twin.degradation.pitting_map import ToothScatter, pitting_parameters
    from twin.plausibility import check_block, check_parameters

    spec = scenario.degradation
    if spec is None:
        raise ScenarioError([(str(scenario.source), "degradation", "the scenario has no degradation block")])
    model_name = spec["model"]
    model = _model(spec)
    path = Path(output) if output is not None else None
    if path is not None:
        from twin.results import check_hdf5_path
        check_hdf5_path(path, "a degradation run")
    dn_cap = float(spec.get("cycles_per_update", 1e7))
    max_increment = float(spec.get("max_increment", 3e-6 if model_name == "wear" else 0.01))
    max_updates = int(spec.get("max_updates", 1000))
    window = float(spec.get("load_window", 0.1))
    rec_dur = float(spec.get("record_duration", 0.05))
    dt = scenario.output_interval
    channels = channels or scenario.outputs or ("accel_pinion_casing",)
    fmu_file = fmu_path or scenario.fmu_path()

    stages: list[Stage] = []
    complete = False
    partial = partial_path(path) if path is not None else None
    with FMU(fmu_file) as fmu:
        check_compatibility(fmu, scenario)
        identity = run_identity(scenario, fmu.sha256)
        geometry_values = {v.name: fmu.get(v.name) for v in fmu.parameters if "[" not in v.name}
        geometry_values.update(fmu.structural_values())       # the tooth counts are built in
        geometry_values.update({k: v for k, v in scenario.parameters.items() if "[" not in k})
        geometry = GearPair.from_parameters(geometry_values)
        n_nodes = int(fmu.structural_values().get("n_profile", 11))
        k_healthy = tuple(scenario.parameters.get(f"k_pair[{i}]", fmu.variable(f"k_pair[{i}]").start)
                          for i in range(1, n_nodes + 1))
        state = model.initial_state(geometry)
        if model_name == "wear":
            state = manufactured_form(state, scenario.parameters, n_nodes)
        if model_name == "pitting" and f"tooth_pit_field[{geometry.z1 * n_nodes}]" not in fmu.variables:
            raise ScenarioError([(str(fmu_file), "degradation.model",
                                  f"pitting needs the per-tooth field tooth_pit_field[1..{geometry.z1 * n_nodes}]"
                                  " (GearTwin.Gearbox21 and the models built on it); this FMU has none")])
        scatter = ToothScatter.draw(geometry.z1, float(spec.get("tooth_scatter", DEFAULT_TOOTH_SCATTER)),
                                    scenario.seed, float(spec.get("pit_cluster_length", 0.0))
                                    ) if model_name == "pitting" else None
        source = next((p for p in (partial, path) if p is not None and p.exists()), None) if resume else None
        if source is not None:     # the partial output, else a complete one to extend (a later stop)
            stages, state = _load_for_resume(source, model, model_name, geometry, identity)
        elif resume and path is not None:
            print(f"note: neither {partial} nor {path} exists; the run starts from the beginning")
        t0 = scenario.start_time
        inputs = {n: p(t0) for n, p in scenario.inputs.items()}
        params = dict(scenario.parameters)
        if stages:
            params.update(stages[-1].parameters)
        contact_stiffness = model_name == "wear" and spec.get("pair_stiffness", "model") == "contact"
        torque = float(inputs.get("load_torque", 0.0) or 0.0)
        nominal = torque / geometry.base_radius_gear if torque > 0 else None
        if contact_stiffness and not stages and nominal is not None:
            # the pair law has the LTCA's compliance at the load from the first record on
            params.update({f"k_pair[{i}]": float(v) for i, v in
                           enumerate(contact_k_pair(geometry, nominal, n_nodes), start=1)})
        if model_name == "wear" and not stages and (np.any(state.pinion_form > 0) or np.any(state.gear_form > 0)):
            # the flanks' form deviation is in the mesh from the first record on
            k_now = tuple(params.get(f"k_pair[{i}]", k) for i, k in enumerate(k_healthy, start=1))
            params.update(mesh_parameters(geometry, wear=state, k_pair_healthy=k_now, n_nodes=n_nodes,
                                          force=nominal).parameters)
        from twin.operating import consistent_start
        start = consistent_start(params, inputs, [v.name for v in fmu.parameters])
        check_parameters(fmu, start)
        fmu.setup(t0, parameters=start, inputs=inputs)
        fmu.capture(t0 + 0.05, dt, ["mesh_force"])        # settle the lateral static deflection
        bar = progress_bar(max_updates, progress, f"{scenario.name} stages", "stage")
        bar.update(len(stages))
        try:
            for u in range(len(stages), max_updates):
                _interrupt.check()
                t = fmu.time
                names = [*ROLL, *FORCE, "motor_speed", "mesh_force"]
                block = fmu.capture(t + window, dt, names)
                check_block(names, block, {}, t0=t + dt, dt=dt, load=inputs.get("load_torque"),
                            contact=block[:, 3:6].sum(axis=1))
                omega1 = float(np.mean(block[:, 6]))
                force = _mean_force(block[:, 7], t)
                if model_name == "wear":
                    load = TransmittedLoad(force)
                else:
                    load = MeshLoad.from_samples(block[:, 0:3], block[:, 3:6])
                vib = {}
                if rec_dur > 0:
                    snip = fmu.capture(fmu.time + rec_dur, dt, list(channels))
                    check_block(list(channels), snip, {c: fmu.variables[c].unit for c in channels},
                                t0=fmu.time - rec_dur, dt=dt)
                    vib = {c: snip[:, j].astype(np.float32) for j, c in enumerate(channels)}
                damage, dmax, xi, fld = _damage(model_name, state)
                current = {f"k_pair[{i}]": fmu.get(f"k_pair[{i}]") for i in range(1, n_nodes + 1)}
                current.update({f"profile_deviation[{i}]": fmu.get(f"profile_deviation[{i}]")
                                for i in range(1, n_nodes + 1)})
                if model_name == "pitting":
                    current.update({f"tooth_pit_field[{k}]": fmu.get(f"tooth_pit_field[{k}]")
                                    for k in range(1, geometry.z1 * n_nodes + 1)})
                trunc = stages[-1].truncation_error if stages else {}
                gear = np.asarray(state.gear_depth) if model_name == "wear" else None
                stages.append(Stage(u, float(state.cycles), damage, dmax, current, np.asarray(xi), np.asarray(fld),
                                    trunc, vib, gear))
                bar.update(1)
                if partial is not None:
                    _write(partial, scenario, model_name, stages, dt, complete=False, state=state, identity=identity)
                if _stop_reached(spec, model_name, damage, state.cycles):
                    complete = True
                    break
                dn = min(dn_cap, model.cycles_for_increment(state, load, omega1, max_increment, max_cycles=dn_cap))
                stop_cycles = spec.get("stop", {}).get("cycles")
                if stop_cycles is not None:
                    dn = min(dn, max(stop_cycles - state.cycles, 1.0))
                state = model.advance(state, load, dn, omega1)
                if model_name == "wear":
                    k_now = contact_k_pair(geometry, force, n_nodes) if contact_stiffness else k_healthy
                    update = mesh_parameters(geometry, wear=state, k_pair_healthy=k_now, n_nodes=n_nodes,
                                             force=force)
                    new, trunc_error = update.parameters, dict(update.truncation_error)
                else:
                    mapped = pitting_parameters(geometry, state, force, k_healthy, scatter=scatter,
                                                weibull_slope=model.m)
                    new, trunc_error = dict(mapped.parameters), {"k_pair": mapped.truncation_error,
                                                                 "tooth_pit_field": mapped.pit_truncation_error}
                fmu.set(new)
                stages[-1] = Stage(**{**stages[-1].__dict__, "truncation_error": trunc_error})
            else:
                complete = not spec.get("stop")
        except KeyboardInterrupt:
            complete = False
        finally:
            bar.close()
    run = DegradationRun(scenario, model_name, tuple(stages), complete, scenario.sample_rate, geometry,
                         float(geometry_values.get("mesh_stiffness_scale", 1.0)))
    if path is not None and stages:
        if complete:
            _write(path, scenario, model_name, stages, dt, complete=True, state=None, identity=identity)
            partial.unlink(missing_ok=True)
        else:
            _write(partial, scenario, model_name, stages, dt, complete=False, state=None, identity=identity)
    return run


def _mean_force(mesh_force: np.ndarray, t: float) -> float:
    """Mean transmitted force of a co-simulated window [N] (> 0, or the run cannot wear)."""
    force = float(np.mean(mesh_force))
    if not (np.isfinite(force) and force > 0):
        raise SimulationError(f"the mesh transmitted no force on average ({force!r} N) in the window "
                              f"starting at t = {t:.4g} s; the gears are not in contact", time=t)
    return force


def _write(path: Path, scenario: Scenario, model_name: str, stages: list[Stage], dt: float, *, complete: bool,
           state, identity: str) -> None:
    import h5py

    from twin._atomic import atomic_path
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["format"] = "gear-twin-degradation"
            f.attrs["format_version"] = 1
            f.attrs["model"] = model_name
            f.attrs["complete"] = complete
            f.attrs["run_identity"] = identity
            f.attrs["sample_rate"] = 1.0 / dt
            f.attrs["damage_unit"] = "1" if model_name == "pitting" else "m"
            f.create_group("scenario").attrs["json"] = json.dumps(scenario.raw, default=str)
            f.create_dataset("cycles", data=[s.cycles for s in stages])
            f.create_dataset("damage", data=[s.damage for s in stages])
            f.create_dataset("max_damage", data=[s.max_damage for s in stages])
            g = f.create_group("stages", track_order=True)
            for s in stages:
                sg = g.create_group(f"{s.index:05d}")
                sg.attrs["cycles"] = s.cycles
                sg.attrs["damage"] = s.damage
                sg.attrs["parameters"] = json.dumps(s.parameters)
                sg.attrs["truncation_error"] = json.dumps(s.truncation_error)
                sg.create_dataset("field_xi", data=s.field_xi)
                sg.create_dataset("field", data=s.field)
                if s.gear_field is not None:
                    sg.create_dataset("gear_field", data=s.gear_field)
                for c, v in s.vibration.items():
                    sg.create_dataset(f"vibration/{c}", data=v, compression="gzip", compression_opts=4)


def _load_for_resume(path: Path, model, model_name: str, geometry, identity: str):
    import h5py

    from twin.errors import ResumeError
    stages = []
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") != "gear-twin-degradation" or f.attrs.get("model") != model_name:
                raise ResumeError(f"'{path}' is not a {model_name} degradation record; cannot resume from it")
            if f.attrs.get("run_identity") != identity:
                raise ResumeError(f"'{path}' was written by another scenario or FMU (its run identity differs); "
                                  "resume refused; remove it or choose another --output")
            for key in f["stages"]:
                sg = f["stages"][key]
                vib = {c: sg["vibration"][c][:] for c in sg.get("vibration", {})}
                gear = sg["gear_field"][:] if "gear_field" in sg else None
                stages.append(Stage(int(key), float(sg.attrs["cycles"]), float(sg.attrs["damage"]),
                                    float(np.max(sg["field"][:])), json.loads(sg.attrs["parameters"]),
                                    sg["field_xi"][:], sg["field"][:], json.loads(sg.attrs["truncation_error"]), vib,
                                    gear))
    except ResumeError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise ResumeError(f"cannot resume from '{path}': the file is damaged or not a degradation record "
                          f"({type(exc).__name__}: {exc})") from None
    if not stages:
        raise ResumeError(f"cannot resume from '{path}': it holds no stage")
    last = stages[-1]
    state = model.state_from_field(geometry, last.cycles, last.field_xi, last.field)
    if last.gear_field is not None:
        from twin.degradation import WearState
        fresh = model.initial_state(geometry, len(last.field_xi))
        state = WearState(state.cycles, state.xi, state.depth, geometry, last.gear_field,
                          fresh.pinion_form, fresh.gear_form)
    # the last stage is re-run from its state so its update is applied again
    return stages[:-1], state
