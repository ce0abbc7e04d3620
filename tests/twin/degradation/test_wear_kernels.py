"""The compiled wear sweep: deposits against a brute-force integration of their definition."""
from __future__ import annotations

import numpy as np

from twin.degradation._wear_kernels import deposit_matrix


def _coverage(v, centre, half, h, ahead, behind, direction, n=20001):
    """int w(s) 1[|v - centre - s| < half] ds by the midpoint rule: w the phase hat 1 - |s|/h,
    a box of length ahead h (behind h) on the side where the pair leaves (enters) the path."""
    s = np.linspace(-h, h, n + 1)
    s = 0.5 * (s[1:] + s[:-1])
    forward = s * direction
    weight = 1.0 - np.abs(s) / h
    if ahead < 1:
        weight = np.where(forward > 0, (forward < ahead * h).astype(float), weight)
    if behind < 1:
        weight = np.where(forward < 0, (-forward < behind * h).astype(float), weight)
    return np.sum(weight * (np.abs(v - centre - s) < half)) * (2 * h / n)


def test_deposits_are_the_swept_cell_pressure_averaged_over_each_grid_stretch():
    u = np.linspace(0.0, 1e-3, 21) ** 1.2 / 1e-3 ** 0.2          # uneven, like a flank grid
    centre = np.array([3e-4, 5e-4, 9.8e-4, 2e-5])
    half = np.array([8e-6, 8e-6, 1e-5, 6e-6])
    sweep = np.array([3e-5, 3e-5, 4e-5, 2e-5])
    ahead = np.array([5.0, 0.4, 0.3, 5.0])
    behind = np.array([5.0, 5.0, 5.0, 0.2])
    weight = np.array([1.0, 2.0, 0.5, 1.5])
    item = np.array([0, 0, 1, 2])
    for direction in (1.0, -1.0):
        grid = u if direction > 0 else u[::-1]
        got = deposit_matrix(grid, centre, half, sweep, ahead, behind, direction, weight, item, 3, 4)
        mid = 0.5 * (grid[1:] + grid[:-1])
        lo, hi = np.concatenate([grid[:1], mid]), np.concatenate([mid, grid[-1:]])
        ref = np.zeros((grid.size, 3))
        for i in range(grid.size):
            points = lo[i] + (np.arange(4) + 0.5) / 4 * (hi[i] - lo[i])
            for c in range(centre.size):
                ref[i, item[c]] += weight[c] * np.mean([_coverage(v, centre[c], half[c], 2 * sweep[c], ahead[c],
                                                                  behind[c], direction) for v in points])
        np.testing.assert_allclose(got, ref, rtol=0, atol=2e-4 * np.abs(ref).max())
        assert np.count_nonzero(got) > 6
