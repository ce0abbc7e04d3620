"""Flank micro-geometry of one gearbox and the per-tooth tables of the dynamic mesh.

Every tooth flank gets its own deviation along the path of contact (fixed for a gearbox):
a position (pitch) error, a low-order form deviation, waviness and roughness as Gaussian
processes in roll distance, both filtered by the Hertzian contact width, and the natural
edge break at the tip. Wear profiles (Archard) and pits (slice-wise contact) are added on
top. The result is a MeshTables record: per pinion tooth and per gear tooth gap [m] on a
path grid, per pinion tooth body compliance and loaded width fraction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import pitting, wear
from .contact import cycle_positions, static_mesh
from .tooth import mesh_geometry, path_tables


@dataclass(frozen=True)
class MeshTables:
    du: float
    u: np.ndarray
    gap_p: np.ndarray      # (z1, n_u)
    gap_g: np.ndarray      # (z2, n_u)
    comp_p: np.ndarray     # (z1, n_u) body compliance of the pair with pinion tooth k
    width_p: np.ndarray    # (z1, n_u) loaded width fraction
    hertz_a: np.ndarray    # (n_u,)
    hertz_q: float
    info: dict


def _gauss_process(rng, x, rms, length, contact):
    """Zero-mean Gaussian process on grid x with correlation length and contact filter."""
    dx = min(length / 4, 5e-6)
    xf = np.arange(x[0] - 6 * length, x[-1] + 6 * length, dx)
    w = rng.standard_normal(xf.size)
    sig = np.hypot(length, contact) / dx
    k = np.exp(-0.5 * (np.arange(-int(4 * sig) - 1, int(4 * sig) + 2) / sig) ** 2)
    y = np.convolve(w, k / np.sqrt((k**2).sum()), mode="same")
    # scale so that the unfiltered process has the r.m.s. asked for
    y *= rms * length / np.hypot(length, contact)
    return np.interp(x, xf, y)


def flank_deviations(rng, s, u, n_teeth, contact, tip_at_end: bool, edge, edge_len, width):
    """(n_teeth, n_u) separation contributions of one gear's flanks [m]."""
    rough = s.roughness * np.sqrt(min(s.roughness_face_length / width, 1.0))
    t = 2 * (u - u[0]) / (u[-1] - u[0]) - 1
    out = np.empty((n_teeth, u.size))
    pos = rng.normal(0, s.pitch_error / np.sqrt(2), n_teeth)

    def legendre(rms):
        c = rng.normal(0, 1, 3)
        f = c[0] * t + c[1] * (1.5 * t**2 - 0.5) + c[2] * (2.5 * t**3 - 1.5 * t)
        return f * rms / np.sqrt((f**2).mean() + 1e-30)
    common = legendre(s.form_error)          # the same dressing of the tool on every tooth
    for k in range(n_teeth):
        out[k] = (pos[k] + common + legendre(s.form_scatter)
                  + _gauss_process(rng, u, s.waviness, s.waviness_length, contact)
                  + _gauss_process(rng, u, rough, s.roughness_length, contact))
    x = (u - (u[-1] - edge_len)) if tip_at_end else (edge_len - u)
    out += edge * np.clip(x / edge_len, 0, None) ** 2
    return out


def nominal_sharing(geo, tables, force):
    """Pair force along the path for ideal flanks at a pinion-side normal force [N]."""
    pos, valid = cycle_positions(geo, 256)
    c = np.interp(pos, tables.u, tables.body_pinion + tables.body_gear)
    aw = np.interp(pos, tables.u, tables.hertz_a)
    _, forces, _ = static_mesh(force, np.zeros_like(pos), c, np.full_like(pos, tables.hertz_q), aw, valid)
    f_u = np.zeros_like(tables.u)
    for n in range(2):
        ok = valid[:, n]
        o = np.argsort(pos[ok, n])
        f_u = np.maximum(f_u, np.interp(tables.u, pos[ok, n][o], forces[ok, n][o], left=0, right=0))
    return f_u


