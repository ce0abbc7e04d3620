"""Unilateral tooth-pair contact law and the quasi-static loaded mesh.

A tooth pair at path position u with approach d = delta - e (delta: mesh deflection along
the line of action, e: separation from the flank deviations of both teeth) carries

    d = c F + (q / w) F (A + ln w - ln F)        for d > 0, F = 0 otherwise,

c being the body compliance of both teeth (Weber bending, shear, compression and foundation,
raised where the load concentrates on the unpitted part of the face), the second term
Weber's Hertzian approach over the loaded width w b. F(d) is found by Newton's method.
"""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def pair_force(d, c, qw, aw, guess):
    """Force [N] and tangent stiffness [N/m] of one pair at approach d [m]."""
    if d <= 0.0:
        return 0.0, 0.0
    f = guess
    if f <= 0.0:
        f = d / (c + qw * 10.0)
    for _ in range(30):
        lf = np.log(f)
        g = c * f + qw * f * (aw - lf) - d
        dg = c + qw * (aw - lf - 1.0)
        if dg <= 1e-30:
            dg = 1e-30
        fn = f - g / dg
        if fn <= 0.0:
            fn = 0.1 * f
        if abs(fn - f) <= 1e-9 * f:
            f = fn
            break
        f = fn
    dg = c + qw * (aw - np.log(f) - 1.0)
    return f, 1.0 / dg


@numba.njit(cache=True)
def static_mesh(load, e, c, qw, aw, valid):
    """Quasi-static mesh: for each position i find delta with sum_n F_n = load.

    e, c, qw, aw, valid: (n_pos, n_pair). Returns delta (n_pos,), forces (n_pos, n_pair)
    and the tangent mesh stiffness (n_pos,).
    """
    n_pos, n_pair = e.shape
    delta = np.zeros(n_pos)
    forces = np.zeros((n_pos, n_pair))
    stiff = np.zeros(n_pos)
    for i in range(n_pos):
        lo = 1e9
        for n in range(n_pair):
            if valid[i, n] and e[i, n] < lo:
                lo = e[i, n]
        if lo == 1e9:
            delta[i] = np.nan
            continue
        hi = lo + 1e-6
        while True:
            tot = 0.0
            for n in range(n_pair):
                if valid[i, n]:
                    f, k = pair_force(hi - e[i, n], c[i, n], qw[i, n], aw[i, n], 0.0)
                    tot += f
            if tot >= load:
                break
            hi = lo + 2.0 * (hi - lo)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            tot = 0.0
            for n in range(n_pair):
                if valid[i, n]:
                    f, k = pair_force(mid - e[i, n], c[i, n], qw[i, n], aw[i, n], 0.0)
                    tot += f
            if tot >= load:
                hi = mid
            else:
                lo = mid
            if hi - lo < 1e-14:
                break
        delta[i] = hi
        ks = 0.0
        for n in range(n_pair):
            if valid[i, n]:
                f, k = pair_force(hi - e[i, n], c[i, n], qw[i, n], aw[i, n], 0.0)
                forces[i, n] = f
                ks += k
        stiff[i] = ks
    return delta, forces, stiff


def interp_rows(table, idx, u, du):
    """Linear interpolation of rows `idx` of `table` (n_rows, n_u) at path positions u."""
    x = np.clip(u / du, 0.0, table.shape[1] - 1.000001)
    i0 = x.astype(int)
    t = x - i0
    return table[idx, i0] * (1 - t) + table[idx, i0 + 1] * t


def cycle_positions(geo, n: int = 256):
    """Positions of the (at most two) pairs over one mesh cycle: u (n, 2), valid (n, 2)."""
    s = np.linspace(0.0, geo.base_pitch, n, endpoint=False)
    u = np.stack([s, s + geo.base_pitch], axis=1)
    valid = (u >= 0.0) & (u <= geo.path_length)
    return u, valid
