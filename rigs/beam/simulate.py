"""One record of the rig: set up the modal model, inputs and tables, integrate, and return
the raw signals at the internal rate (before the acquisition chain)."""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import signal

from . import integrate
from .contact import cycle_positions, static_mesh
from .effects import Effect
from .structure import build, modal
from .surfaces import build_tables
from .tooth import mesh_geometry, path_tables


class DamageError(ValueError):
    """A damage specification the rig does not know."""


@dataclass(frozen=True)
class Damage:
    pitting: float = 0.0      # pitted fraction of the pinion's active flank area
    wear: float = 0.0         # mean worn depth of the pinion's active flank [m]


def resolve_damage(damage) -> Damage:
    if damage is None:
        return Damage()
    if isinstance(damage, Damage):
        d = damage
    elif isinstance(damage, dict):
        bad = set(damage) - {"pitting", "wear"}
        if bad:
            raise DamageError(f"unknown damage kind {sorted(bad)[0]!r}; known: pitting, wear")
        d = Damage(float(damage.get("pitting", 0.0)), float(damage.get("wear", 0.0)))
    else:
        raise DamageError(f"damage must be a mapping or a Damage, not {damage!r}")
    if not 0.0 <= d.pitting <= 0.6:
        raise DamageError(f"pitting fraction {d.pitting} outside [0, 0.6]")
    if not 0.0 <= d.wear <= 400e-6:
        raise DamageError(f"wear depth {d.wear} m outside [0, 4e-4]")
    return d


@lru_cache(maxsize=16)
def tables_for(params, box_seed, damage: Damage, spall_key):
    spall = dict(spall_key) if spall_key else None
    return build_tables(params, box_seed, damage.pitting, damage.wear, spall=spall)


@lru_cache(maxsize=32)
def mean_mesh_stiffness(gears, load: float) -> float:
    """Mean tangent mesh stiffness [N/m] of ideal flanks over a mesh cycle at brake torque load."""
    geo = mesh_geometry(gears)
    tab = path_tables(gears, geo, 256)
    pos, valid = cycle_positions(geo, 256)
    c = np.interp(pos, tab.u, tab.body_pinion + tab.body_gear)
    aw = np.interp(pos, tab.u, tab.hertz_a)
    force = max(load, 0.5) * gears.z_pinion / gears.z_gear / geo.rb1
    _, _, k = static_mesh(force, np.zeros_like(pos), c, np.full_like(pos, tab.hertz_q), aw, valid)
    return float(np.mean(k))


@lru_cache(maxsize=16)
def modal_for(params, load: float, lubricated: bool, cutoff=None):
    model = build(params, load)
    kbar = mean_mesh_stiffness(params.gears, load)
    return model, modal(model, kbar, params, lubricated, cutoff), kbar


def _band_noise(rng, n, fs, band, rms, channels):
    x = rng.standard_normal((n, channels))
    sos = signal.butter(4, band, fs=fs, output="sos")
    y = signal.sosfilt(sos, x, axis=0)
    y *= rms / np.maximum(y.std(axis=0), 1e-30)
    return y


def _outer_race_impacts(rng, t, angle, bearing_geo, static_load, eff, fs):
    """Impulse train of a localised outer-race defect (force magnitude per sample)."""
    balls, d, dm = bearing_geo
    cage = angle * 0.5 * (1 - d / dm)                  # cage angle, outer race fixed
    phase = balls * cage / (2 * np.pi)                  # ball passages over the defect
    k = np.arange(np.ceil(phase[0]), np.floor(phase[-1]) + 1)
    times = np.interp(k, phase, t)
    # rolling-element slip: each passage early or late by a fraction of the period
    period = np.gradient(times) if times.size > 1 else np.ones(times.size)
    times = times + rng.normal(0, eff["jitter"], times.size) * period
    out = np.zeros(t.size)
    width = eff["pulse"]
    n_p = max(int(round(width * fs)), 2)
    shape = np.sin(np.pi * np.arange(n_p) / n_p)
    amp = eff["severity"] * static_load * rng.lognormal(0, 0.15, times.size)
    idx = np.searchsorted(t, times)
    for i, a in zip(idx, amp):
        if 0 <= i < t.size - n_p:
            out[i:i + n_p] += a * shape
    return out


