"""Compiled integration loop of :meth:`twin.degradation.tooth_wear.ToothLoadSharing.wear` (numba).

It computes exactly what ``ToothLoadSharing._node_rates`` and ``_share_two`` state in NumPy (at
most two pairs in mesh: a contact ratio below 2); only the order of the floating-point sums differs.
"""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def integrate_two_pairs(field, c, ref, norm, tooth, k, profile, sliding, lower, weight, hats, force, steps, dd):
    """Advance ``field`` (z, n) in place by ``steps`` explicit steps of ``dd`` [m] of mean depth.

    Per step: each pair's force under the common approach (both pairs loaded, or the closer alone),
    Archard's depth per pass c_j F v_s / v1 collected on the nodes' hats, the identical teeth's
    ``ref`` (n,) subtracted, divided by ``norm``, and the mean over teeth removed at each node."""
    z, n = field.shape
    p_count = tooth.shape[0]
    acc = np.empty(z * n)
    grow = np.empty((z, n))
    for _ in range(steps):
        acc[:] = 0.0
        for p in range(p_count):
            t0, t1 = tooth[p, 0], tooth[p, 1]
            l0, l1 = lower[p, 0], lower[p, 1]
            w0, w1 = weight[p, 0], weight[p, 1]
            d0 = field[t0, l0] * w0 + field[t0, l0 + 1] * (1.0 - w0) + profile[p, 0]
            d1 = field[t1, l1] * w1 + field[t1, l1 + 1] * (1.0 - w1) + profile[p, 1]
            f0 = 0.0
            f1 = 0.0
            in0, in1 = np.isfinite(d0), np.isfinite(d1)
            if in0 and in1:
                delta = (force + k[p, 0] * d0 + k[p, 1] * d1) / (k[p, 0] + k[p, 1])
                if delta >= max(d0, d1):
                    f0 = k[p, 0] * (delta - d0)
                    f1 = k[p, 1] * (delta - d1)
                elif d1 < d0:
                    f1 = force
                else:
                    f0 = force
            elif in0:
                f0 = force
            else:
                f1 = force
            if f0 != 0.0:
                work = c[t0] * f0 * sliding[p, 0]
                acc[t0 * n + l0] += work * w0
                acc[t0 * n + l0 + 1] += work * (1.0 - w0)
            if f1 != 0.0:
                work = c[t1] * f1 * sliding[p, 1]
                acc[t1 * n + l1] += work * w1
                acc[t1 * n + l1 + 1] += work * (1.0 - w1)
        for node in range(n):
            mean = 0.0
            for t in range(z):
                g = (acc[t * n + node] / hats[t * n + node] - ref[node]) / norm
                grow[t, node] = g
                mean += g
            mean /= z
            for t in range(z):
                field[t, node] += dd * (grow[t, node] - mean)
    return field
