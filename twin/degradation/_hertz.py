"""The flank as a loaded line contact sees it: averages over the Hertzian contact width.

A contact of half-width b cannot follow a flank feature narrower than 2b: to first order the
approach of a loaded contact changes by the pressure-weighted mean of a small change of the gap
over the contact (Betti's reciprocal theorem with the Hertz pressure as the reference load), and
wear, which removes material where the pressure is, levels a feature narrower than the contact
within the elastic approach (a fraction of a um) while the flank wears by many um.  Both the
wear increment and the deviation the mesh sees are therefore taken as Hertz-weighted means over
the contact width b = sqrt(4 w R / (pi E*)) of the current load (geometry and material only; no
tuned length).
"""
from __future__ import annotations

import numpy as np

_N_QUAD = 9


def contact_average(u: np.ndarray, half_width: np.ndarray, n_quad: int = _N_QUAD) -> np.ndarray:
    """Matrix S (n, n): ``S @ f`` is the mean of the flank field f (on the points u [m], flank arc
    length, monotonic, (n,)) under a Hertz (semi-elliptical) pressure of half-width
    ``half_width`` [m] (n,) centred at each point, f taken piecewise linear between the points.

    A contact cannot reach beyond the ends of the flank: near an end the window is moved inward
    so that it lies on the flank.  Rows sum to 1; ``half_width`` 0 gives the identity."""
    u = np.asarray(u, dtype=float)
    b = np.broadcast_to(np.asarray(half_width, dtype=float), u.shape)
    order = 1.0 if u[-1] >= u[0] else -1.0
    us = u * order                                            # increasing copy
    lo, hi = us[0], us[-1]
    k = np.arange(1, n_quad + 1)
    node = np.cos(k * np.pi / (n_quad + 1))                   # Gauss-Chebyshev (2nd kind): weight sqrt(1 - s^2)
    weight = np.sin(k * np.pi / (n_quad + 1)) ** 2
    weight /= weight.sum()
    half = np.minimum(b, 0.5 * (hi - lo))
    centre = np.clip(us, lo + half, hi - half)
    points = np.clip(centre[:, None] + half[:, None] * node[None, :], lo, hi)      # (n, q)
    j = np.clip(np.searchsorted(us, points, side="right") - 1, 0, u.size - 2)
    t = (points - us[j]) / (us[j + 1] - us[j])
    s = np.zeros((u.size, u.size))
    rows = np.repeat(np.arange(u.size), n_quad).reshape(points.shape)
    np.add.at(s, (rows, j), weight[None, :] * (1.0 - t))
    np.add.at(s, (rows, j + 1), weight[None, :] * t)
    return s
