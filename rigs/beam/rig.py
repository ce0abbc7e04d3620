"""The beam rig: one gearbox, its modes and its records."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import acquire
from .effects import resolve
from .hammer import check_direction, check_location, check_rate, draw_blows
from .params import VERSION, Params, scatter_params
from .simulate import Damage, modal_for, resolve_damage, simulate
from .structure import NDOF_NODE

PITTING_EDGES = tuple(np.round(np.linspace(0.0, 0.20, 7), 6))
WEAR_EDGES = tuple(np.round(np.linspace(0.0, 240e-6, 5), 9))
CHANNELS = ("accel_pinion_casing", "accel_gear_casing", "encoder")


class RigError(ValueError):
    """Bad operating point or record request."""


@dataclass(frozen=True)
class Mode:
    frequency: float        # Hz
    damping_ratio: float
    observability: float    # 0..1 at the casing sensors
    label: str


@dataclass(frozen=True)
class RigRecord:
    name: str
    channels: dict
    units: dict
    sample_rate: float
    nominal_speed: float
    load: float
    tachometer: str
    attributes: dict
    truth: dict


@dataclass(frozen=True)
class Rig:
    """A gearbox of the beam rig. Rig() is the nominal gearbox with the committed defaults."""
    params: Params = field(default_factory=Params)
    box_seed: int = 0
    scatter: float = 0.0
    factors: tuple = ()

    # ---- gearbox-level properties drawn once from the box seed
    def _box_rng(self, tag):
        return np.random.default_rng([self.box_seed, 424242, tag])

    @property
    def gear_offset(self) -> int:
        return int(self._box_rng(1).integers(0, self.params.gears.z_gear))

    @property
    def brake_phase(self) -> float:
        return float(self._box_rng(2).uniform(0, 2 * np.pi))

    @property
    def speed_sensor_error(self) -> float:
        return float(self._box_rng(3).normal(0, self.params.drive.speed_sensor_error))

    @property
    def sensor_gain_errors(self) -> tuple:
        return tuple(float(x) for x in self._box_rng(4).normal(0, self.params.sensors.gain_error_box, 2))

    @property
    def encoder_line_errors(self) -> np.ndarray:
        s = self.params.sensors
        return self._box_rng(5).normal(0, s.encoder_line_error, s.encoder_lines)

    def scattered(self, seed: int, scatter: float = 0.12) -> "Rig":
        """One gearbox: base parameters scattered by +-scatter (uniform), seeded."""
        if not 0.0 <= scatter < 0.5:
            raise RigError(f"scatter {scatter} outside [0, 0.5)")
        params, factors = scatter_params(self.params, np.random.default_rng([int(seed), 99]), scatter)
        return Rig(params, int(seed), float(scatter), tuple(sorted(factors.items())))

    # ---- linearisation
    def modes(self, speed: float = 20.0, load: float = 20.0, fmax: float = 5000.0,
              lubricated: bool = True) -> tuple:
        """Modes of the linearised rig at the mean mesh stiffness of this load, up to fmax.

        observability: peak casing-sensor accelerance of the mode alone for the mesh and
        bearing excitations, max(|S phi| |E phi|) / (2 zeta), relative to the largest mode
        below fmax (1 = the most visible mode; below about 0.02 a run-up will hardly show it).
        No speed dependence (no gyroscopic terms at these speeds); the argument is kept for
        the common interface.
        """
        _check_point(speed, load)
        model, mm, _ = modal_for(self.params, float(load), bool(lubricated), 1e9)
        Phi = mm.shapes
        sel = np.nonzero((mm.freq > 0) & (mm.freq <= fmax))[0]
        exc = [model.mesh] + [
            _pair(model, h, d) for h in range(4) for d in range(2)]
        E = np.stack(exc) @ Phi[:, sel]
        S = np.abs(model.sensors @ Phi[:, sel]).max(axis=0)
        peak = S * np.linalg.norm(E, axis=0) / (2 * np.maximum(mm.zeta[sel], 1e-4))
        obs = peak / peak.max()
        labels = _labels(self.params, model, Phi[:, sel], {k: v[sel] for k, v in mm.energy.items()})
        return tuple(Mode(float(mm.freq[i]), float(mm.zeta[i]), float(o), lab)
                     for i, o, lab in zip(sel, obs, labels))

    # ---- records
    def steady(self, speed: float = 20.0, load: float = 20.0, duration: float = 2.0, effect=None,
               damage=None, seed: int = 0, *, lubricated=None, name=None, speed_scatter=0.0,
               load_scatter=0.015, label=None) -> RigRecord:
        return self._record("steady", (speed, speed), 0.0, load, duration, effect, damage, seed,
                            lubricated, name, speed_scatter, load_scatter, label)

    def runup(self, speeds=(2.0, 20.0), load: float = 20.0, duration: float = 6.0, effect=None,
              damage=None, seed: int = 0, *, lubricated=None, name=None) -> RigRecord:
        if len(speeds) != 2:
            raise RigError(f"speeds must be (start, end), not {speeds!r}")
        return self._record("runup", tuple(speeds), duration, load, duration, effect, damage, seed,
                            lubricated, name, 0.0, 0.015, None)

    def impact(self, speed: float = 20.0, load: float = 20.0, duration: float = 4.0,
               impacts_per_second: float = 4.0, location: str = "pinion_housing", seed: int = 0,
               name=None, direction: str = "vertical") -> RigRecord:
        """An operational hammer test: blows at random instants while the rig runs (oiled,
        healthy), recorded as one more channel ``hammer`` [N] (the hammer's load cell, same
        acquisition rate and anti-alias filter as the accelerometers).

        Each blow is a haversine pulse of 0.15-0.3 ms contact and 100-300 N peak (params.Hammer),
        about ``impacts_per_second`` of them (gamma-distributed intervals). Struck from above,
        i.e. along -z, the vertical of this rig (y joins the shaft centres):

        - ``pinion_housing``: housing of bearing A, the pinion shaft's front-wall bearing on the
          coupling side of the pinion; DOF vector ``bearing_housing[0, 1]`` (casing modes),
        - ``gear_housing``: housing of bearing C, the gear shaft's bearing in the same wall;
          ``bearing_housing[2, 1]``,
        - ``pinion_shaft_end``: free (encoder) end node of the pinion shaft (its last node),
          vertical DOF ``encoder - 4 + 1``,
        - ``gear_shaft_end``: free (encoder) end node of the gear shaft (its first node),
          vertical DOF ``gear_encoder - 4 + 1``.

        The truth carries the location, its DOF and the blows (start of contact [s from the
        first sample], contact times, peaks) with the load cell's gain and range. Slow roll
        (0.5 Hz) keeps the running excitation weak against the blows. ``direction="horizontal"``
        strikes the same point from the side, along -y (its y DOF), as a modal test does to
        reach the modes that move across the shafts' plane.
        """
        location = check_location(location)
        direction = check_direction(direction)
        rate = check_rate(impacts_per_second)
        _check_point(speed, load)
        if not 0.05 <= duration <= 60.0:
            raise RigError(f"duration {duration} s outside [0.05, 60]")
        blows = draw_blows(location, rate, float(duration), self.params.hammer,
                           np.random.default_rng([self.box_seed, int(seed), 31]), direction)
        if name is None:
            side = "" if direction == "vertical" else f"_{direction}"
            name = f"impact_{speed:g}Hz_{load:g}Nm_{location}{side}_seed{seed}"
        return self._record("impact", (speed, speed), 0.0, load, duration, None, None, seed,
                            True, name, 0.0, 0.015, None, hammer=(blows, rate))

    def pitting_stages(self, per_stage: int = 4, duration: float = 1.0, seed: int = 0,
                       at_centre: bool = False) -> list:
        """Records of the six pitting stages at 20 Hz / 20 N m (lubricated), scattered per record."""
        return self._stages("pitting", PITTING_EDGES, 20.0, 20.0, per_stage, duration, seed, at_centre)

    def wear_stages(self, per_stage: int = 4, duration: float = 1.0, seed: int = 0,
                    at_centre: bool = False) -> list:
        """Records of the four wear stages at 10 Hz / 5 N m (dry), scattered per record."""
        return self._stages("wear", WEAR_EDGES, 10.0, 5.0, per_stage, duration, seed, at_centre)

    def _stages(self, kind, edges, speed, load, per_stage, duration, seed, at_centre):
        rng = np.random.default_rng([self.box_seed, int(seed), 77])
        n_stage = len(edges) - 1
        # record names carry no stage: a seeded running number (the stage is in the truth file)
        number = rng.permutation(n_stage * per_stage)
        out = []
        for s in range(n_stage):
            for i in range(per_stage):
                lo, hi = edges[s], edges[s + 1]
                value = 0.5 * (lo + hi) if at_centre else float(rng.uniform(lo, hi))
                out.append(self.steady(speed, load, duration, damage={kind: value},
                                       seed=int(rng.integers(0, 2**31)),
                                       name=f"{kind}_record_{number[s * per_stage + i]:03d}",
                                       speed_scatter=0.02, load_scatter=0.10, label=s))
        return out

    def _record(self, kind, speeds, ramp, load, duration, effect, damage, seed, lubricated, name,
                speed_scatter, load_scatter, label, hammer=None):
        for sp in speeds:
            _check_point(sp, load)
        if not 0.05 <= duration <= 60.0:
            raise RigError(f"duration {duration} s outside [0.05, 60]")
        eff = resolve(effect)
        dmg = resolve_damage(damage)
        if lubricated is None:
            lubricated = dmg.wear == 0.0
        p = self.params
        rng = np.random.default_rng([self.box_seed, int(seed), 5])
        speed_factor = float(rng.uniform(1 - speed_scatter, 1 + speed_scatter)) if speed_scatter else 1.0
        load_true = float(load * (rng.uniform(1 - load_scatter, 1 + load_scatter) if load_scatter > 0.02
                                  else 1 + rng.normal(0, load_scatter)))
        err = self.speed_sensor_error + float(rng.normal(0, p.drive.speed_drift))
        # the drive regulates its measured speed to the set-point times the record factor
        err_total = (1 + err) / speed_factor - 1
        sim = simulate(self, speed_from=speeds[0], speed_to=speeds[1], ramp=ramp, duration=duration,
                       load=load_true, lubricated=bool(lubricated), effect=eff, damage=dmg, rng=rng,
                       sensor_err=err_total, hammer=None if hammer is None else hammer[0])
        out, fs_in = sim["out"], sim["fs"]
        s = p.sensors
        n_out = int(round(duration * s.sample_rate))
        gains, ranges, chans = [], [], {}
        for c in range(2):
            gain = (1 + self.sensor_gain_errors[c]) * (1 + float(rng.normal(0, s.gain_error_record)))
            bracket = None
            if eff is not None and eff.name == "casing_resonance" and eff.params["channel"] == CHANNELS[c]:
                bracket = (eff.params["frequency"], eff.params["damping"])
            y, r = acquire.accelerometer(out[:, c], fs_in, s.sample_rate, s, rng, gain, bracket)
            chans[CHANNELS[c]] = y[:n_out]
            gains.append(gain)
            ranges.append(r)
        chans["encoder"] = acquire.encoder(out[:, 2], fs_in, s.sample_rate, n_out, s.encoder_lines,
                                           self.encoder_line_errors)
        true_speed = out[:, 6] / (2 * np.pi)
        if name is None:   # distinct per effect and seed; says nothing of damage
            name = f"{kind}_{speeds[1]:g}Hz_{load:g}Nm_{eff.name if eff else 'base'}_seed{seed}"
        modes = self.modes(speeds[1], load_true, lubricated=bool(lubricated))
        truth = {
            "rig": VERSION, "record": name, "kind": kind, "seed": int(seed),
            "box": {"seed": self.box_seed, "scatter": self.scatter,
                    "factors": {k: v for k, v in self.factors}},
            "speed": {"nominal": [float(x) for x in speeds],
                      "true_mean": float(true_speed.mean()),
                      "true_start": float(true_speed[: int(0.05 * fs_in)].mean()),
                      "true_end": float(true_speed[-int(0.05 * fs_in):].mean()),
                      "offset": float(1 / (1 + err_total) - 1)},
            "load": {"nominal": float(load), "true": load_true},
            "lubricated": bool(lubricated),
            "sensor_gain": dict(zip(CHANNELS[:2], gains)),
            "sensor_range": dict(zip(CHANNELS[:2], ranges)),
            "sensor_noise_rms": s.noise,
            "effect": None if eff is None else {
                "name": eff.name, "params": eff.params,
                "outside_catalogue": eff.name in ("bearing_outer_race", "coupling_misalignment")},
            "damage": {"pitting": dmg.pitting, "wear": dmg.wear,
                       "pitted_fraction_per_tooth": sim["tables"].info["pitted_fraction_per_tooth"],
                       "wear_mean_depth_gear": sim["tables"].info["wear_mean_depth_gear"]},
            "label": label,
            "mesh_stiffness_mean": sim["mesh_stiffness"],
            "mesh_force_rms_ac": float(out[:, 4].std()),
            "modes": [m.__dict__ for m in modes],
        }
        attrs = {"record_kind": kind, "speed_from": float(speeds[0]), "speed_to": float(speeds[1]),
                 "rig": "beam"}
        units = {"accel_pinion_casing": "m/s2", "accel_gear_casing": "m/s2", "encoder": "rad"}
        if hammer is not None:
            blows, rate = hammer
            f, gain, r = acquire.load_cell(sim["hammer"], fs_in, s.sample_rate, p.hammer,
                                           np.random.default_rng([self.box_seed, int(seed), 32]))
            chans["hammer"] = f[:n_out]
            units["hammer"] = "N"
            attrs["impact_location"] = blows.location
            attrs["impact_direction"] = blows.direction
            truth["hammer"] = {**blows.truth(sim["model"]), "impacts_per_second": rate,
                               "sensor_gain": gain, "sensor_range": r,
                               "sensor_noise_rms": p.hammer.noise}
        return RigRecord(name, chans, units, s.sample_rate, float(speeds[1]), float(load), "encoder",
                         attrs, truth)


def _check_point(speed, load):
    if not (isinstance(speed, (int, float)) and 0.5 <= speed <= 60.0):
        raise RigError(f"speed {speed!r} Hz outside [0.5, 60]")
    if not (isinstance(load, (int, float)) and 0.5 <= load <= 80.0):
        raise RigError(f"load {load!r} N m outside [0.5, 80]")


def _pair(model, h, d):
    v = -model.bearing_housing[h, d].copy()
    v[model.bearing_dofs[h, d]] += 1.0
    return v


def _labels(params, model, Phi, energy):
    nn = len(params.shafts.stations)
    n = model.M.shape[0]
    groups = {"torsional": np.zeros(n, bool), "pinion shaft lateral": np.zeros(n, bool),
              "gear shaft lateral": np.zeros(n, bool)}
    for s, name in ((0, "pinion shaft lateral"), (1, "gear shaft lateral")):
        for i in range(nn):
            base = (s * nn + i) * NDOF_NODE
            groups[name][base:base + 4] = True
            groups["torsional"][base + 4] = True
    groups["torsional"][[model.motor, model.torque_meter, model.brake]] = True
    kin = (Phi * (model.M @ Phi))
    out = []
    for r in range(Phi.shape[1]):
        ke = {k: float(kin[g, r].sum()) for k, g in groups.items()}
        cas = kin[model.casing_dofs, r]
        ke["casing"] = float(cas.sum())
        top = max(ke, key=ke.get)
        if top == "casing":
            lab = model.casing_labels[int(np.argmax(cas))]
        elif top == "torsional":
            tors = {"motor": kin[model.motor, r], "brake": kin[model.brake, r],
                    "torque meter": kin[model.torque_meter, r]}
            lab = "torsional, " + max(tors, key=tors.get) + " dominant"
        else:
            lab = top
        if energy["mesh"][r] > 0.3:
            lab = "mesh: " + lab
        out.append(lab)
    return out
