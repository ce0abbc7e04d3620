"""The model's damage against pinion cycles, ``D_model(N)``.

**Trajectory.**  The calibrated degradation model of the scenario gives the damage against
pinion cycles, ``D_model(N)`` (:class:`Trajectory`): by default the co-simulated run of
:func:`twin.degradation_run.run_degradation` (``method="cosim"``: the FMU's dynamic load, 20 s
for the lubricated and 35 s for the dry scenario), or an HDF5 already written by ``twin run`` /
``twin archive`` (:func:`read_trajectory`).  ``method="static"`` drives the same cycle-jumping
loop with the quasi-static load sharing :meth:`MeshLoad.static` (damage fed back through
:func:`mesh_parameters`; no FMU, < 1 s for pitting, ~15 s for wear).  For pitting it agrees
with the co-simulated run within 3 % in cycles to 20 % density; for wear it does *not*: the
co-simulated wear rate drops about 4x between 90 and 120 um of mean depth (the worn profile
changes the dynamic load sharing) and the run reaches 240 um after 2.3e6 cycles instead of
1.5e6.  Use the static trajectory for pitting only, or to test.

"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twin.errors import ParameterError, ScenarioError
from twin.rul.base import DAMAGE_KINDS, RULError


@dataclass(frozen=True, eq=False)
class Trajectory:
    """The model's damage against pinion cycles, ``D_model(N)``, tabulated.

    Attributes
    ----------
    cycles : (n,) float array, strictly increasing, starting at 0
    damage : (n,) float array, non-decreasing, >= 0 (pitting density or mean wear depth [m])
    kind : "pitting_density" or "wear_depth"
    source : str
        Where it came from (for reports).

    Between points the damage is interpolated linearly; beyond the last point it is
    extrapolated with the mean slope over the last quarter of the table (capped at 1 for a
    density); before 0 it is 0.
    """

    cycles: np.ndarray
    damage: np.ndarray
    kind: str
    source: str = ""

    def __post_init__(self):
        c = np.array(self.cycles, dtype=float)
        d = np.array(self.damage, dtype=float)
        src = self.source or "trajectory"
        if self.kind not in DAMAGE_KINDS.values():
            raise RULError(f"damage kind must be one of {sorted(DAMAGE_KINDS.values())}, got {self.kind!r}",
                           source=src)
        if c.ndim != 1 or d.shape != c.shape or c.size < 2:
            raise RULError(f"cycles and damage must be 1-D of the same length >= 2, got shapes {c.shape} "
                           f"and {d.shape}", source=src)
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(d))):
            raise RULError("cycles and damage must be finite", source=src)
        if c[0] != 0 or np.any(np.diff(c) <= 0):
            bad = 0 if c[0] != 0 else int(np.argmax(np.diff(c) <= 0)) + 1
            raise RULError(f"cycles must start at 0 and increase strictly; cycles[{bad}] = {c[bad]!r}", source=src)
        if d.min() < 0 or np.any(np.diff(d) < 0):
            bad = int(np.argmax(np.diff(d) < 0)) + 1 if np.any(np.diff(d) < 0) else int(np.argmin(d))
            raise RULError(f"damage must be >= 0 and non-decreasing; damage[{bad}] = {d[bad]!r}", source=src)
        if d[-1] <= d[0]:
            raise RULError(f"the damage never grows (stays at {d[0]!r})", source=src)
        c.setflags(write=False)
        d.setflags(write=False)
        object.__setattr__(self, "cycles", c)
        object.__setattr__(self, "damage", d)
        tail = max(1, c.size // 4)
        slope = (d[-1] - d[-1 - tail]) / (c[-1] - c[-1 - tail])
        object.__setattr__(self, "_slope", float(slope))
        keep = np.concatenate(([True], np.diff(d) > 0))      # first point of each plateau
        object.__setattr__(self, "_inv", (d[keep], c[keep]))

    @property
    def max_damage(self) -> float:
        return float(self.damage[-1])

    def damage_at(self, cycles) -> np.ndarray:
        """D_model at ``cycles`` (any shape); see the class docstring for the extrapolation."""
        n = np.asarray(cycles, dtype=float)
        out = np.interp(n, self.cycles, self.damage, left=0.0)
        beyond = n > self.cycles[-1]
        if np.any(beyond):
            ext = self.damage[-1] + self._slope * (n - self.cycles[-1])
            out = np.where(beyond, ext, out)
        out = np.where(n <= 0, 0.0, out)
        if self.kind == "pitting_density":
            out = np.minimum(out, 1.0)
        return out

    def cycles_at(self, damage: float) -> float:
        """First cycle count at which D_model reaches ``damage`` (within the table)."""
        if not (math.isfinite(damage) and self.damage[0] < damage <= self.damage[-1]):
            raise RULError(f"damage {damage!r} is outside the trajectory's range "
                           f"({self.damage[0]!r}, {self.damage[-1]!r}]", source=self.source or "trajectory")
        d, c = self._inv
        return float(np.interp(damage, d, c))


def _nominal(scenario, name: str, default: float) -> float:
    prof = scenario.inputs.get(name)
    return prof(scenario.start_time) if prof is not None else default


def scenario_speed_hz(scenario) -> float:
    """The scenario's pinion speed [Hz] at its start (20 Hz when it has no speed input)."""
    return _nominal(scenario, "motor_speed_ref", 2 * math.pi * 20.0) / (2 * math.pi)


