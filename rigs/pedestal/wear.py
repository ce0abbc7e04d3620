"""Abrasive (Archard) wear of both flanks, as a worn-profile law scaled by the mean depth.

Archard: the depth worn at a flank point per pass is ``k_w p s``, contact pressure times the
distance slid under the contact. A point of body i crosses the Hertzian band of width 2 b_H at
its rolling speed v_i while the other surface slides past at v_1 - v_2, so it slides
``2 b_H |v_1 - v_2| / v_i`` per pass, and with the mean band pressure ``w' / (2 b_H)``:

    dh_i(s) = k_w w'(s) |v_1 - v_2| / v_i

with w'(s) the load per face width carried by the pair at s. Here ``w'`` comes from the rig's
own load sharing (the pair-stiffness law, shared by stiffness in the double-contact zones), the
speeds from the radii of curvature (zero wear at the pitch point, most at the pinion root where
the specific sliding is highest), and the profile is smoothed over the largest Hertzian width,
because each point is worn by the whole passing band. Pinion teeth pass z2/z1 times as often as
gear teeth, so the gear profile carries the factor z1/z2.

The damage measure is the *mean wear depth of the pinion's active flank* [m]; the gear follows
with the same wear coefficient. Each tooth of either gear wears with its own factor (std 8 %)
because it met its own partners' roughness. Wear removes material at every point of the path
(a positive deviation), opens the backlash by the mean depths, and thins the teeth, whose
bending stiffness (~ thickness^3, about half the pair compliance) falls accordingly.
"""
from __future__ import annotations

import numpy as np

from .flanks import ToothTables
from .geometry import GearPair


def _archard_rates(gears: GearPair, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Wear per unit line load and per pinion revolution at s: (pinion, gear)."""
    rho1, rho2 = gears.radii_of_curvature(s)
    v1 = rho1                                  # per unit pinion angular speed
    v2 = rho2 * gears.z1 / gears.z2
    slip = np.abs(v1 - v2)
    return slip / v1, slip / v2 * (gears.z1 / gears.z2)


def wear_profiles(gears: GearPair, s: np.ndarray, load: float, mean_depth: float,
                  mismatch: float = 0.0, steps: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """Worn profiles (pinion, gear) [m] on the path grid for a pinion mean depth ``mean_depth``.

    Wear is integrated in ``steps`` increments of equal pinion mean depth. In each, the load of
    the mesh cycle is shared by the rig's loaded contact of the *current* worn profiles: a pair
    whose flanks have worn deeper than its partner's carries less load (or none), which is what
    keeps real worn profiles bounded near the pinion root.
    """
    from .flanks import pair_force, static_contact

    pb, L = gears.base_pitch, gears.path_length
    ds = s[1] - s[0]
    r1, r2 = _archard_rates(gears, s)
    h1 = np.zeros_like(s)
    h2 = np.zeros_like(s)
    force = max(abs(load), 0.5) / gears.rb2
    k_max = gears.pair_stiffness_max(load)
    # positions of the mesh cycle: the pair at u and its partners at u - pb, u + pb
    u = s[s <= pb]
    pairs = np.stack([u, u + pb, u + 2 * pb], axis=1)
    inside = pairs <= L
    idx = np.clip(np.rint(pairs / ds).astype(int), 0, s.size - 1)
    half = gears.hertz_half_width(s, force / gears.face_width).max()
    n = max(1, int(round(2 * half / ds)))
    kern = np.ones(n) / n
    for _ in range(max(1, steps) if mean_depth > 0 else 0):
        dev = np.where(inside, (h1 + h2)[idx], np.inf)
        k_rel = np.where(inside, gears.pair_stiffness_shape(pairs), 0.0)
        delta, _ = static_contact(k_rel, dev, k_max, force, mismatch)
        w, _ = pair_force(k_rel * k_max, delta[:, None] - np.where(inside, dev, 0.0), mismatch)
        w = np.where(inside, w, 0.0)
        line = np.zeros_like(s)
        np.add.at(line, idx[inside], w[inside] / gears.face_width)
        line = np.convolve(np.pad(line, n, mode="edge"), kern, mode="same")[n:-n]
        d1, d2 = line * r1, line * r2
        step = (mean_depth / max(1, steps)) / max(d1.mean(), 1e-300)
        h1 += step * d1
        h2 += step * d2
    return h1, h2


def apply_wear(tables: ToothTables, gears: GearPair, seed: int, mean_depth: float,
               load: float, mismatch: float = 0.0) -> tuple[ToothTables, dict]:
    """Tables of the worn gearbox (pinion mean depth ``mean_depth`` [m]) and a summary."""
    if mean_depth < 0.0 or not np.isfinite(mean_depth):
        raise ValueError(f"wear depth must be a finite depth >= 0 in m, got {mean_depth!r}")
    rng = np.random.default_rng([seed, 53])
    dh1, dh2 = wear_profiles(gears, tables.s, load, mean_depth, mismatch)
    f1 = np.clip(1.0 + rng.normal(0.0, 0.08, gears.z1), 0.6, 1.4)
    f2 = np.clip(1.0 + rng.normal(0.0, 0.08, gears.z2), 0.6, 1.4)
    h1 = f1[:, None] * dh1[None, :]
    h2 = f2[:, None] * dh2[None, :]
    thickness = 0.5 * np.pi * gears.module
    soft1 = np.clip(1.0 - 1.5 * h1.mean(axis=1) / thickness, 0.3, 1.0)
    soft2 = np.clip(1.0 - 1.5 * h2.mean(axis=1) / thickness, 0.3, 1.0)
    new = tables.replace(pinion_dev=tables.pinion_dev + h1, gear_dev=tables.gear_dev + h2,
                         pinion_k=tables.pinion_k * soft1[:, None],
                         gear_k=tables.gear_k * soft2[:, None])
    summary = {"kind": "wear", "mean_depth": float(mean_depth),
               "gear_mean_depth": float(h2.mean()),
               "pinion_max_depth": float(h1.max()),
               "backlash_increase": float(h1.mean() + h2.mean())}
    return new, summary