def build_tables(params, box_seed: int, pitting_fraction=0.0, wear_depth=0.0,
                 pitting_load=20.0, wear_load=5.0, spall=None) -> MeshTables:
    """Per-tooth mesh tables of the gearbox with box_seed, for a damage state.

    pitting_fraction: mean pitted fraction of the pinion's active flank; wear_depth: mean
    worn depth of the pinion's active flank [m]; *_load: brake torque [N m] of the test that
    produced the damage (sets the load sharing it followed). spall: optional dict of a local
    tooth fault (tooth, u_from, u_to, z_from, z_to, depth) cut into the pit raster.
    """
    g, s = params.gears, params.surfaces
    geo = mesh_geometry(g)
    tab = path_tables(g, geo, params.numerics.path_samples)
    u = tab.u
    z1, z2 = g.z_pinion, g.z_gear
    rng = np.random.default_rng([box_seed, 7001])
    contact = 30e-6
    gap_p = flank_deviations(rng, s, u, z1, contact, True, g.tip_edge_break, g.tip_edge_length,
                             g.face_width)
    gap_g = flank_deviations(rng, s, u, z2, contact, False, g.tip_edge_break, g.tip_edge_length,
                             g.face_width)
    info = {}
    force_of = lambda torque: torque * z1 / z2 / geo.rb1
    # wear (both flanks), per-tooth scatter of the worn depth
    h_p, h_g = wear.archard_profiles(wear_depth, geo, tab, force_of(wear_load), z1, z2)
    mp = rng.lognormal(0, 0.10, z1)
    mg = rng.lognormal(0, 0.10, z2)
    mp /= mp.mean()
    mg /= mg.mean()
    gap_p += mp[:, None] * h_p[None]
    gap_g += mg[:, None] * h_g[None]
    info["wear_mean_depth_pinion"] = float((mp[:, None] * h_p[None]).mean())
    info["wear_mean_depth_gear"] = float((mg[:, None] * h_g[None]).mean())
    info["wear_max_depth_pinion"] = float(h_p.max() * mp.max())
    # pitting on the pinion flanks
    f_nom = nominal_sharing(geo, tab, force_of(pitting_load))
    R = tab.rho1 * tab.rho2 / (tab.rho1 + tab.rho2)
    pressure = np.sqrt(np.maximum(f_nom, 0) / (R + 1e-12))
    hazard = (pressure / pressure.max()) ** 8 * np.where(u < geo.pitch_u, 1.6, 0.6) + 1e-4
    prng = np.random.default_rng([box_seed, 7002])
    pops = pitting.pit_population(prng, hazard, u, g.face_width, z1)
    share = prng.lognormal(0, 0.35, z1)
    share /= share.mean()
    targets = np.clip(pitting_fraction * share, 0, 0.8)
    depth, reached = pitting.pit_coverage(pops, targets, u, g.face_width)
    if spall is not None:
        zz = (np.arange(pitting.N_FACE) + 0.5) * g.face_width / pitting.N_FACE
        iu = (u >= spall["u_from"]) & (u <= spall["u_to"])
        iz = (zz >= spall["z_from"]) & (zz <= spall["z_to"])
        depth[spall["tooth"]][np.ix_(iu, iz)] = np.maximum(
            depth[spall["tooth"]][np.ix_(iu, iz)], spall["depth"])
    info["pitted_fraction_per_tooth"] = [float(x) for x in (depth > 0).mean(axis=(1, 2))]
    body = tab.body_pinion + tab.body_gear
    f_ref = np.maximum(f_nom.max() / 1.5, 10.0)
    hertz_lin = tab.hertz_q * (tab.hertz_a - np.log(f_ref) - 1)
    w, phi, pit_gap = pitting.slice_contact(depth, body, hertz_lin, g.face_width, params.numerics.slices)
    gap_p += pit_gap
    comp_p = tab.body_gear[None] + tab.body_pinion[None] * 1.0 + (phi - 1.0) * body[None]
    return MeshTables(float(u[1] - u[0]), u, gap_p, gap_g, comp_p, w, tab.hertz_a, tab.hertz_q, info)
