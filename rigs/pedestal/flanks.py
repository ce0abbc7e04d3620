"""Per-tooth flank tables of one gearbox on the path coordinate, and its loaded mean stiffness.

A table row belongs to one tooth, a column to one point ``s`` of the path of contact (see
``geometry``). Deviations are *material missing* along the line of action [m] (a positive value
delays contact); stiffness factors multiply the pair stiffness law.

Manufacturing deviations follow the ISO 1328-1:2013 tolerance formulas for a flank tolerance
class A (``sqrt(2) ** (A - 5)`` times the class-5 value, d and m in mm, result in um):

* single pitch ``f_pT = 0.001 d + 0.4 m + 5``;
* helix-free profile slope ``f_HaT = 2 sqrt(m) + 0.14 sqrt(d) + 0.5`` and form
  ``f_faT = 2.5 sqrt(m) + 0.17 sqrt(d) + 0.5``.

The real deviations of a gearbox are drawn with a standard deviation of a fraction of these
tolerances; single pitch deviations close over a revolution (their cumulative sum is the tooth
position error); profile slope and form are mostly the tool's (common to all teeth of a gear)
plus a tooth-specific share. Surface roughness is a Gaussian profile with an exponential
correlation, fixed
for the gearbox, so it repeats with the hunting period.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import GearPair
from .params import Flanks

N_PATH = 480   # points on the path of contact (30 um spacing for the default pair)


@dataclass(frozen=True)
class ToothTables:
    """Flank state of a gearbox (arrays are read-only by convention)."""

    s: np.ndarray            # (N_PATH,) path coordinate [m]
    shape: np.ndarray        # (N_PATH,) single-pair stiffness law k1/k_max
    pinion_dev: np.ndarray   # (z1, N_PATH) [m]
    gear_dev: np.ndarray     # (z2, N_PATH) [m]
    pinion_k: np.ndarray     # (z1, N_PATH) stiffness factor
    gear_k: np.ndarray       # (z2, N_PATH)

    def replace(self, **kw) -> "ToothTables":
        d = dict(self.__dict__)
        d.update(kw)
        return ToothTables(**d)


def iso1328_tolerances(gears: GearPair, d_mm: float, iso_class: int) -> dict:
    """Single pitch, profile slope and profile form tolerances [m] of one gear."""
    m = gears.module * 1e3
    f = np.sqrt(2.0) ** (iso_class - 5)
    return {"f_pT": (0.001 * d_mm + 0.4 * m + 5.0) * f * 1e-6,
            "f_HaT": (2.0 * np.sqrt(m) + 0.14 * np.sqrt(d_mm) + 0.5) * f * 1e-6,
            "f_faT": (2.5 * np.sqrt(m) + 0.17 * np.sqrt(d_mm) + 0.5) * f * 1e-6}


def _roughness(rng: np.random.Generator, n_teeth: int, s: np.ndarray, rms: float,
               corr: float) -> np.ndarray:
    """AR(1) profiles along s: exponential correlation exp(-|ds|/corr), std ``rms``."""
    ds = s[1] - s[0]
    a = np.exp(-ds / corr)
    white = rng.standard_normal((n_teeth, s.size))
    out = np.empty_like(white)
    out[:, 0] = white[:, 0]
    scale = np.sqrt(1.0 - a * a)
    for j in range(1, s.size):
        out[:, j] = a * out[:, j - 1] + scale * white[:, j]
    return rms * out


def _gear_tables(rng, gears: GearPair, fl: Flanks, z: int, d_mm: float, s: np.ndarray,
                 root_at_start: bool) -> np.ndarray:
    tol = iso1328_tolerances(gears, d_mm, fl.iso_class)
    frac = fl.deviation_fraction
    fp = rng.normal(0.0, frac * tol["f_pT"], z)
    fp -= fp.mean()                               # pitches close over one revolution
    position = np.cumsum(fp)
    position -= position.mean()
    # profile coordinate of the flank from root (0) to tip (1) at each path point
    u = s / s[-1] if root_at_start else 1.0 - s / s[-1]
    x = 2.0 * u - 1.0
    # Profile slope and form come mostly from the tool (common to every tooth of a gear) and
    # a smaller tooth-specific part (indexing, clamping, tool wear along the cut).
    own = fl.tooth_to_tooth
    slope = rng.normal(0.0, frac * tol["f_HaT"]) + own * rng.normal(0.0, frac * tol["f_HaT"], z)
    # form: low-order Legendre content (P2..P4) scaled to the form tolerance fraction
    leg = np.stack([0.5 * (3 * x ** 2 - 1), 0.5 * (5 * x ** 3 - 3 * x),
                    0.125 * (35 * x ** 4 - 30 * x ** 2 + 3)])
    sig = frac * tol["f_faT"] / np.sqrt(3.0)
    coef = rng.normal(0.0, sig, (1, 3)) + own * rng.normal(0.0, sig, (z, 3))
    dev = position[:, None] + 0.5 * slope[:, None] * x[None, :] + coef @ leg
    dev += _roughness(rng, z, s, fl.roughness_rms, fl.roughness_correlation)
    return dev


def manufactured_tables(gears: GearPair, fl: Flanks, seed: int) -> ToothTables:
    """Tooth tables of a healthy, as-manufactured gearbox (seeded by its identity)."""
    rng = np.random.default_rng([seed, 7])
    s = np.linspace(0.0, gears.path_length, N_PATH)
    pin = _gear_tables(rng, gears, fl, gears.z1, 2e3 * gears.r1, s, root_at_start=True)
    gear = _gear_tables(rng, gears, fl, gears.z2, 2e3 * gears.r2, s, root_at_start=False)
    # deburred tip edges: a parabolic roll-off over the last ``tip_roll`` of each tip's path
    # (gear tip at A, pinion tip at E), so engagement and release are gradual
    lr = fl.tip_roll
    gear += fl.tip_relief * np.clip(1.0 - s / lr, 0.0, 1.0)[None, :] ** 2
    pin += fl.tip_relief * np.clip(1.0 - (s[-1] - s) / lr, 0.0, 1.0)[None, :] ** 2
    return ToothTables(s=s, shape=gears.pair_stiffness_shape(s), pinion_dev=pin, gear_dev=gear,
                       pinion_k=np.ones((gears.z1, N_PATH)), gear_k=np.ones((gears.z2, N_PATH)))


def hunting_contacts(gears: GearPair, tables: ToothTables, positions_per_mesh: int = 12):
    """Contacting pairs over one hunting period, positions on the pinion roll.

    Returns ``(k_rel, dev)`` of shape (positions, pairs) with ``k_rel`` the stiffness relative
    to k_max (0 where the pair is out of contact) and ``dev`` the deviation of the pair.
    """
    z1, z2 = gears.z1, gears.z2
    n_hunt = z1 * z2 // np.gcd(z1, z2)
    pb, L = gears.base_pitch, gears.path_length
    u = (np.arange(n_hunt * positions_per_mesh) + 0.5) * pb / positions_per_mesh
    n_pairs = int(np.ceil(L / pb)) + 1
    n_hi = np.floor(u / pb).astype(int)
    k_rel = np.zeros((u.size, n_pairs))
    dev = np.zeros((u.size, n_pairs))
    ds = tables.s[1] - tables.s[0]
    for j in range(n_pairs):
        n = n_hi - j
        s = u - n * pb
        inside = (s >= 0.0) & (s <= L)
        idx = np.clip(s / ds, 0, tables.s.size - 1.000001)
        i0 = idx.astype(int)
        fr = idx - i0
        ip, ig = n % z1, n % z2

        def lerp(tab, rows):
            return tab[rows, i0] * (1 - fr) + tab[rows, i0 + 1] * fr

        kk = np.interp(s, tables.s, tables.shape) * lerp(tables.pinion_k, ip) * lerp(
            tables.gear_k, ig)
        k_rel[:, j] = np.where(inside, kk, 0.0)
        dev[:, j] = np.where(inside, lerp(tables.pinion_dev, ip) + lerp(tables.gear_dev, ig),
                             np.inf)
    return k_rel, dev


def pair_force(k: np.ndarray, x: np.ndarray, mismatch: float) -> tuple[np.ndarray, np.ndarray]:
    """Face-integrated force and tangent stiffness of pairs with approach ``x = delta - e`` [m]
    and a linear gap ``mismatch`` [m] across the face (full contact once x >= mismatch / 2)."""
    f = max(float(mismatch), 1e-9)
    h = x + 0.5 * f
    full = h >= f
    part = (h > 0) & ~full
    force = np.where(full, k * x, np.where(part, k * h * h / (2 * f), 0.0))
    tangent = np.where(full, k, np.where(part, k * h / f, 0.0))
    return force, tangent


def static_contact(k_rel: np.ndarray, dev: np.ndarray, k_max: float, force: float,
                   mismatch: float = 0.0):
    """Quasi-static loaded contact: deflection delta and tangent stiffness at each position.

    Solves ``sum_j F_j(delta - e_j) = force`` (``pair_force``) by bisection, to 1e-12 m.
    """
    k = k_rel * k_max
    e = np.where(np.isfinite(dev) & (k > 0), dev, np.inf)
    lo = np.min(e, axis=1) - 0.5 * mismatch
    hi = lo + force / np.maximum(np.max(k, axis=1), 1.0) + mismatch + 1e-6
    ee = np.where(np.isfinite(e), e, 0.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        fm, _ = pair_force(k, mid[:, None] - ee, mismatch)
        fm = np.where(np.isfinite(e), fm, 0.0).sum(axis=1)
        big = fm > force
        hi = np.where(big, mid, hi)
        lo = np.where(big, lo, mid)
    delta = 0.5 * (lo + hi)
    _, tg = pair_force(k, delta[:, None] - ee, mismatch)
    return delta, np.where(np.isfinite(e), tg, 0.0).sum(axis=1)


def mean_tangent_stiffness(gears: GearPair, tables: ToothTables, load: float,
                           mismatch: float) -> float:
    """Mean tangent mesh stiffness [N/m] of this gearbox at output torque ``load`` [N.m]
    with a mismatch across the face ``mismatch`` [m]."""
    k_rel, dev = hunting_contacts(gears, tables)
    _, tangent = static_contact(k_rel, dev, gears.pair_stiffness_max(load),
                                max(abs(load), 0.5) / gears.rb2, mismatch)
    return float(np.mean(tangent))