def simulate(rig, *, speed_from, speed_to, ramp, duration, load, lubricated, effect: Effect | None,
             damage: Damage, rng: np.random.Generator, sensor_err: float, hammer=None):
    """Integrate one record; returns dict of internal-rate signals and facts for the truth.

    hammer: the blows of a hammer test (hammer.Blows) or None; with blows, the hammer force
    is one more external force series and "hammer" the force at the output instants [N].
    """
    p = rig.params
    fs = p.sensors.internal_rate
    h = 1.0 / fs
    n_settle = int(round(p.numerics.settle * fs))
    n_steps = int(round(duration * fs))
    n_tot = n_settle + n_steps + 2
    spall = None
    eff = effect.params if effect else {}
    name = effect.name if effect else None
    geo = mesh_geometry(p.gears)
    if name == "local_tooth_fault":
        b = p.gears.face_width
        spall = (("tooth", int(eff["tooth"])), ("u_from", geo.pitch_u + eff["from_pitch"]),
                 ("u_to", geo.pitch_u + eff["to_pitch"]), ("z_from", eff["face_from"] * b),
                 ("z_to", eff["face_to"] * b), ("depth", eff["depth"]))
    tab = tables_for(p, rig.box_seed, damage, spall)
    model, mm, kbar = modal_for(p, float(load), bool(lubricated))
    Phi = mm.shapes
    w = 2 * np.pi * mm.freq
    Ph, G0, G1 = integrate.step_matrices(mm.freq, mm.zeta, h)
    gvec = model.mesh @ Phi
    beta = float(np.sum(gvec**2 * G1[:, 0]) + mm.mesh_residual)
    n = model.M.shape[0]
    e = np.zeros((n, len(integrate.LOOP_CHANNELS)))
    pin, gea = model.pinion_node, model.gear_node
    e[model.motor, 0] = 1.0
    e[model.brake, 1] = 1.0
    for c, dof in zip(range(2, 8), (pin, pin + 1, pin + 4, gea, gea + 1, gea + 4)):
        e[dof, c] = 1.0
    cpl = model.pinion_coupling_node
    e[cpl, 8] = e[cpl + 1, 9] = 1.0
    e[cpl + 4, 10], e[model.torque_meter, 10] = 1.0, -1.0
    B = Phi.T @ e
    # precomputed external force series: bearing roughness (force pairs) and casing process
    bb = p.broadband
    loads = np.linalg.norm(model.bearing_loads, axis=1)
    ser_vec = np.zeros((n, 10))
    for hb in range(4):
        for d in range(2):
            ser_vec[model.bearing_dofs[hb, d], 2 * hb + d] += 1.0
            ser_vec[:, 2 * hb + d] -= model.bearing_housing[hb, d]
    ser_vec[:, 8] = model.bearing_housing[:, 1].sum(axis=0) / 4
    ser_vec[:, 9] = model.bearing_housing[:, 0].sum(axis=0) / 4
    G_ser = Phi.T @ ser_vec
    series = np.zeros((n_tot, 10))
    rms = np.repeat(bb.bearing_force * loads + bb.bearing_floor, 2)
    series[:, :8] = _band_noise(rng, n_tot, fs, bb.band, 1.0, 8) * rms[None]
    series[:, 8:] = _band_noise(rng, n_tot, fs, bb.band, bb.casing_force, 2)
    t_all = (np.arange(n_tot) - n_settle) * h
    w0, w1 = 2 * np.pi * speed_from, 2 * np.pi * speed_to
    true_scale = 1.0 / (1.0 + sensor_err)
    if name == "bearing_outer_race":
        hb = int(eff["bearing"])
        ramp_t = np.clip(t_all / max(ramp, 1e-9), 0, 1) if ramp > 0 else np.ones_like(t_all)
        omega = (w0 + (w1 - w0) * ramp_t) * true_scale
        angle = np.cumsum(omega) * h
        bg = p.bearings
        geo_b = ((bg.pinion_balls, bg.pinion_ball_d, bg.pinion_pitch_d) if hb < 2
                 else (bg.gear_balls, bg.gear_ball_d, bg.gear_pitch_d))
        if hb >= 2:
            angle = angle * p.gears.z_pinion / p.gears.z_gear
        imp = _outer_race_impacts(rng, t_all, angle, geo_b, loads[hb], eff, fs)
        d = model.bearing_loads[hb] / loads[hb]
        series[:, 2 * hb] += imp * d[0]
        series[:, 2 * hb + 1] += imp * d[1]
    if hammer is not None:
        # output o is the state at (o + 1) h of the run: record time o h is t_all - h
        series = np.ascontiguousarray(np.column_stack([series, hammer.force(t_all - h)]))
        G_ser = np.ascontiguousarray(np.column_stack([G_ser, Phi.T @ hammer.vector(model)]))
    fl = _band_noise(rng, n_tot, fs, p.brake.fluctuation_band, p.brake.fluctuation, 1)[:, 0]
    # loop parameters
    par = np.zeros(len(integrate.NAMES))
    P = integrate.P
    dr = p.drive
    rigid = Phi[:, 0]
    j_tot = 1.0 / rigid[model.motor] ** 2                # inertia seen at the motor
    wc_i, wc_w = 2 * np.pi * dr.current_bandwidth, 2 * np.pi * dr.speed_bandwidth
    vals = dict(h=h, k_mean=kbar, beta=beta, rb1=geo.rb1, pb=geo.base_pitch, g_len=geo.path_length,
                u_pitch=geo.pitch_u, rho1_start=geo.rho1_start,
                loa_length=geo.centre_distance * np.sin(p.gears.pressure_angle),
                z1=p.gears.z_pinion, z2=p.gears.z_gear, gear_offset=rig.gear_offset, q=tab.hertz_q,
                mu=p.surfaces.friction_lubricated if lubricated else p.surfaces.friction_dry,
                ratio=p.gears.z_pinion / p.gears.z_gear, alpha=p.gears.pressure_angle,
                R=dr.resistance, L=dr.inductance, kt=dr.torque_constant,
                kp_i=dr.inductance * wc_i, ki_i=dr.resistance * wc_i,
                kp_w=j_tot * wc_w / dr.torque_constant, ki_w=j_tot * wc_w**2 / (4 * dr.torque_constant),
                i_max=dr.current_limit, v_max=dr.voltage_limit, sensor_err=sensor_err,
                w_a=w0, w_b=w1, t_a=0.0, t_b=ramp, t0=0.0,
                comm_n=dr.commutator_segments, comm_a=dr.commutator_ripple,
                load=load, brake_1x=p.brake.once_per_rev, brake_phase=rig.brake_phase,
                brake_visc=p.brake.viscous)
    if name == "drive_ripple":
        vals.update(rip_amp=eff["amplitude"], rip_freq=eff["frequency"], rip_phase=eff["phase"])
    if name == "pinion_runout":
        vals.update(ecc_p=eff["eccentricity"], ecc_p_phase=eff["phase"])
    if name == "gear_runout":
        vals.update(ecc_g=eff["eccentricity"], ecc_g_phase=eff["phase"])
    if name == "coupling_misalignment":
        vals.update(mis_force=eff["force"], mis_torque=eff["torque"], mis_phase=eff["phase"])
    for k, v in vals.items():
        par[P[k]] = v
    # initial state: static deflection under the mean torques, rigid rotation at speed
    f0 = np.zeros(n)
    f0[model.motor] = load * p.gears.z_pinion / p.gears.z_gear
    f0[model.brake] = -load
    pf = Phi.T @ f0
    q0 = np.zeros(w.size)
    q0[1:] = pf[1:] / w[1:] ** 2
    v0 = np.zeros(w.size)
    v0[0] = w0 * true_scale / rigid[model.motor]
    rows = np.stack([model.sensors[0] @ Phi, model.sensors[1] @ Phi, Phi[model.encoder],
                     Phi[model.gear_encoder], Phi[model.motor], Phi[model.brake],
                     Phi[pin + 4], Phi[gea + 4]])
    out = integrate.run(n_steps, n_settle, par, Ph, G0, G1, 2 * mm.zeta * w, w**2, gvec, B, G_ser,
                        series, fl, rows, tab.gap_p, tab.gap_g, tab.comp_p, tab.width_p,
                        tab.hertz_a, tab.du, q0, v0, -n_settle * h)
    res = {"out": out, "fs": fs, "modal": mm, "model": model, "mesh_stiffness": kbar,
           "tables": tab}
    if hammer is not None:
        res["hammer"] = series[n_settle + 1:n_settle + 1 + n_steps, -1].copy()
    return res
