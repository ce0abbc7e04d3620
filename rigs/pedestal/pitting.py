"""Fatigue pitting of the pinion flanks: a seeded pit field that grows with the pitted fraction.

Each gearbox owns a population of pit nuclei on its 19 pinion flanks, fixed by its identity:

* a nucleus has a tooth (drawn with per-tooth propensities, lognormal sigma 0.7, so some teeth
  pit far more than others), a centre on the flank (profile position normal about the pinion's
  dedendum between the lowest point of single contact and the pitch point, where Hertz pressure
  and negative sliding meet; face-width position uniform), a birth time in [0, 1] and an initial
  radius (lognormal, median 0.3 mm, ellipses 1.6x longer across the face than up the profile);
* after birth a pit grows linearly, ``R = R0 (1 + 2 (tau - t_birth))`` (spalls widen at their
  edges), so every flank cell gets an arrival time: the first tau at which a pit covers it;
* the pitted fraction ``D`` of the active flank area (all teeth, whole path of contact, whole face
  width) selects tau as the D-quantile of the arrival times. Fields of increasing D are nested.

What a pitted contact line does, at each path point of each tooth with a pitted width fraction p:

* the pair stiffness falls with the lost contact length: factor ``1 - p`` (floor 0.05);
* the transmission error grows only where most of the line is gone and the pair has to reach the
  pit bottoms: ``e += depth p ** 3`` with the pit depth (default 25 um, order of the Hertzian
  depth of maximum shear stress at these loads times a few, as measured on S45C spalls).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .flanks import N_PATH, ToothTables
from .geometry import GearPair

N_WIDTH = 64
N_NUCLEI = 5000
PIT_DEPTH = 15e-6


@lru_cache(maxsize=8)
def _arrival_times(seed: int, z1: int, path_length: float, base_pitch: float,
                   pitch_point: float, face_width: float) -> np.ndarray:
    """Arrival time of pitting at each (tooth, path point, width point) cell, shape (z1, S, W)."""
    rng = np.random.default_rng([seed, 31])
    propensity = rng.lognormal(0.0, 0.5, z1)
    tooth = rng.choice(z1, size=N_NUCLEI, p=propensity / propensity.sum())
    lpstc = path_length - base_pitch
    centre_s = rng.normal(0.5 * (lpstc + pitch_point), 0.16 * path_length, N_NUCLEI)
    centre_s = np.clip(centre_s, 0.0, path_length)
    centre_w = rng.uniform(0.0, face_width, N_NUCLEI)
    birth = rng.uniform(0.0, 1.0, N_NUCLEI)
    r0 = rng.lognormal(np.log(0.3e-3), 0.45, N_NUCLEI)
    ds = path_length / (N_PATH - 1)
    dw = face_width / (N_WIDTH - 1)
    s_grid = np.arange(N_PATH) * ds
    w_grid = np.arange(N_WIDTH) * dw
    arrival = np.full((z1, N_PATH, N_WIDTH), np.inf)
    reach = 3.0   # pits grow to at most 3 R0 within tau <= 1
    for i in range(N_NUCLEI):
        rs, rw = reach * r0[i], reach * 1.6 * r0[i]
        a0 = max(0, int((centre_s[i] - rs) / ds))
        a1 = min(N_PATH, int((centre_s[i] + rs) / ds) + 2)
        b0 = max(0, int((centre_w[i] - rw) / dw))
        b1 = min(N_WIDTH, int((centre_w[i] + rw) / dw) + 2)
        ss = (s_grid[a0:a1, None] - centre_s[i]) / r0[i]
        ww = (w_grid[None, b0:b1] - centre_w[i]) / (1.6 * r0[i])
        rho = np.sqrt(ss ** 2 + ww ** 2)
        t = birth[i] + np.maximum(0.0, rho - 1.0) / 2.0
        t = np.where(rho <= reach, t, np.inf)
        blk = arrival[tooth[i], a0:a1, b0:b1]
        np.minimum(blk, t, out=blk)
    return arrival


def pitted_width(gears: GearPair, seed: int, fraction: float) -> np.ndarray:
    """Pitted fraction of the contact line, shape (z1, N_PATH), for a pitted area ``fraction``."""
    if not 0.0 <= fraction < 1.0:
        raise ValueError(f"pitting fraction must be in [0, 1), got {fraction!r}")
    arrival = _arrival_times(int(seed), gears.z1, gears.path_length, gears.base_pitch,
                             gears.pitch_point, gears.face_width)
    if fraction == 0.0:
        return np.zeros(arrival.shape[:2])
    finite = arrival[np.isfinite(arrival)]
    if finite.size < fraction * arrival.size:
        tau = np.inf
        pitted = np.isfinite(arrival)
    else:
        tau = np.quantile(arrival.ravel(), fraction)
        pitted = arrival <= tau
    return pitted.mean(axis=2)


def apply_pitting(tables: ToothTables, gears: GearPair, seed: int, fraction: float,
                  depth: float = PIT_DEPTH) -> tuple[ToothTables, dict]:
    """Tables of the pitted gearbox and a summary for the truth file."""
    p = pitted_width(gears, seed, fraction)
    k = tables.pinion_k * np.maximum(1.0 - p, 0.05)
    dev = tables.pinion_dev + depth * p ** 3
    per_tooth = p.mean(axis=1)
    summary = {"kind": "pitting", "pitted_fraction": float(fraction),
               "pit_depth": depth, "per_tooth_fraction": [round(float(v), 5) for v in per_tooth]}
    return tables.replace(pinion_k=k, pinion_dev=dev), summary
