"""A third simulator of the test gearbox, of another model family: loaded tooth contact + linear dynamics.

The twin (21 DOF) and the lumped rig (:mod:`rigs.lumped`) both integrate a time-varying,
nonlinear mesh contact in the time domain.  This module follows the other classic line of gear
noise modelling: a quasi-static *loaded tooth contact analysis* (LTCA) gives the static
transmission error, and that error excites a linear mesh mode (Ozguven & Houser, J. Sound Vib. 121,
1988), whose force reaches the sensor through a bearing and the casing.  It was written (2026-11-24)
after the archive and assessor settings had been chosen, and fixed before it was first scored, so it
is a blind test of those choices.  It shares the datasheet geometry (:func:`rigs.lumped.mesh_geometry`) and
the record drawing (:func:`rigs.lumped.write_simulated_target`) with the lumped rig, no
physics.

=============================  =====================================================================
part                           this simulator (defaults in :class:`LtcaRig`)
=============================  =====================================================================
pair stiffness                 from beam theory: each tooth a cantilever with its involute thickness
                               (radial flank below the base circle), bending ``12 int (y_L - y)^2 /
                               (E b s^3)`` and shear ``1.2 int 1 / (G b s)``, plus a Hertzian
                               ``4 (1 - nu^2) / (pi E b)``; the compliances add, and the peak is
                               scaled to ISO 6336-1's ``c' b`` (beam theory has no fillet or
                               foundation compliance)
load sharing                   quasi-static: the approach ``delta`` solves
                               ``sum_j k_j max(0, delta - e_j) = F`` over the pairs in mesh, with
                               ``e_j`` each pair's deviation (tooth errors, wear)
tooth errors                   cumulative pitch deviations of pinion *and* gear (a closed random walk of
                               single-pitch deviations, 1.5 / 1.8 um sd) and both run-outs (radial
                               8 / 10 um, i.e. ``F_r / 2 sin(alpha)`` along the line of action), fixed
                               for the gearbox: a precision-ground pair
dynamics                       linear: ``m_e x'' + c x' + k_m x = k_m delta(t)``, ``k_m`` the mean
                               mesh stiffness, 5 % damping; the dynamic mesh force ``-m_e x''`` drives
                               the pinion bearing (1.2 kg on 1.5e8 N/m, 1.8 kHz) whose force drives five
                               casing modes (1.1-9.3 kHz)
speed                          the drive's coupling adds a twice-per-revolution speed ripple (0.1 %)
wear                           Archard, integrated: in steps of 0.25 um of mean depth, each flank point
                               wears by its load (from the load sharing at the test's load, on the
                               worn profiles) times its sliding distance per mesh, ``|v1 - v2| 2a /
                               v_i`` (Flodin & Andersson 1997); pinion *and* gear (the gear's teeth
                               mesh z1/z2 times as often); per-tooth factors (sd 5 %)
pitting                        discrete pits: per pinion tooth a fixed sequence of circular pits
                               (log-normal radius, median 0.4 mm) centred below the pitch line,
                               added until the pitted share of the active flank is ``D a_i`` (``a_i``
                               gamma, sd 40 %, mean 1 over the teeth); a contact line loses the
                               stiffness of its pitted width (at most 95 %)
acquisition                    25.6 kHz (no time integration: the transmission error is computed and
                               filtered at 4x that rate, then decimated), gain 10 %, noise 6 %,
                               speed and load scatter 1.5 % / 8 %
=============================  =====================================================================

Limits, by design: no loss of contact in the dynamics (the linear model allows negative force), one
mesh mode, the flank measured in roll distance (pits are circles in that coordinate), no fillet.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from rigs.lumped import (ISO_SINGLE_PAIR_STIFFNESS, check_records, field_problems, mesh_geometry, mode_problems,
                         write_simulated_target)
from twin.errors import ParameterError, SimulationError

__all__ = ["LtcaRig", "lost_width", "make_ltca_target", "pair_stiffness", "pit_fields", "simulate_ltca",
           "static_approach", "wear_profiles"]

_U_NODES = 401          # points along the path of contact for the profiles
_PIT_GRID = (146, 80)   # cells along the path x across the face for the pit fields (~0.1 x 0.25 mm)
_PITS_PER_TOOTH = 4000  # enough to pit any tooth to over 60 % of its flank


@dataclass(frozen=True)
class LtcaRig:
    """The LTCA simulator's gearbox, structure and acquisition (module docstring for the physics).

    Attributes
    ----------
    teeth : tuple of int
        Pinion and gear tooth numbers.
    module, pressure_angle, face_width : float
        Module [m], pressure angle [rad], face width [m].
    youngs_modulus, poisson_ratio : float
        Steel [Pa], [-].
    mesh_damping : float
        Damping ratio of the mesh mode [-].
    pitch_error, runout : tuple of float
        Single-pitch deviation sd [m] and radial run-out [m] of (pinion, gear).
    coupling_ripple : float
        Amplitude of the twice-per-revolution speed ripple, relative [-].
    wear_tooth_scatter, pitting_tooth_scatter : float
        Relative sd of the per-tooth wear and pitting factors [-].
    pit_radius, pit_radius_spread : float
        Median pit radius [m] and the sd of its log [-].
    pit_spread : float
        Sd of the pits' distance below the pitch point, as a fraction of the path [-].
    shaft_mass, bearing_stiffness, bearing_damping : float
        Pinion bearing mode: mass [kg], stiffness [N/m], damping ratio [-].
    modes_hz, modes_damping, modes_gain : tuple of float
        Casing modes: frequency [Hz], damping ratio [-], relative participation [-].
    sample_rate : float
        Acquisition rate [Hz].
    oversampling : int
        Filter rate / acquisition rate.
    gain_error, noise, speed_scatter, load_scatter : float
        As in :class:`twin.transfer.domain.TargetShift`.
    """

    teeth: tuple = (19, 52)
    module: float = 3e-3
    pressure_angle: float = math.radians(20.0)
    face_width: float = 0.020
    youngs_modulus: float = 2.06e11
    poisson_ratio: float = 0.3
    mesh_damping: float = 0.05
    pitch_error: tuple = (1.5e-6, 1.8e-6)
    runout: tuple = (8e-6, 10e-6)
    coupling_ripple: float = 0.001
    wear_tooth_scatter: float = 0.05
    pitting_tooth_scatter: float = 0.4
    pit_radius: float = 0.4e-3
    pit_radius_spread: float = 0.5
    pit_spread: float = 0.15
    shaft_mass: float = 1.2
    bearing_stiffness: float = 1.5e8
    bearing_damping: float = 0.04
    modes_hz: tuple = (1100.0, 2450.0, 3900.0, 6200.0, 9300.0)
    modes_damping: tuple = (0.02, 0.03, 0.03, 0.04, 0.05)
    modes_gain: tuple = (0.5, 1.0, 0.8, 0.6, 0.3)
    sample_rate: float = 25600.0
    oversampling: int = 4
    gain_error: float = 0.10
    noise: float = 0.06
    speed_scatter: float = 0.015
    load_scatter: float = 0.08

    def __post_init__(self) -> None:
        # tuples, so a rig is hashable (one gearbox's draws are cached per rig and seed)
        for name in ("teeth", "pitch_error", "runout", "modes_hz", "modes_damping", "modes_gain"):
            if isinstance(getattr(self, name), list):
                object.__setattr__(self, name, tuple(getattr(self, name)))
        problems = []
        if len(self.teeth) != 2 or not all(isinstance(z, int) and z >= 10 for z in self.teeth):
            problems.append(f"teeth must be two integers >= 10, got {self.teeth!r}")
        problems += field_problems(self, ("module", "pressure_angle", "face_width", "youngs_modulus", "mesh_damping",
                                          "pit_radius", "pit_spread", "shaft_mass", "bearing_stiffness",
                                          "bearing_damping", "sample_rate"),
                                   ("coupling_ripple", "wear_tooth_scatter", "pitting_tooth_scatter",
                                    "pit_radius_spread", "gain_error", "noise", "speed_scatter", "load_scatter"))
        if not (isinstance(self.poisson_ratio, (int, float)) and 0 <= self.poisson_ratio < 0.5):
            problems.append(f"poisson_ratio must be in [0, 0.5), got {self.poisson_ratio!r}")
        for name in ("pitch_error", "runout"):
            v = getattr(self, name)
            if len(v) != 2 or not all(isinstance(x, (int, float)) and math.isfinite(x) and x >= 0 for x in v):
                problems.append(f"{name} must be two finite numbers >= 0 (pinion, gear), got {v!r}")
        if not (isinstance(self.oversampling, int) and self.oversampling >= 1):
            problems.append(f"oversampling must be a positive integer, got {self.oversampling!r}")
        problems += mode_problems(self)
        if problems:
            raise ParameterError("LtcaRig: " + "; ".join(problems))


# ---- geometry and stiffness ----------------------------------------------------------------------------
def _geometry(rig: LtcaRig):
    """(MeshGeometry, path length L [m], pinion and gear radii of curvature along u, shape (_U_NODES,) each)."""
    g = mesh_geometry(rig)
    length = g.contact_ratio * math.pi * rig.module * math.cos(rig.pressure_angle)
    r1 = 0.5 * rig.module * rig.teeth[0]
    r2 = 0.5 * rig.module * rig.teeth[1]
    u = np.linspace(0.0, 1.0, _U_NODES)
    rho1 = r1 * math.sin(rig.pressure_angle) - g.roll_pitch * length + u * length
    rho2 = (r1 + r2) * math.sin(rig.pressure_angle) - rho1
    return g, length, rho1, rho2


def _tooth_compliance(rig: LtcaRig, z: int, rho: np.ndarray) -> np.ndarray:
    """Bending + shear compliance [m/N] of a tooth of ``z`` teeth loaded where its radius of curvature is ``rho``."""
    a = rig.pressure_angle
    r = 0.5 * rig.module * z
    rb, rf = r * math.cos(a), r - 1.25 * rig.module
    inv = lambda x: np.tan(x) - x                                       # noqa: E731 (the involute function)
    grid = np.linspace(rf, r + rig.module, 400)
    # involute thickness above the base circle; below it the flank is taken radial (the base thickness)
    alpha_r = np.arccos(np.minimum(rb / np.maximum(grid, rb), 1.0))
    thick = 2 * np.maximum(grid, rb) * (math.pi / (2 * z) + inv(a) - inv(alpha_r))
    e, shear = rig.youngs_modulus, rig.youngs_modulus / (2 * (1 + rig.poisson_ratio))
    load_r = np.sqrt(rb ** 2 + rho ** 2)
    out = np.empty_like(rho)
    for i, rl in enumerate(load_r):
        m = grid <= rl
        y, s = grid[m], thick[m]
        out[i] = (np.trapezoid(12 * (rl - y) ** 2 / (e * rig.face_width * s ** 3), y)
                  + np.trapezoid(1.2 / (shear * rig.face_width * s), y))
    return out


def pair_stiffness(rig: LtcaRig) -> np.ndarray:
    """Single-pair stiffness along the path of contact [N/m], shape (_U_NODES,), u from 0 (pinion root) to 1.

    Beam theory gives the shape; its peak is ISO 6336-1's ``c' b`` (14 N/(mm um) times the face width).
    """
    _, _, rho1, rho2 = _geometry(rig)
    hertz = 4 * (1 - rig.poisson_ratio ** 2) / (math.pi * rig.youngs_modulus * rig.face_width)
    k = 1.0 / (_tooth_compliance(rig, rig.teeth[0], rho1) + _tooth_compliance(rig, rig.teeth[1], rho2) + hertz)
    return k * (ISO_SINGLE_PAIR_STIFFNESS * rig.face_width / k.max())


def static_approach(k: np.ndarray, e: np.ndarray, force) -> np.ndarray:
    """Quasi-static approach ``delta`` [m] with ``sum_j k_j max(0, delta - e_j) = force``.

    Parameters
    ----------
    k, e : ndarray (..., P)
        Pair stiffness [N/m] (0 for a pair out of mesh) and deviation [m] of the P pairs; at
        least one pair per position must be in mesh (the leading pair always is).
    force : float or ndarray (...)
        Mesh force [N], > 0.

    Returns
    -------
    ndarray (...)
        The approach; the pairs with ``e_j < delta`` carry the load.
    """
    k, e = np.broadcast_arrays(np.asarray(k, dtype=float), np.asarray(e, dtype=float))
    e = np.where(k > 0, e, np.inf)
    order = np.argsort(e, axis=-1)
    ks, es = np.take_along_axis(k, order, -1), np.take_along_axis(e, order, -1)
    ck = np.cumsum(ks, axis=-1)
    cke = np.cumsum(ks * np.where(ks > 0, es, 0.0), axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = (np.asarray(force, dtype=float)[..., None] + cke) / ck
    nxt = np.concatenate([es[..., 1:], np.full(es.shape[:-1] + (1,), np.inf)], axis=-1)
    ok = (ck > 0) & (delta <= nxt)
    return np.take_along_axis(delta, np.argmax(ok, axis=-1)[..., None], -1)[..., 0]


def _partners(eps: float, u: np.ndarray):
    """Path positions of the pairs in mesh together with a pair at ``u``: (len(u), P), NaN where none."""
    n = int(math.ceil(eps))
    shifts = np.arange(-n, n + 1) / eps
    v = u[:, None] + shifts[None, :]
    return np.where((v >= 0) & (v < 1) | (shifts == 0)[None, :], v, np.nan)


def wear_profiles(rig: LtcaRig, depths, load: float) -> tuple[np.ndarray, np.ndarray]:
    """Worn profiles of pinion and gear at the given mean pinion wear depths [m].

    Archard's law integrated in steps of 0.25 um of mean pinion depth: each step re-solves the load
    sharing at the brake torque ``load`` [N.m] on the current worn profiles, and each flank point
    wears by its load times its sliding distance per mesh (module docstring).

    Returns
    -------
    pinion, gear : ndarray (len(depths), _U_NODES)
        Material removed along the path of contact [m]; ``pinion.mean(axis=1) == depths``.
    """
    depths = np.asarray(depths, dtype=float)
    if depths.ndim != 1 or not np.all(np.isfinite(depths) & (depths >= 0)):
        raise ParameterError("wear depths must be a 1-D array of finite numbers >= 0")
    step = 0.25e-6
    n_steps = int(math.ceil(depths.max() / step)) if depths.size and depths.max() > 0 else 0
    if n_steps == 0:
        return np.zeros((depths.size, _U_NODES)), np.zeros((depths.size, _U_NODES))
    g, _, rho1, rho2 = _geometry(rig)
    u = np.linspace(0.0, 1.0, _U_NODES)
    k = pair_stiffness(rig)
    ratio = rig.teeth[0] / rig.teeth[1]
    slide = np.abs(rho1 - ratio * rho2)
    slide1, slide2 = slide / rho1, slide / rho2     # per pinion-tooth mesh; the gear's teeth mesh z1/z2 as often
    force = load / g.base_radii[1]
    part = _partners(g.contact_ratio, u)
    have = np.isfinite(part)
    kp = np.where(have, np.interp(np.nan_to_num(part), u, k), 0.0)
    centre = int(math.ceil(g.contact_ratio))         # the column of the pair itself
    h1, h2 = np.zeros(_U_NODES), np.zeros(_U_NODES)
    hist1, hist2 = [h1.copy()], [h2.copy()]
    for _ in range(n_steps):
        dev = np.where(have, np.interp(np.nan_to_num(part), u, h1 + h2), np.inf)
        delta = static_approach(kp, dev, force)
        share = kp[:, centre] * np.maximum(delta - dev[:, centre], 0.0)
        d1, d2 = share * slide1, share * slide2
        scale = step / d1.mean()
        h1, h2 = h1 + scale * d1, h2 + scale * d2
        hist1.append(h1.copy())
        hist2.append(h2.copy())
    grid = step * np.arange(n_steps + 1)
    hist1, hist2 = np.array(hist1), np.array(hist2)
    idx = np.clip(np.searchsorted(grid, depths) - 1, 0, n_steps - 1)
    w = ((depths - grid[idx]) / step)[:, None]
    p1 = (1 - w) * hist1[idx] + w * hist1[idx + 1]
    p2 = (1 - w) * hist2[idx] + w * hist2[idx + 1]
    return p1, p2


def pit_fields(rig: LtcaRig, rng: np.random.Generator) -> np.ndarray:
    """Order in which each pinion tooth's flank cells pit: shape (z1, *_PIT_GRID), int.

    Cell value n means the n-th pit of that tooth's sequence is the first to cover the cell
    (``_PITS_PER_TOOTH`` where none does).  A tooth with ``N`` pits has the cells ``< N`` pitted.
    Centres lie below the pitch point by a half-normal distance (sd ``pit_spread`` of the path),
    uniformly across the face; radii are log-normal.
    """
    g, length, _, _ = _geometry(rig)
    nu, nz = _PIT_GRID
    cu = (np.arange(nu) + 0.5) / nu * length
    cz = (np.arange(nz) + 0.5) / nz * rig.face_width
    fields = np.empty((rig.teeth[0], nu, nz), dtype=np.int32)
    for tooth in range(rig.teeth[0]):
        uc = np.clip(g.roll_pitch - np.abs(rig.pit_spread * rng.standard_normal(_PITS_PER_TOOTH)), 0, 1) * length
        zc = rng.uniform(0, rig.face_width, _PITS_PER_TOOTH)
        rad = rig.pit_radius * np.exp(rig.pit_radius_spread * rng.standard_normal(_PITS_PER_TOOTH))
        first = np.full((nu, nz), _PITS_PER_TOOTH, dtype=np.int32)
        for c in range(0, _PITS_PER_TOOTH, 250):
            sl = slice(c, c + 250)
            inside = ((cu[None, :, None] - uc[sl, None, None]) ** 2 + (cz[None, None, :] - zc[sl, None, None]) ** 2
                      <= rad[sl, None, None] ** 2)
            hit = inside.any(axis=0)
            first = np.where((first == _PITS_PER_TOOTH) & hit, c + np.argmax(inside, axis=0), first)
        fields[tooth] = first
    return fields


def lost_width(fields: np.ndarray, densities: np.ndarray) -> np.ndarray:
    """Pitted share of the face width along the path, (z1, _U_NODES), for pitted flank shares ``densities`` (z1,)."""
    nu = fields.shape[1]
    cells = fields.shape[1] * fields.shape[2]
    out = np.empty((fields.shape[0], _U_NODES))
    u = np.linspace(0.0, 1.0, _U_NODES)
    centres = (np.arange(nu) + 0.5) / nu
    for i, (f, d) in enumerate(zip(fields, densities)):
        need = int(math.ceil(min(max(d, 0.0), 1.0) * cells))
        # a share beyond what the whole sequence pits (about 54 % of the flank) stops there
        n = min(np.sort(f, axis=None)[need - 1] + 1, _PITS_PER_TOOTH) if need > 0 else 0
        out[i] = np.interp(u, centres, (f < n).mean(axis=1))
    return out


# ---- the records --------------------------------------------------------------------------------------
def _closed_walk(rng: np.random.Generator, z: int, sd: float) -> np.ndarray:
    """Cumulative pitch deviations of a gear: single-pitch deviations summed and closed round the gear."""
    f = sd * rng.standard_normal(z)
    f -= f.mean()
    cum = np.cumsum(f)
    return cum - cum.mean()


@lru_cache(maxsize=4)
def _gearbox(rig: LtcaRig, gear_seed: int, kind: str) -> tuple:
    """The draws that make one gearbox: pitch deviations and run-out phases of both gears, then the
    per-tooth wear factors (wear) or pit factors and pit fields (pitting).  The same for every batch
    of records of a target domain, so it is drawn once (the pit fields take seconds)."""
    z1, z2 = rig.teeth
    rng = np.random.default_rng(gear_seed)
    pitch1, pitch2 = _closed_walk(rng, z1, rig.pitch_error[0]), _closed_walk(rng, z2, rig.pitch_error[1])
    phases = tuple(rng.uniform(0, 2 * np.pi, 2))
    if kind == "wear_depth":
        factors = (1 + rig.wear_tooth_scatter * rng.standard_normal(z1),
                   1 + rig.wear_tooth_scatter * rng.standard_normal(z2))
        return pitch1, pitch2, phases, factors, None
    shape = 1.0 / max(rig.pitting_tooth_scatter, 1e-3) ** 2
    pit_factor = rng.gamma(shape, 1.0 / shape, z1)
    return pitch1, pitch2, phases, (pit_factor / pit_factor.mean(),), pit_fields(rig, rng)


def simulate_ltca(rig: LtcaRig, speeds, loads, damages, kind: str, duration: float, *, gear_seed: int,
                  nominal_load: float, start_angles=None, settle: float = 0.05) -> np.ndarray:
    """Casing acceleration of records of the LTCA model, before gain and noise.

    Parameters
    ----------
    speeds, loads, damages : array_like, shape (R,)
        Pinion speed [Hz], brake (output) torque [N.m], and the stage variable (pitting density
        [-] or mean pinion wear depth [m]) per record.
    kind : {"pitting_density", "wear_depth"}
    duration : float
        Record length after ``settle`` [s].
    gear_seed : int
        Seeds the gearbox: tooth errors, per-tooth factors, pit sequences.
    nominal_load : float
        Brake torque the wear grew under [N.m].
    start_angles : array_like, shape (R,), optional
        Pinion angle at the start of each record [rad] (default 0).

    Returns
    -------
    ndarray, shape (R, round(duration * rig.sample_rate))
        Acceleration [arbitrary but consistent units].
    """
    from scipy.signal import bilinear, decimate, lfilter

    if not (isinstance(nominal_load, (int, float)) and math.isfinite(nominal_load) and nominal_load > 0):
        raise ParameterError(f"nominal_load must be a finite number > 0 [N.m], got {nominal_load!r}")
    speeds, loads, damages, start = check_records(speeds, loads, damages, kind, start_angles)
    z1, z2 = rig.teeth
    g, _, _, _ = _geometry(rig)
    eps = g.contact_ratio
    u_nodes = np.linspace(0.0, 1.0, _U_NODES)
    k_u = pair_stiffness(rig)
    pitch1, pitch2, (phase1, phase2), factors, fields = _gearbox(rig, int(gear_seed), kind)
    ecc1, ecc2 = (0.5 * r * math.sin(rig.pressure_angle) for r in rig.runout)
    if kind == "wear_depth":
        wear1, wear2 = factors
        prof1, prof2 = wear_profiles(rig, damages, nominal_load)
    else:
        (pit_factor,) = factors

    fs = rig.sample_rate * rig.oversampling
    n_settle, n_keep = int(round(settle * fs)), int(round(duration * rig.sample_rate)) * rig.oversampling
    t = np.arange(n_settle + n_keep) / fs
    k_mean = np.mean(k_u) * eps
    pairs = np.arange(int(math.ceil(eps)))
    te = np.empty((speeds.size, t.size))
    for r in range(speeds.size):
        f = speeds[r]
        # a twice-per-revolution speed ripple a: theta' = 2 pi f (1 + a sin(2 theta0))
        theta = start[r] + 2 * np.pi * f * t - rig.coupling_ripple / 2 * (np.cos(4 * np.pi * f * t) - 1)
        p = theta * z1 / (2 * np.pi)
        n = np.floor(p)
        u = ((p - n)[:, None] + pairs) / eps
        active = u < 1.0
        uc = np.minimum(u, 1.0)
        t1 = ((n[:, None] - pairs) % z1).astype(np.intp)
        t2 = ((n[:, None] - pairs) % z2).astype(np.intp)
        k = np.interp(uc, u_nodes, k_u)
        e = pitch1[t1] + pitch2[t2]
        if kind == "wear_depth":
            e = e + wear1[t1] * np.interp(uc, u_nodes, prof1[r]) + wear2[t2] * np.interp(uc, u_nodes, prof2[r])
        else:
            lost = lost_width(fields, damages[r] * pit_factor)
            idx = uc * (_U_NODES - 1)
            i0 = np.minimum(idx.astype(np.intp), _U_NODES - 2)
            w = idx - i0
            k = k * (1.0 - np.minimum(0.95, (1 - w) * lost[t1, i0] + w * lost[t1, i0 + 1]))
        delta = static_approach(np.where(active, k, 0.0), e, loads[r] / g.base_radii[1])
        te[r] = (delta + ecc1 * np.cos(theta + phase1) + ecc2 * np.cos(theta * z1 / z2 + phase2))
    if not np.all(np.isfinite(te)):
        raise SimulationError("the LTCA model gave a non-finite transmission error")
    te -= te.mean(axis=1, keepdims=True)

    def filt(x, num, den):
        b, a = bilinear(num, den, fs=fs)
        return lfilter(b, a, x, axis=1)

    def warped(f_hz):
        return 2 * fs * math.tan(math.pi * f_hz / fs)

    wm = warped(math.sqrt(k_mean / g.equivalent_mass) / (2 * np.pi))
    force = filt(te, [-k_mean, 0.0, 0.0], [1.0, 2 * rig.mesh_damping * wm, wm ** 2])
    wb = warped(math.sqrt(rig.bearing_stiffness / rig.shaft_mass) / (2 * np.pi))
    bearing = filt(force, [2 * rig.bearing_damping * wb, wb ** 2], [1.0, 2 * rig.bearing_damping * wb, wb ** 2])
    acc = np.zeros_like(bearing)
    for fm, zeta, gain in zip(rig.modes_hz, rig.modes_damping, rig.modes_gain):
        w = warped(fm)
        acc += gain * filt(bearing, [1.0, 0.0, 0.0], [1.0, 2 * zeta * w, w ** 2])
    acc = acc[:, n_settle:]
    if rig.oversampling > 1:
        acc = decimate(acc, rig.oversampling, ftype="fir", axis=1, zero_phase=True)
    return acc


def make_ltca_target(source_scenario, output: str | Path, *, records_per_stage: int = 15,
                     record_duration: float = 0.4, seed: int = 4, rig: LtcaRig | None = None,
                     progress: bool = True) -> Path:
    """Simulate the target domain of ``source_scenario``'s stages on the LTCA model; write it.

    Same file layout as :func:`rigs.lumped.make_lumped_target`, with the metadata entry
    ``ltca_rig`` (JSON).  Only the scenario's stages, damage kind and nominal operating point are
    read; its FMU is not used.
    """
    rig = rig or LtcaRig()
    return write_simulated_target(
        source_scenario, output, rig, lambda *a, **k: simulate_ltca(rig, *a, **k), name="ltca",
        records_per_stage=records_per_stage, record_duration=record_duration, seed=seed, progress=progress,
        note="independent LTCA simulator (rigs.ltca); labels and damage are for evaluation only")


if __name__ == "__main__":
    import sys

    from rigs.lumped import main

    sys.exit(main(make=make_ltca_target, prog="python -m rigs.ltca"))
