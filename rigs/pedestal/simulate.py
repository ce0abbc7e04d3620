"""Build one simulation case of a gearbox and run it into a ``RigRecord``."""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import signal

from . import acquisition, effects, kernel
from .flanks import ToothTables, manufactured_tables, mean_tangent_stiffness
from .pitting import apply_pitting
from .record import Damage, RigRecord
from .structure import I_B, I_G, I_M, I_P, I_T, I_XA, I_XP, I_YA, I_YP, LinearStructure, \
    build_structure, panels_of
from .wear import apply_wear

GRAVITY = 9.81


@dataclass(frozen=True)
class Case:
    """Everything a run needs that does not depend on the record's random draws."""

    struct: LinearStructure
    tables: ToothTables
    effect: effects.Effect | None
    damage: Damage | None
    damage_truth: dict | None
    load: float                 # true brake torque [N m]
    k_max: float
    k_mean: float
    c_max: float
    kp: float
    ki: float
    friction: float
    eccentricity: tuple


@lru_cache(maxsize=16)
def _healthy_tables(gears, flanks, seed) -> ToothTables:
    return manufactured_tables(gears, flanks, seed)


def controller_gains(rig) -> tuple[float, float]:
    d, g = rig.drivetrain, rig.gears
    j = (d.motor_inertia + d.meter_inertia + d.pinion_inertia
         + (d.gear_inertia + d.brake_inertia) / g.ratio ** 2)
    wc = 2 * np.pi * d.speed_bandwidth
    return 2 * d.speed_loop_damping * wc * j, wc * wc * j


def build_case(rig, load: float, effect=None, damage: Damage | None = None,
               lubricated: bool = True) -> Case:
    eff = effects.as_effect(effect)
    if eff is not None:
        eff = eff.resolved(rig.identity.ripple_frequency)
    panels = panels_of(rig.structure) + effects.extra_panel(eff)
    struct = build_structure(rig.gears, rig.drivetrain, rig.structure, panels)
    tables = _healthy_tables(rig.gears, rig.flanks, rig.identity.seed)
    dtruth = None
    if damage is not None and damage.kind == "pitting":
        tables, dtruth = apply_pitting(tables, rig.gears, rig.identity.seed, damage.size)
    elif damage is not None and damage.kind == "wear":
        tables, dtruth = apply_wear(tables, rig.gears, rig.identity.seed, damage.size, load,
                                   rig.flanks.face_mismatch)
    tables = effects.tooth_fault(tables, eff, rig.identity.fault_tooth)
    k_max = rig.gears.pair_stiffness_max(load)
    k_mean = mean_tangent_stiffness(rig.gears, tables, load, rig.flanks.face_mismatch)
    c_mean = 2 * rig.flanks.mesh_damping_ratio * np.sqrt(k_mean * struct.mesh_mass)
    kp, ki = controller_gains(rig)
    mu = rig.flanks.friction_lubricated if lubricated else rig.flanks.friction_dry
    ecc = effects.eccentricities(eff, rig.flanks.eccentricity)
    return Case(struct, tables, eff, damage, dtruth, float(load), k_max, k_mean,
                c_mean * k_max / k_mean, kp, ki, mu, ecc)


def _band_noise(rng, n, fs, lo, hi, std) -> np.ndarray:
    if std == 0.0:
        return np.zeros(n)
    sos = signal.butter(2, [lo, hi], btype="bandpass", fs=fs, output="sos")
    x = signal.sosfilt(sos, rng.standard_normal(n + 4096))[4096:]
    return std * x / x.std()


def _slow_noise(rng, n, fs, cutoff, std) -> np.ndarray:
    """Low-pass noise built at 2 kHz and interpolated (cheap for long records)."""
    if std == 0.0:
        return np.zeros(n)
    fs_c = 2000.0
    m = int(n * fs_c / fs) + 64
    sos = signal.butter(2, cutoff, fs=fs_c, output="sos")
    x = signal.sosfilt(sos, rng.standard_normal(m + 2000))[2000:]
    x = std * x / x.std()
    return np.interp(np.arange(n) / fs, np.arange(m) / fs_c, x)


