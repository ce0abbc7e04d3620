"""Final-pick rules (twin/calibration/selection.py) on hand-made fronts with known answers."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration import knee_point, least_crowded, neighbour_counts


def test_least_crowded_picks_the_isolated_member():
    F = np.array([[0.00, 1.00], [0.01, 0.99], [0.02, 0.98], [0.03, 0.97], [1.00, 0.00]])
    assert least_crowded(F) == 4
    np.testing.assert_array_equal(neighbour_counts(F), [4, 4, 4, 4, 1])


def test_least_crowded_is_scale_invariant():
    F = np.array([[0.00, 1.00], [0.01, 0.99], [0.02, 0.98], [0.5, 0.5], [1.00, 0.00], [0.99, 0.01]])
    assert least_crowded(F) == 3
    assert least_crowded(F * np.array([1e-3, 1e4])) == 3


def test_least_crowded_tie_break_by_nearest_neighbour_distance():
    F = np.array([[0.0, 1.0], [0.2, 0.8], [1.0, 0.0]])
    # With a small radius every member is alone (count 1); member 2 is farthest from the others.
    assert least_crowded(F, radius=0.01) == 2
    # With a radius covering everything, counts tie again; the same rule applies.
    assert least_crowded(F, radius=10.0) == 2


def test_least_crowded_single_and_duplicate_points():
    assert least_crowded(np.array([[3.0, 4.0]])) == 0
    assert least_crowded(np.array([[0.0, 1.0], [0.0, 1.0], [1.0, 0.0]])) == 2
    assert least_crowded(np.array([[2.0, 2.0], [2.0, 2.0], [2.0, 2.0]])) == 0
    assert least_crowded(np.array([3.0, 1.0, 2.0, 2.0])) in (0, 1)   # 1-d: single objective
    with pytest.raises(ValueError):
        least_crowded(np.array([[0.0, 1.0], [1.0, 0.0]]), radius=0.0)
    with pytest.raises(ValueError):
        least_crowded(np.array([[0.0, np.nan]]))


def test_knee_point_two_objectives():
    F = np.array([[0.0, 1.0], [0.1, 0.4], [0.5, 0.2], [1.0, 0.0]])
    assert knee_point(F) == 1
    assert knee_point(F * np.array([1e3, 1e-2]) + 5.0) == 1   # invariant to scale and offset
    assert knee_point(F[::-1]) == 2                          # follows the member, not the position


def test_knee_point_three_objectives():
    F = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.4, 0.4, 0.1], [0.2, 0.2, 0.2]])
    assert knee_point(F) == 4


def test_knee_point_degenerate_sets():
    assert knee_point(np.array([[1.0, 2.0]])) == 0
    # Duplicated knee: the lower index wins.
    F = np.array([[0.0, 1.0], [0.1, 0.4], [0.1, 0.4], [1.0, 0.0]])
    assert knee_point(F) == 1
    # All identical and a constant objective: defined, deterministic.
    assert knee_point(np.ones((4, 2))) == 0
    assert knee_point(np.array([[0.0, 5.0], [1.0, 5.0], [2.0, 5.0]])) == 0
    # Single objective: the minimiser.
    assert knee_point(np.array([[3.0], [1.0], [2.0]])) == 1
    # Concave front: nothing bulges towards the ideal point; an extreme (distance 0) is returned.
    x = np.linspace(0.0, 1.0, 5)
    assert knee_point(np.column_stack([x, 1.0 - x ** 2])) in (0, 4)