def _degradation_model(scenario):
    from twin.degradation import FatiguePitting, FlankWear
    spec = scenario.degradation
    coeffs = dict(spec.get("coefficients", {}))
    try:
        return FatiguePitting(**coeffs) if spec["model"] == "pitting" else FlankWear(**coeffs)
    except TypeError as exc:
        raise ScenarioError([(str(scenario.source), "degradation.coefficients", str(exc))]) from None


def trajectory_from_scenario(scenario, *, method: str = "cosim", reach: float | None = None,
                             progress: bool = False, substeps: int = 4) -> Trajectory:
    """The calibrated model's damage trajectory under the scenario's operating point.

    Parameters
    ----------
    scenario : Scenario
        Must have a ``degradation:`` block (model, coefficients, ``max_increment``).
    method : "static" or "cosim"
        "static": the cycle-jumping loop of :func:`~twin.degradation_run.run_degradation` with the
        quasi-static load (:meth:`MeshLoad.static`, torque from the scenario's load input) and the
        damage fed back through :func:`mesh_parameters`; no FMU.  "cosim": run_degradation itself
        (the co-simulated load; needs the FMU, ~20 s for the lubricated scenario).
    reach : float, optional
        Damage the trajectory must reach.  Static: default 1.5 x the largest of the scenario's
        stop criterion and last archive stage boundary.  Co-simulated: the run stops on the
        scenario's criterion, raised to ``reach`` when that is higher.  It also stops after
        ``degradation.max_updates`` x 4 load updates, when the damage stops growing, or when a
        node of the mesh has lost all its stiffness (the quasi-static load has no solution).
    substeps : int
        Static method: points recorded per load update (the load is frozen over an update, so
        the sub-steps are exact for the model and only make the table finer).
    """
    spec = scenario.degradation
    if spec is None:
        raise ScenarioError([(str(scenario.source), "degradation", "the scenario has no degradation block")])
    kind = DAMAGE_KINDS[spec["model"]]
    if method == "cosim":
        from twin.degradation_run import run_degradation
        stop_key = "pitting_density" if kind == "pitting_density" else "wear_depth"
        if reach is not None and spec.get("stop", {}).get(stop_key, math.inf) < reach:
            # the run must get past the damage asked for: raise its stop criterion
            scenario = scenario.with_overrides(degradation={**spec, "stop": {stop_key: float(reach)}})
        run = run_degradation(scenario, None, progress=progress)
        return _dedupe(run.cycles, run.damage, kind, f"co-simulated degradation run of '{scenario.name}'")
    if method != "static":
        raise RULError(f"trajectory method must be 'static' or 'cosim', got {method!r}")

    from twin._progress import progress_bar
    from twin.degradation import GearPair, MeshLoad, TransmittedLoad
    from twin.degradation.pitting_map import ToothScatter, pitting_parameters
    model = _degradation_model(scenario)
    geometry = GearPair.from_parameters({**{k: v for k, v in scenario.parameters.items() if "[" not in k},
                                         **scenario.structural})
    torque_pinion = _nominal(scenario, "load_torque", 20.0) * geometry.z1 / geometry.z2
    omega1 = 2 * math.pi * scenario_speed_hz(scenario)
    params = {k: v for k, v in scenario.parameters.items() if "[" in k or k == "mesh_stiffness_scale"}
    healthy = _healthy_k(scenario, geometry)
    k_healthy = tuple(params.get(f"k_pair[{i}]", h) for i, h in enumerate(healthy, start=1))
    params.update({f"k_pair[{i}]": k for i, k in enumerate(k_healthy, start=1)})
    stop = spec.get("stop", {})
    crit = stop.get("pitting_density" if kind == "pitting_density" else "wear_depth", 0.0)
    last_stage = float(scenario.archive["stages"][-1]) if scenario.archive else 0.0
    target = reach if reach is not None else 1.5 * max(crit, last_stage)
    if target <= 0:
        raise RULError("give reach= (or a stop criterion / archive stages in the scenario): "
                       "the trajectory needs a damage to run to", source=str(scenario.source))
    if kind == "pitting_density":
        target = min(target, 0.95)
    max_inc = float(spec.get("max_increment", 3e-6 if kind == "wear_depth" else 0.01))
    dn_cap = float(spec.get("cycles_per_update", 1e7))
    max_updates = 4 * int(spec.get("max_updates", 1000))
    state = model.initial_state(geometry)
    cycles, damage = [0.0], [0.0]
    measure = (lambda s: float(s.pitting_density)) if kind == "pitting_density" else (lambda s: float(s.mean_depth))
    force = torque_pinion / geometry.base_radius_pinion
    bar = progress_bar(max_updates, progress, f"{scenario.name} trajectory", "update")
    try:
        for _ in range(max_updates):
            if kind == "wear_depth":
                # Archard under a frozen load is linear in cycles: one LTCA gives the jump and every
                # sub-step exactly.  The load sharing comes from the LTCA of the worn flanks.
                d1, d2 = model.depth_per_cycle(state, TransmittedLoad(force))
                peak = max(float(d1.max()), float(d2.max()))
                dn = dn_cap if peak <= 0 else min(dn_cap, max_inc / peak)
                start = state
                for j in range(1, substeps + 1):
                    f = dn * j / substeps
                    state = start.with_depths(start.cycles + f, start.depth + d1 * f, start.gear_depth + d2 * f)
                    cycles.append(float(state.cycles))
                    damage.append(measure(state))
            else:
                try:
                    load = MeshLoad.static(geometry, torque_pinion, parameters=params)
                except ParameterError:
                    break                             # a node lost all stiffness: the tooth has failed
                dn = min(dn_cap, model.cycles_for_increment(state, load, omega1, max_inc, max_cycles=dn_cap))
                for _ in range(substeps):
                    state = model.advance(state, load, dn / substeps, omega1)
                    cycles.append(float(state.cycles))
                    damage.append(measure(state))
                mapped = pitting_parameters(geometry, state, force, k_healthy,
                                            scatter=ToothScatter.draw(geometry.z1, 0.0, 0), weibull_slope=model.m)
                params = {**params, **{k: v for k, v in mapped.parameters.items() if k.startswith("k_pair[")}}
            bar.update(1)
            if damage[-1] >= target or damage[-1] <= damage[-1 - substeps] * (1 + 1e-9):
                break
    finally:
        bar.close()
    return _dedupe(np.array(cycles), np.maximum.accumulate(np.array(damage)), kind,
                   f"quasi-static degradation model of '{scenario.name}'")


