"""``Rig``: one gearbox of the pedestal rig, its modes and its records."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace

import numpy as np

from . import simulate
from .effects import Effect
from .geometry import GearPair
from .modes import Mode, linear_modes
from .params import SCATTERED, Acquisition, Drivetrain, Flanks, GearboxIdentity, Structure, \
    identity_from_seed, scatter_value
from .record import Damage, RigRecord, as_damage

VERSION = "pedestal rig v1, 2026-11-25"


def _check_positive(name: str, value) -> float:
    v = float(value)
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


@dataclass(frozen=True)
class Rig:
    """The pedestal rig with one gearbox. ``Rig()`` is the nominal gearbox (committed defaults)."""

    gears: GearPair = field(default_factory=GearPair)
    drivetrain: Drivetrain = field(default_factory=Drivetrain)
    structure: Structure = field(default_factory=Structure)
    flanks: Flanks = field(default_factory=Flanks)
    acquisition: Acquisition = field(default_factory=Acquisition)
    identity: GearboxIdentity = field(default_factory=GearboxIdentity)
    scatter: float = 0.0

    # -- gearboxes ---------------------------------------------------------------------------
    def scattered(self, seed: int, scatter: float = 0.12) -> "Rig":
        """Another gearbox: every base parameter in ``params.SCATTERED`` times an independent
        uniform factor in [1 - scatter, 1 + scatter]; its own teeth, speed offset, sensor
        calibration and run-out phases (all from ``seed``)."""
        if not 0.0 <= scatter < 0.5:
            raise ValueError(f"scatter must be in [0, 0.5), got {scatter!r}")
        rng = np.random.default_rng([int(seed), 2026])

        def factor():
            return 1.0 + rng.uniform(-scatter, scatter)

        sections = {"drivetrain": self.drivetrain, "structure": self.structure,
                    "flanks": self.flanks}
        changes: dict[str, dict] = {k: {} for k in sections}
        for sec, name in SCATTERED:
            changes[sec][name] = scatter_value(getattr(sections[sec], name), factor)
        return replace(self, **{k: replace(v, **changes[k]) for k, v in sections.items()},
                       identity=identity_from_seed(int(seed) + 1), scatter=float(scatter))

    def describe(self) -> dict:
        """All parameters of this gearbox as plain data (for the truth file)."""
        return {"gears": asdict(self.gears), "drivetrain": asdict(self.drivetrain),
                "structure": asdict(self.structure), "flanks": asdict(self.flanks),
                "acquisition": asdict(self.acquisition), "identity": asdict(self.identity),
                "scatter": self.scatter, "version": VERSION}

    # -- linearisation -----------------------------------------------------------------------
    def modes(self, speed: float = 20.0, load: float = 20.0, effect=None,
              damage=None) -> tuple[Mode, ...]:
        """Modes of the linearised rig at an operating point (see ``rigs.pedestal.modes``)."""
        _check_positive("speed", speed)
        case = simulate.build_case(self, _check_positive("load", load), effect,
                                   as_damage(damage))
        c_mean = case.c_max * case.k_mean / case.k_max
        return linear_modes(case.struct, case.k_mean, c_mean, case.kp, case.ki,
                            self.drivetrain.torque_lag)

    # -- records -----------------------------------------------------------------------------
    def _profile(self, n_pre: int, n_rec: int, start: float, end: float, factor: float):
        ramp = np.linspace(start, end, n_rec + 1)
        return factor * np.concatenate([np.full(n_pre, start), ramp])

    def _record(self, kind, speeds, load, duration, effect, damage, seed, name, lubricated,
                speed_scatter, load_scatter, extra_truth=None, hammer=None, extra_attrs=None):
        acq = self.acquisition
        duration = _check_positive("duration", duration)
        load = _check_positive("load", load)
        rng = np.random.default_rng([int(seed), 5])
        speed_factor = (1.0 + self.identity.speed_offset
                        + rng.normal(0.0, max(acq.speed_jitter, speed_scatter)))
        true_load = load * (1.0 + rng.normal(0.0, max(0.01, load_scatter)))
        dmg = as_damage(damage)
        case = simulate.build_case(self, true_load, effect, dmg, lubricated)
        fs_int = acq.sample_rate * acq.oversampling
        n_pre = int(round(acq.preroll * fs_int))
        n_rec = int(round(duration * acq.sample_rate)) * acq.oversampling
        profile = self._profile(n_pre, n_rec, speeds[0], speeds[1], speed_factor)
        attrs = {"nominal_speed": float(speeds[1]), "load": float(load),
                 "tachometer": "encoder", "tachometer_kind": "angle", "record_kind": kind}
        if kind == "runup":
            attrs["commanded_speed_from"] = float(speeds[0])
            attrs["commanded_speed_to"] = float(speeds[1])
        attrs.update(extra_attrs or {})
        truth = {"simulator": VERSION, "kind": kind, "seed": int(seed),
                 "gearbox_seed": self.identity.seed, "scatter": self.scatter,
                 "gearbox": self.describe(),
                 "sensor_mount_frequencies": list(self.structure.mount_frequencies),
                 "true_speed_factor": float(speed_factor),
                 "true_speed": [float(speeds[0] * speed_factor), float(speeds[1] * speed_factor)],
                 "true_load": float(true_load), "lubricated": bool(lubricated),
                 "modes": [m.as_dict() for m in self.modes(speeds[1], true_load, effect, dmg)]}
        truth.update(extra_truth or {})
        return simulate.run(self, case, profile, duration, int(seed), name, kind, attrs, truth,
                            hammer=hammer(n_pre + n_rec, fs_int, case) if hammer else None)

    def steady(self, speed: float = 20.0, load: float = 20.0, duration: float = 2.0,
               effect: str | Effect | None = None, damage=None, seed: int = 0,
               name: str | None = None, lubricated: bool = True, speed_scatter: float = 0.0,
               load_scatter: float = 0.0) -> RigRecord:
        """A steady record at commanded pinion speed ``speed`` [Hz] and brake torque ``load``
        [N m]. ``speed_scatter``/``load_scatter``: extra per-record std (relative)."""
        speed = _check_positive("speed", speed)
        return self._record("steady", (speed, speed), load, duration, effect, damage, seed,
                            name or f"steady_{seed}", lubricated, speed_scatter, load_scatter)

    def runup(self, speeds: tuple = (2.0, 20.0), load: float = 20.0, duration: float = 6.0,
              effect: str | Effect | None = None, damage=None, seed: int = 0,
              name: str | None = None, lubricated: bool = True) -> RigRecord:
        """A linear speed ramp of the VFD from ``speeds[0]`` to ``speeds[1]`` [Hz]."""
        lo, hi = (_check_positive("speeds", s) for s in speeds)
        return self._record("runup", (lo, hi), load, duration, effect, damage, seed,
                            name or f"runup_{seed}", lubricated, 0.0, 0.0)

    def impact(self, speed: float = 20.0, load: float = 20.0, duration: float = 4.0,
               impacts_per_second: float = 4.0, location: str = "pinion_pedestal",
               seed: int = 0, name: str | None = None, direction: str = "vertical") -> RigRecord:
        """An operational impact test: hammer blows (force channel ``hammer`` [N]) on a
        pedestal (``pinion_pedestal``/``gear_pedestal``) while the rig runs, struck from above
        (``direction="vertical"``, along -y) or from the side (``"horizontal"``, along -x)."""
        from .excitation import check_impact, hammer_input
        speed = _check_positive("speed", speed)
        check_impact(location, direction)

        def make(n, fs_int, case):
            return hammer_input(n, fs_int, case.struct, location, impacts_per_second, seed, direction)

        where = {"impact_location": location, "impact_direction": direction}
        return self._record("impact", (speed, speed), load, duration, None, None, seed,
                            name or f"impact_{seed}", True, 0.0, 0.0, extra_truth={"hammer": where},
                            hammer=make, extra_attrs=where)

    # -- degradation stages --------------------------------------------------------------------
    def pitting_stages(self):
        from .stages import pitting_stages
        return pitting_stages()

    def wear_stages(self):
        from .stages import wear_stages
        return wear_stages()

    def stage_records(self, kind: str, per_stage: int = 4, duration: float = 1.0,
                      seed: int = 0) -> list[RigRecord]:
        from .stages import stage_records
        return stage_records(self, kind, per_stage, duration, seed)


__all__ = ["Rig", "Damage", "RigRecord", "VERSION"]
