"""Compiled inner loops of :mod:`twin.degradation.ltca` (numba): the no-load gap of a pair and
the active-set solution of the contact problem.  They compute what the ``LoadedContact``
docstrings state; only the order of floating-point operations may differ."""
from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def _locate(x, xp, j):
    """The interval j of increasing xp with xp[j] <= x < xp[j + 1] (as ``searchsorted(xp, x,
    'right') - 1``, clipped to 0 .. n - 2), walking from the previous answer ``j``: the points of
    a scan are ordered, so this is a step or two instead of a bisection."""
    n = xp.size
    if j < 0 or j > n - 2:
        j = 0
    while j > 0 and xp[j] > x:
        j -= 1
    while j < n - 2 and xp[j + 1] <= x:
        j += 1
    return j


@numba.njit(cache=True)
def _interp(x, xp, fp, j):
    """np.interp at x with the interval j of :func:`_locate` (clamped beyond the ends)."""
    n = xp.size
    if x <= xp[0]:
        return fp[0]
    if x >= xp[n - 1]:
        return fp[n - 1]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    return slope * (x - xp[j]) + fp[j]


@numba.njit(cache=True)
def gap(x, xi_c, constants, table, with_pitted):
    """No-load separation [m] at tangent offsets x (inf off the active flanks) and pitted
    fraction of the face width, (n,) each: ``x^2 / 2R + h1(u1c + x) + h2(u2c - x)``.

    constants: rb1, rb2, s_a, path length, line-of-action length, pinion arc at xi 0 and 1,
    gear arc at xi 0 and 1 (``LoadedContact._constants``); table: ``FlankDamage.table``.  Without
    ``with_pitted`` the pitted fraction is not computed (left undefined)."""
    rb1, rb2, s_a, length, loa, u1_0, u1_1, u2_tip, u2_root = constants
    xi, h1, h2, p1, p2 = table[0], table[1], table[2], table[3], table[4]
    rho1c = s_a + xi_c * length
    rho2c = loa - rho1c
    r = rho1c * rho2c / (rho1c + rho2c)
    n = x.size
    sep = np.empty(n)
    pitted = np.empty(n if with_pitted else 0)
    base1 = rho1c * rho1c / (2 * rb1)
    base2 = rho2c * rho2c / (2 * rb2)
    j1 = 0
    j2 = 0
    for i in range(n):
        u1 = base1 + x[i]
        u2 = base2 - x[i]
        ok = (u1 >= u1_0 - 1e-15) and (u1 <= u1_1 + 1e-15) and (u2 <= u2_tip + 1e-15) and (u2 >= u2_root - 1e-15)
        rho1 = math.sqrt(2 * rb1 * max(u1, 0.0))
        rho2 = math.sqrt(2 * rb2 * max(u2, 0.0))
        xi1 = min(max((rho1 - s_a) / length, 0.0), 1.0)
        xi2 = min(max((loa - rho2 - s_a) / length, 0.0), 1.0)
        j1 = _locate(xi1, xi, j1)
        j2 = _locate(xi2, xi, j2)
        value = x[i] * x[i] / (2.0 * r) + _interp(xi1, xi, h1, j1) + _interp(xi2, xi, h2, j2)
        sep[i] = value if ok else math.inf
        if with_pitted:
            pitted[i] = 1.0 - (1.0 - _interp(xi1, xi, p1, j1)) * (1.0 - _interp(xi2, xi, p2, j2))
    return sep, pitted


@numba.njit(cache=True)
def _solve(a, b):
    """Gaussian elimination with partial pivoting of a small dense system (a, b overwritten).
    Returns (x, regular)."""
    n = b.size
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(a[i, j]))
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(a[i, k]) > abs(a[p, k]):
                p = i
        if abs(a[p, k]) <= 1e-14 * scale:
            return b, False
        if p != k:
            for j in range(n):
                a[k, j], a[p, j] = a[p, j], a[k, j]
            b[k], b[p] = b[p], b[k]
        for i in range(k + 1, n):
            f = a[i, k] / a[k, k]
            if f != 0.0:
                for j in range(k, n):
                    a[i, j] -= f * a[k, j]
                b[i] -= f * b[k]
    x = np.empty(n)
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= a[i, j] * x[j]
        x[i] = acc / a[i, i]
    return x, True


