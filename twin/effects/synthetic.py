"""Measurements with a hidden effect, for tests, benchmarks and the demo.

A "truth" gearbox is the candidate model (every catalogue effect, all off) with **one** effect
switched on, base parameters moved off their defaults, a shaft speed that differs from the
record's nominal speed, a sensor gain error and white noise. The twin's model lacks the effect
and starts from the default parameters, so it has to be calibrated before it is compared.

Most cases run at the rig's test point, 20 Hz and 20 N.m.  Backlash only acts when the flanks
separate, and in steady running at 20 N.m they never do, so its case (:data:`CONDITIONS`) is a
nearly unloaded record (0.2 N.m, the classic rattle condition) of a pinion with 40 um of
distributed wear.  That wear is the degradation state the twin already knows (from its
degradation run), so it sits in ``known_parameters`` and :func:`calibrate_base` hands it on; the
hidden effect is the clearance the worn flanks fly across (10 um along the line of action,
tight: at this condition the flights reach about 20 um).  The impacts make the response
chaotic, and the spectrum of 2 s of chaos scatters by about 1.3 dB from run to run, so this
record is 6 s long (the scatter falls to about 0.8 dB); pass ``duration=case.duration`` to the
diagnosis.

``out_of_catalogue`` adds instead a narrowband line that no catalogue effect can produce (an
inverter switching harmonic picked up by the sensor cable, at 3.15 kHz): the diagnosis must
report it as unexplained.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from twin.effects.catalogue import CATALOGUE

#: Effect parameters of the truth, per effect (FMU names relative to the effect instance).
TRUTH: dict[str, dict[str, float]] = {
    "pinion_eccentricity": {"eccentricity": 3.0e-5},
    "gear_eccentricity": {"eccentricity": 1.0e-4},
    "motor_torque_ripple": {"amplitude": 0.5, "frequency": 137.3},
    "load_torque_fluctuation": {"amplitude": 3.0, "frequency": 3.7},
    "housing_mode": {"frequency": 2700.0, "damping_ratio": 0.02, "participation": 1.0},
    "local_tooth_damage": {"stiffness_loss": 0.5},
    "backlash": {"gap": 1.0e-5},
    "tooth_friction": {"friction_coefficient": 0.08},
    "distributed_wear": {"wear_depth": 8e-6},
}
#: Base parameters the truth moves off their defaults (relative, +-) and the twin calibrates.
BASE_OFFSETS = {"mesh_stiffness_scale": 0.05, "kt35": 0.06, "ky6": 0.06}
OUT_OF_CATALOGUE_HZ = 3150.0
#: Per effect: the record's load [N.m], length [s] and the known wear depth of the pinion [m]
#: (see above); the others run at 20 N.m for 2 s on unworn teeth.
CONDITIONS: dict[str, dict[str, float]] = {"backlash": {"load": 0.2, "duration": 6.0, "known_wear_depth": 4.0e-5}}


@dataclass(frozen=True)
class HiddenCase:
    effect: str | None                  # catalogue id, "out_of_catalogue" or None (nothing missing)
    signal: np.ndarray = field(repr=False)   # (n,) measured acceleration [m/s2]
    sample_rate: float
    nominal_speed: float                # drive setting written in the record [Hz]
    load: float                         # N.m
    truth_parameters: dict              # FMU parameters of the truth (base offsets + effect)
    natural_frequencies: np.ndarray     # (k,) gearbox modes of the truth [Hz] (a tap test)
    gain: float
    speed_factor: float
    known_parameters: dict = field(default_factory=dict)   # degradation state the twin knows

    @property
    def duration(self) -> float:
        """Length of the record [s]."""
        return self.signal.size / self.sample_rate


def make_case(effect: str | None, seed: int, *, candidates_fmu, duration: float | None = None,
              sample_rate: float = 20000.0,
              nominal_speed: float = 20.0, load: float | None = None, noise: float = 0.05,
              n_modes: int = 8) -> HiddenCase:
    """Simulate one record of a truth gearbox with ``effect`` hidden (see the module docstring).

    ``candidates_fmu`` is the built ``GearTwin.Variants.Gearbox21Candidates``.  ``load`` [N.m]
    and ``duration`` [s] default to the effect's :data:`CONDITIONS` (20 N.m and 2 s for most).
    """
    from twin.errors import ParameterError
    from twin.fmu import FMU
    from twin.linearize import modes, state_jacobian
    from twin.operating import operating_point, simulate_operating_point

    if effect is not None and effect != "out_of_catalogue" and effect not in CATALOGUE:
        raise ParameterError(f"unknown hidden effect {effect!r}")
    rng = np.random.default_rng(seed)
    cond = CONDITIONS.get(effect or "", {})
    load = float(cond.get("load", 20.0)) if load is None else float(load)
    duration = float(cond.get("duration", 2.0)) if duration is None else float(duration)
    with FMU(candidates_fmu) as fmu:
        defaults = fmu.parameter_values()
        known = {}
        if "known_wear_depth" in cond:
            # the known wear has the shape of the DistributedWear component; the model computes it
            fmu.setup(0.0, parameters={CATALOGUE["distributed_wear"].parameter("wear_depth"): cond["known_wear_depth"]})
            n = int(fmu.variables["n_profile"].start)
            dev = fmu.get([CATALOGUE["distributed_wear"].parameter(f"deviation[{i}]") for i in range(1, n + 1)])
            known = {f"profile_deviation[{i}]": float(v) for i, v in enumerate(dev, start=1)}
    params = {k: defaults[k] * (1 + rng.uniform(-r, r)) for k, r in BASE_OFFSETS.items()}
    params.update(known)
    for e in CATALOGUE.values():
        params.update({e.parameter(k): v for k, v in e.neutral.items()})
    if effect in TRUTH:
        scale = rng.uniform(0.8, 1.2)
        for k, v in TRUTH[effect].items():
            lo, hi = _bounds(effect, k)
            val = v * scale if k not in ("frequency",) else v * rng.uniform(0.97, 1.03)
            params[CATALOGUE[effect].parameter(k)] = float(np.clip(val, lo, hi))
    speed_factor = 1 + rng.uniform(0.004, 0.012) * rng.choice([-1, 1])
    drive = nominal_speed * speed_factor
    x = simulate_operating_point(candidates_fmu, drive, load, parameters=params, settle=0.2, duration=duration,
                                 channels=["accel_pinion_casing"], output_interval=1.0 / sample_rate)[:, 0]
    if effect == "out_of_catalogue":
        t = np.arange(x.size) / sample_rate
        x = x + 0.25 * np.std(x) * np.sin(2 * math.pi * OUT_OF_CATALOGUE_HZ * t + rng.uniform(0, 2 * math.pi))
    gain = 1 + rng.uniform(-0.04, 0.04)
    x = gain * x + rng.normal(0.0, noise * float(np.std(x)), x.size)
    # the gearbox modes of the truth without the hidden effect, as a tap test would give them
    base_only = {k: v for k, v in params.items() if k in BASE_OFFSETS}
    start, inputs = operating_point(nominal_speed, load)
    jac, _ = state_jacobian(candidates_fmu, parameters={**_neutral(), **base_only, **start}, inputs=inputs,
                            settle=0.02, window=2.5e-3, samples=4)
    fr, _ = modes(jac)
    return HiddenCase(effect, x, sample_rate, nominal_speed, load, params, np.asarray(fr[:n_modes]), gain,
                      speed_factor, known)


def _neutral() -> dict[str, float]:
    return {e.parameter(k): v for e in CATALOGUE.values() for k, v in e.neutral.items()}


def _bounds(effect: str, name: str) -> tuple[float, float]:
    for p in CATALOGUE[effect].fit:
        if p.name == name:
            return p.lower, p.upper
    return -np.inf, np.inf


def write_case(case: HiddenCase, path, name: str = "record") -> Path:
    """Write the case as a one-record measurement file (HDF5, atomically); returns the path."""
    from twin.measurements import Record, write_measurements
    rec = Record(name, {"accel_pinion_casing": case.signal}, {"accel_pinion_casing": "m/s2"}, case.sample_rate,
                 nominal_speed=case.nominal_speed, load=case.load)
    return write_measurements([rec], path)


def calibrate_base(case: HiddenCase, fmu_path, *, max_nfev: int = 40) -> dict[str, float]:
    """The twin's calibration before diagnosis: the parameters of :data:`BASE_OFFSETS` fitted to
    the case's measured modes (bounded least squares, :func:`twin.calibration.refine_modes`),
    starting from the defaults. Returns FMU parameter values, with the case's known degradation
    state (``known_parameters``) added."""
    from twin.calibration.problem import CalibrationTarget, ParameterSpace, refine_modes
    from twin.fmu import FMU
    with FMU(fmu_path) as fmu:
        defaults = fmu.parameter_values()
    space = ParameterSpace.from_bounds({k: (defaults[k] * (1 - 2 * r), defaults[k] * (1 + 2 * r))
                                        for k, r in BASE_OFFSETS.items()})
    target = CalibrationTarget(case.signal, case.sample_rate, case.nominal_speed, case.load,
                               case.natural_frequencies)
    x0 = np.array([defaults[k] for k in space.names])
    return {**space.to_dict(refine_modes(fmu_path, space, target, x0, max_nfev=max_nfev)), **case.known_parameters}
