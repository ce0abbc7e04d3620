"""Compiled inner loops of :mod:`twin.degradation.wear` (numba): the pressure deposits of one
mesh cycle on a flank grid, and the sub-stepped wear integration with the pair law.

They compute exactly what the NumPy formulation in ``wear.py``'s docstrings states; only the
order of the floating-point sums differs.
"""
from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def _coverage(t, a, h, ahead, behind, direction):
    """int w(s) 1[|t - s| < a] ds for one cell: the phase hat 1 - |s| / h, or a box of length
    ahead h (behind h) on the side where the pair leaves (enters) the path within the step."""
    lo, hi = t - a, t + a
    if direction > 0:
        f_lo, f_hi = lo, hi
    else:
        f_lo, f_hi = -hi, -lo
    out = 0.0
    # forward side, s in [0, f_end]
    box = ahead < 1.0
    f_end = ahead * h if box else h
    x0, x1 = max(f_lo, 0.0), min(f_hi, f_end)
    if x1 > x0:
        out += (x1 - x0) if box else (x1 - x1 * x1 / (2.0 * h)) - (x0 - x0 * x0 / (2.0 * h))
    # backward side, s' = -s in [0, b_end]
    box = behind < 1.0
    b_end = behind * h if box else h
    y0, y1 = max(-f_hi, 0.0), min(-f_lo, b_end)
    if y1 > y0:
        out += (y1 - y0) if box else (y1 - y1 * y1 / (2.0 * h)) - (y0 - y0 * y0 / (2.0 * h))
    return out


@numba.njit(cache=True)
def deposit_matrix(u, centre, half, sweep, ahead, behind, direction, weight, item, n_items, n_sub):
    """(n, n_items): sum over the cells c of each item of weight_c x the mean over grid point i's
    flank stretch (halfway to its neighbours, ``n_sub`` midpoints) of the cell's coverage.

    u (n,) monotonic flank arc [m]; the cell arrays (C,); ``direction`` +1 or -1, the sense of u
    as the roll grows."""
    n = u.size
    out = np.zeros((n, n_items))
    lo = np.empty(n)
    hi = np.empty(n)
    for i in range(n):
        lo[i] = u[0] if i == 0 else 0.5 * (u[i - 1] + u[i])
        hi[i] = u[n - 1] if i == n - 1 else 0.5 * (u[i] + u[i + 1])
    increasing = u[n - 1] >= u[0]
    for c in range(centre.size):
        a = half[c]
        h = 2.0 * sweep[c]
        reach = a + h                      # coverage is zero beyond |v - centre| >= a + h
        first, last = centre[c] - reach, centre[c] + reach
        for i in range(n):
            a_i, b_i = (lo[i], hi[i]) if increasing else (hi[i], lo[i])
            if b_i < first or a_i > last:
                continue
            acc = 0.0
            for k in range(n_sub):
                v = lo[i] + (k + 0.5) / n_sub * (hi[i] - lo[i])
                acc += _coverage(v - centre[c], a, h, ahead[c], behind[c], direction)
            out[i, item[c]] += weight[c] * acc / n_sub
    return out


@numba.njit(cache=True)
def _forces(e, table, stiffness, total, out):
    """Pair forces per phase: sum_j k_j max(0, delta - e_j) = total (pairs sorted by e).
    Returns False when a phase has no stiffness to carry the load."""
    out[:] = 0.0
    width = table.shape[1]
    ks = np.empty(width)
    es = np.empty(width)
    idx = np.empty(width, dtype=np.int64)
    for m in range(table.shape[0]):
        p = 0
        for s in range(width):
            j = table[m, s]
            if j < 0:
                continue
            # insertion by separation
            q = p
            while q > 0 and es[q - 1] > e[j]:
                es[q] = es[q - 1]
                ks[q] = ks[q - 1]
                idx[q] = idx[q - 1]
                q -= 1
            es[q] = e[j]
            ks[q] = stiffness[j]
            idx[q] = j
            p += 1
        cum_k = 0.0
        cum_ke = 0.0
        delta = math.nan
        for q in range(p):
            cum_k += ks[q]
            cum_ke += ks[q] * es[q]
            if cum_k > 0:
                cand = (total + cum_ke) / cum_k
                nxt = es[q + 1] if q + 1 < p else math.inf
                if cand >= es[q] - 1e-18 and cand <= nxt + 1e-18:
                    delta = cand
                    break
        if math.isnan(delta):
            return False
        for q in range(p):
            out[idx[q]] = ks[q] * max(0.0, delta - es[q])
    return True


@numba.njit(cache=True)
def integrate(h1, h2, d1, d2, inv_ref, e0, press1, press2, table, stiffness, total, approach_scale,
              coefficient, beta, depth_r, fraction, cycles):
    """Sub-stepped wear over ``cycles`` (see ``FlankWear._integrate``).  Returns (dh1, dh2, ok)."""
    n, n_items = d1.shape
    dh1 = np.zeros(n)
    dh2 = np.zeros(n)
    e = np.empty(n_items)
    f = np.empty(n_items)
    r1 = np.empty(n)
    r2 = np.empty(n)
    done = 0.0
    for _ in range(100000):
        if done >= cycles * (1 - 1e-12):
            break
        for j in range(n_items):
            acc = e0[j]
            for i in range(n):
                acc += press1[j, i] * dh1[i] + press2[j, i] * dh2[i]
            e[j] = acc
        if not _forces(e, table, stiffness, total, f):
            return dh1, dh2, False
        for j in range(n_items):
            f[j] *= inv_ref[j]
        for i in range(n):
            s1 = 0.0
            s2 = 0.0
            for j in range(n_items):
                s1 += d1[i, j] * f[j]
                s2 += d2[i, j] * f[j]
            r1[i] = coefficient * s1 * (1.0 + (beta - 1.0) * math.exp(-(h1[i] + dh1[i]) / depth_r))
            r2[i] = coefficient * s2 * (1.0 + (beta - 1.0) * math.exp(-(h2[i] + dh2[i]) / depth_r))
        peak = 0.0
        for j in range(n_items):
            g = 0.0
            for i in range(n):
                g += press1[j, i] * r1[i] + press2[j, i] * r2[i]
            peak = max(peak, g)
        step = cycles - done
        if peak > 0:
            step = min(step, fraction * approach_scale / peak)
        for i in range(n):
            dh1[i] += r1[i] * step
            dh2[i] += r2[i] * step
        done += step
    return dh1, dh2, True