def _healthy_k(scenario, geometry):
    """The healthy k_pair nodes of the scenario's model: computed from the geometry for a variant
    built with geometry options (as the build does), else the base model's default."""
    from twin.degradation import HEALTHY_K_PAIR
    from twin.variants import GEOMETRY_OPTIONS
    if any(k in GEOMETRY_OPTIONS for k in scenario.structural):
        from twin.degradation.stiffness import k_pair_nodes
        return tuple(k_pair_nodes(geometry, int(scenario.structural.get("n_profile", 11))))
    return HEALTHY_K_PAIR


def _dedupe(cycles, damage, kind, source) -> Trajectory:
    cycles = np.asarray(cycles, dtype=float)
    damage = np.asarray(damage, dtype=float)
    keep = np.concatenate(([True], np.diff(cycles) > 0))
    return Trajectory(cycles[keep], damage[keep], kind, source)


def read_trajectory(path: str | Path) -> Trajectory:
    """Trajectory from an HDF5 written by ``twin run`` (degradation record) or ``twin archive``."""
    import h5py
    path = Path(path)
    if not path.is_file():
        raise RULError("trajectory file does not exist", source=str(path))
    try:
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
            if fmt == "gear-twin-degradation":
                kind = DAMAGE_KINDS.get(str(f.attrs.get("model")), "")
                cycles, damage = f["cycles"][:], f["damage"][:]
            elif fmt == "gear-twin-archive" and "degradation" in f:
                kind = str(f.attrs.get("damage_kind"))
                cycles, damage = f["degradation"]["cycles"][:], f["degradation"]["damage"][:]
            else:
                raise RULError(f"not a degradation record or an archive with its degradation run (format {fmt!r})",
                               source=str(path))
    except OSError as exc:
        raise RULError(f"cannot read as HDF5: {exc}", source=str(path)) from None
    return _dedupe(cycles, damage, kind, str(path))



def default_threshold(scenario) -> float | None:
    """The scenario's stop criterion in damage units (pitting_density or wear_depth), else None."""
    spec = scenario.degradation or {}
    stop = spec.get("stop", {})
    key = "pitting_density" if spec.get("model") == "pitting" else "wear_depth"
    return float(stop[key]) if key in stop else None