def run(rig, case: Case, speed_hz: np.ndarray, duration: float, seed: int, name: str,
        kind: str, attributes: dict, truth: dict, hammer: dict | None = None) -> RigRecord:
    """Integrate the case along the true pinion-speed profile ``speed_hz`` (one value per
    internal step plus one, pre-roll included) and acquire the record."""
    acq, dtr, gears = rig.acquisition, rig.drivetrain, rig.gears
    rng = np.random.default_rng([seed, 11])
    fs = acq.sample_rate
    ov = acq.oversampling
    fs_int = fs * ov
    dt = 1.0 / fs_int
    n_pre = int(round(acq.preroll * fs_int))
    n_out = int(round(duration * fs))
    n = n_pre + n_out * ov
    assert speed_hz.size == n + 1
    w_ref = 2 * np.pi * speed_hz
    t = np.arange(n) * dt
    theta_nom = np.concatenate([[0.0], np.cumsum(0.5 * (w_ref[1:] + w_ref[:-1]) * dt)])[:-1]

    struct, load = case.struct, case.load
    t_pinion = load / gears.ratio
    ext_t = np.zeros((n, 4))
    ext_t[:, 0] = effects.ripple_torque(case.effect, t, rng.uniform(0, 2 * np.pi))
    ext_t[:, 1] = _band_noise(rng, n, fs_int, 20.0, 8000.0, dtr.process_noise * t_pinion)
    ext_t[:, 2] = _band_noise(rng, n, fs_int, 20.0, 8000.0,
                              dtr.process_noise * t_pinion * gears.ratio)
    brake = 1.0 + _slow_noise(rng, n, fs_int, 40.0, dtr.brake_fluctuation)
    brake += dtr.brake_ripple * np.sin(theta_nom / gears.ratio + rng.uniform(0, 2 * np.pi))
    ext_t[:, 3] = load * brake

    dirs = []
    forces = []
    nvec = struct.normal
    bearing_load = 0.5 * load / gears.rb2 + 0.5 * rig.structure.pinion_mass * GRAVITY
    f_or = effects.outer_race_force(case.effect, theta_nom, w_ref[:-1] / (2 * np.pi), dt,
                                    bearing_load, rng)
    if np.any(f_or):
        d = np.zeros(struct.mass.size)
        d[I_XP], d[I_YP], d[I_XA], d[I_YA] = -nvec[0], -nvec[1], nvec[0], nvec[1]
        dirs.append(d)
        forces.append(f_or)
    if hammer is not None:
        dirs.append(hammer["direction"])
        forces.append(hammer["force"])
    if not dirs:
        dirs.append(np.zeros(struct.mass.size))
        forces.append(np.zeros(n))
    force_dirs = np.ascontiguousarray(np.array(dirs))
    ext_f = np.ascontiguousarray(np.array(forces).T)

    x0, v0, z0, te0, u0 = _initial_state(rig, case, w_ref[0], rng)
    e1, e2 = case.eccentricity
    phases = rig.identity.runout_phases
    nx, ny = nvec
    tx, ty = struct.tangent
    P = np.array([gears.rb1, gears.rb2, gears.base_pitch, gears.path_length,
                  case.tables.s[1] - case.tables.s[0], u0, case.k_max, case.c_max,
                  case.k_mean, rig.flanks.backlash + _backlash_growth(case), case.friction,
                  gears.rho1_start, gears.tangent_length, e1, e2, phases[0], phases[1],
                  rig.structure.pinion_mass, rig.structure.gear_mass, case.kp, case.ki,
                  dtr.torque_lag, dtr.torque_limit, np.tan(gears.pressure_angle), nx, ny, tx, ty,
                  0.02, 0.5, rig.flanks.face_mismatch, rig.flanks.wobble_ratio])
    assert P.size == kernel.N_PARAMS
    acc = np.empty((2, n))
    theta = np.empty(n)
    fmesh = np.empty(n)
    delta = np.empty(n)
    tb = case.tables
    kernel.integrate(x0, v0, z0, te0, dt, n, w_ref, P, struct.mass,
                     *kernel.compressed_rows(struct.K, struct.C),
                     struct.mesh_vector, tb.shape, tb.pinion_dev, tb.pinion_k, tb.gear_dev,
                     tb.gear_k, ext_t, ext_f, force_dirs, struct.sensor_rows, acc, theta,
                     fmesh, delta)
    if not (np.all(np.isfinite(acc)) and np.all(np.isfinite(theta))):
        raise FloatingPointError(f"record {name!r}: the integration diverged")

    gain_draw = 1.0 + rng.normal(0.0, acq.gain_error, 2)
    gains = np.array(rig.identity.sensor_gains) * gain_draw
    st = rig.structure
    meas = acquisition.acquire_channels(acc, fs_int, acq, st.mount_frequencies,
                                        st.mount_damping, gains, n_pre, n_out, rng)
    enc = acquisition.encoder_angle(theta, n_pre, n_out, ov, acq.encoder_lines)
    channels = {"accel_pinion_casing": meas[0], "accel_gear_casing": meas[1], "encoder": enc}
    units = {"accel_pinion_casing": "m/s2", "accel_gear_casing": "m/s2", "encoder": "rad"}
    if hammer is not None:
        channels["hammer"] = hammer["force"][n_pre:n_pre + ov * n_out:ov].copy()
        units["hammer"] = "N"
    sl = slice(n_pre, n, ov)
    truth = dict(truth)
    truth.update({
        "gains": [float(g) for g in gains],
        "mean_speed": float(np.mean(np.diff(theta[sl])) * fs / (2 * np.pi)),
        "effect": None if case.effect is None else case.effect.as_dict(),
        "damage": None if case.damage is None else {"kind": case.damage.kind,
                                                      "size": case.damage.size},
        "damage_detail": case.damage_truth,
        "mesh_stiffness_mean": case.k_mean,
        "mesh_force_mean": float(np.mean(fmesh[sl])),
        "contact_loss_fraction": float(np.mean(fmesh[sl] <= 0.0)),
        "casing_rms_before_sensor": [float(np.sqrt(np.mean(acc[s, sl] ** 2))) for s in (0, 1)],
    })
    if case.effect is not None and case.effect.name == "local_tooth_fault":
        truth["fault_tooth"] = rig.identity.fault_tooth
    return RigRecord(name, channels, units, fs, attributes, truth)