@numba.njit(cache=True)
def active_set(c, sep, force, max_iter):
    """The contact LCP of ``ltca._active_set``: (C q + sep - delta)_i >= 0 complementary to
    q >= 0, sum q = force.  Returns (q, delta, converged)."""
    n = sep.size
    active = np.zeros(n, dtype=np.bool_)
    for _ in range(max(1, min(3, n))):          # the (up to) three least separations start active
        best = -1
        for i in range(n):
            if not active[i] and (best < 0 or sep[i] < sep[best]):
                best = i
        active[best] = True
    q = np.zeros(n)
    delta = 0.0
    largest = 0.0
    for i in range(n):
        if math.isfinite(sep[i]):
            largest = max(largest, abs(sep[i]))
    tol = 1e-12 + 1e-9 * largest
    gap = np.empty(n)
    idx = np.empty(n, dtype=np.int64)
    for _ in range(max_iter):
        m = 0
        for i in range(n):
            if active[i]:
                idx[m] = i
                m += 1
        mat = np.zeros((m + 1, m + 1))
        rhs = np.empty(m + 1)
        for a in range(m):
            for b in range(m):
                mat[a, b] = c[idx[a], idx[b]]
            mat[a, m] = -1.0
            mat[m, a] = 1.0
            rhs[a] = -sep[idx[a]]
        rhs[m] = force
        sol, regular = _solve(mat, rhs)
        if not regular:
            return q, delta, -1
        delta = sol[m]
        negative = False
        for a in range(m):
            if sol[a] < 0:
                negative = True
        if negative:
            # drop the cells that pull; keep at least the most compressed one
            best = 0
            for a in range(m):
                if sol[a] > sol[best]:
                    best = a
            kept = 0
            for a in range(m):
                if sol[a] < 0:
                    active[idx[a]] = False
                else:
                    kept += 1
            if kept == 0:
                active[idx[best]] = True
            continue
        q[:] = 0.0
        for a in range(m):
            q[idx[a]] = sol[a]
        worst = 0
        for i in range(n):
            acc = 0.0
            for k in range(m):
                acc += c[i, idx[k]] * sol[k]
            gap[i] = 0.0 if active[i] else acc + sep[i] - delta
            if gap[i] < gap[worst]:
                worst = i
        if gap[worst] >= -tol:
            return q, delta, 1
        limit = 0.5 * gap[worst]
        for i in range(n):
            if gap[i] < limit:
                active[i] = True
    return q, delta, 0


@numba.njit(cache=True)
def _prim(t):
    """Antiderivative of ln|t|: t ln|t| - t (0 at t = 0)."""
    at = abs(t)
    return t * math.log(at) - t if at > 0 else 0.0


@numba.njit(cache=True)
def half_plane_kernel(n, w, depth, scale, intact):
    """A[i, k] = scale int_cell_k ln(depth / |x_i - s|) ds / intact_k for n equal cells of width w
    (``LoadedContact._kernel``)."""
    row = np.empty(2 * n - 1)
    for m in range(2 * n - 1):
        d = w * (m - (n - 1))
        row[m] = w * math.log(depth) - (_prim(d + w / 2) - _prim(d - w / 2))
    out = np.empty((n, n))
    for i in range(n):
        for k in range(n):
            out[i, k] = scale * row[i - k + n - 1] / intact[k]
    return out


@numba.njit(cache=True)
def _arange(start, stop, step):
    """np.arange(start, stop, step) for floats, element for element as NumPy fills it."""
    n = max(int(math.ceil((stop - start) / step)), 0)
    out = np.empty(n)
    delta = (start + step) - start
    for i in range(n):
        out[i] = start if i == 0 else (start + step if i == 1 else start + i * delta)
    return out


@numba.njit(cache=True)
def pair_cells(coarse, xi_c, constants, table, threshold, width, max_cells):
    """``LoadedContact._cells`` after its coarse scan points ``coarse``: the cells of one pair
    where the gap is within ``threshold`` of its least value.  Returns (found, x, w, sep,
    pitted, gmin)."""
    empty = np.empty(0)
    gap_c = gap(coarse, xi_c, constants, table, False)[0]
    n = coarse.size
    least = math.inf
    for i in range(n):
        if math.isfinite(gap_c[i]):
            least = min(least, gap_c[i])
    if not math.isfinite(least):
        return False, empty, 0.0, empty, empty, 0.0
    margin = 0.0
    for i in range(n - 1):
        if math.isfinite(gap_c[i]) and math.isfinite(gap_c[i + 1]):
            margin = max(margin, abs(gap_c[i + 1] - gap_c[i]))
    lo = math.inf
    hi = -math.inf
    for i in range(n):
        if gap_c[i] <= least + threshold + margin:
            lo = min(lo, coarse[i])
            hi = max(hi, coarse[i])
    step = coarse[1] - coarse[0]
    lo, hi = lo - step, hi + step
    fine = _arange(lo, hi + width / 2, width / 2.0)
    gap_f = gap(fine, xi_c, constants, table, False)[0]
    gmin = math.inf
    for i in range(fine.size):
        gmin = min(gmin, gap_f[i])
    if not math.isfinite(gmin):
        return False, empty, 0.0, empty, empty, 0.0
    lo = math.inf
    hi = -math.inf
    for i in range(fine.size):
        if gap_f[i] <= gmin + threshold:
            lo = min(lo, fine[i])
            hi = max(hi, fine[i])
    lo, hi = lo - width, hi + width
    count = int(math.ceil((hi - lo) / width))
    w = width if count <= max_cells else (hi - lo) / max_cells
    # cells on a lattice anchored at the nominal contact point, so that the discretisation is
    # the same at every mesh position (a shifting grid leaves a ripple in the wear)
    k0 = math.floor(lo / w)
    count = min(max(int(math.ceil(hi / w)) - k0, 3), max_cells)
    x = np.empty(count)
    for i in range(count):
        x[i] = w * ((k0 + i) + 0.5)
    sep, pitted = gap(x, xi_c, constants, table, True)
    return True, x, w, sep, pitted, gmin
