"""contact_average: the flank as a loaded contact of Hertz half-width b sees it."""
from __future__ import annotations

import numpy as np

from twin.degradation._hertz import contact_average


def test_rows_are_means_and_zero_width_is_the_identity():
    u = np.linspace(0.0, 1e-3, 41) ** 1.5 / 1e-3 ** 0.5            # uneven spacing, like a flank grid
    s = contact_average(u, np.full(u.size, 60e-6))
    np.testing.assert_allclose(s.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(s @ np.full(u.size, 7.0), 7.0, atol=1e-12)      # uniform wear stays uniform
    inner = (u > u[0] + 60e-6) & (u < u[-1] - 60e-6)
    np.testing.assert_allclose((s @ (3 * u + 1))[inner], (3 * u + 1)[inner], rtol=1e-12)   # a slope away from the ends
    np.testing.assert_array_equal(contact_average(u, np.zeros(u.size)), np.eye(u.size))
    # a decreasing grid (the gear flank's arc against the roll) gives the mirrored matrix
    np.testing.assert_allclose(contact_average(u[::-1], np.full(u.size, 60e-6)), s[::-1, ::-1], atol=1e-15)


def test_a_feature_narrower_than_the_contact_is_bridged_a_wide_one_is_not():
    u = np.linspace(0.0, 2e-3, 401)                                  # 5 um spacing
    narrow = np.where(np.abs(u - 1e-3) < 6e-6, 10e-6, 0.0)           # 12 um wide, 10 um deep
    wide = np.where(np.abs(u - 1e-3) < 200e-6, 10e-6, 0.0)           # 400 um wide
    s = contact_average(u, np.full(u.size, 30e-6))                   # b = 30 um
    assert (s @ narrow).max() < 0.4 * narrow.max()
    assert abs((s @ wide)[200] - 10e-6) < 1e-12
    # at the end of the flank the contact lies on the flank: a one-point ridge there is averaged too
    ridge = np.zeros(u.size)
    ridge[-1] = 10e-6
    assert (s @ ridge)[-1] < 0.2 * 10e-6