def _backlash_growth(case: Case) -> float:
    if case.damage_truth and case.damage_truth.get("kind") == "wear":
        return case.damage_truth["backlash_increase"]
    return 0.0


def _initial_state(rig, case: Case, w0: float, rng):
    """Static equilibrium under the mean load, rolling at w0, at a random hunting position."""
    struct, gears = case.struct, rig.gears
    n = struct.mass.size
    g = struct.mesh_vector
    K = struct.K + case.k_mean * np.outer(g, g)
    K[I_M, I_M] += 1e-3 * K[I_T, I_T]          # fixes the free rotation at theta_m = 0
    f = np.zeros(n)
    t_in = case.load / gears.ratio
    f[I_M] = t_in
    f[I_B] = -case.load
    x0 = np.linalg.solve(K, f)
    hunt = gears.z1 * gears.z2 // np.gcd(gears.z1, gears.z2)
    u0 = (int(rng.integers(0, hunt)) + float(rng.uniform())) * gears.base_pitch
    # lift the gear by the deviation of the pair in contact so the mesh starts loaded
    tb = case.tables
    devs = []
    for j in range(3):
        nn = int(np.floor(u0 / gears.base_pitch)) - j
        s = u0 - nn * gears.base_pitch
        if 0 <= s <= gears.path_length:
            devs.append(np.interp(s, tb.s, tb.pinion_dev[nn % gears.z1])
                        + np.interp(s, tb.s, tb.gear_dev[nn % gears.z2]))
    if devs:
        x0[I_G] -= min(devs) / gears.rb2
        x0[I_B] -= min(devs) / gears.rb2
    v0 = np.zeros(n)
    v0[[I_M, I_T, I_P]] = w0
    v0[[I_G, I_B]] = w0 / gears.ratio
    return x0, v0, t_in / case.ki, t_in, u0
