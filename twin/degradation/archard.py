"""Abrasive wear of the pinion flank: Archard's law with Hertzian pressure from adjacent contacts.

Feng et al., Eq. (10):  h(theta, t) = integral K_wear P(theta, t) v(t) dt.

For one pass of the tooth through the mesh, write the contact centre's position on the pinion
flank as the involute arc length u_c (see :meth:`GearPair.flank_position`).  The contact moves
over the pinion flank at the rolling speed v1 = omega1 rho1, so dt = du_c / v1, and a flank
point at u_i collects, per pass (= per pinion revolution),

    dh_i = K  integral  p_c(u_i - u_c) v_s(u_c) / v1(u_c) du_c                      [m]

with the Hertzian semi-elliptical pressure of the contact centred at u_c,
p_c(x) = Pmax(u_c) sqrt(1 - (x / b(u_c))^2) for |x| < b(u_c), else 0.

* ``adjacent=True`` (the improved model of Feng et al. [45]): the integral runs over every
  contact position whose Hertzian zone covers u_i, each with its own load, half-width, peak
  pressure and slide-to-roll ratio.  It is evaluated on contact cells of width <= b/4 uniform
  in u, with b, Pmax, v_s/v1 constant per cell and the pressure integrated exactly across the
  cell: integral sqrt(1 - t^2) dt = (t sqrt(1 - t^2) + arcsin t) / 2.  Sharp changes of load
  (entry into and exit from the single-pair zone) are thereby spread over the contact width,
  which is what smooths the worn profile.
* ``adjacent=False`` (classic point-wise Archard, e.g. Flodin & Andersson, Wear 207, 1997): the
  point sees only the contact centred on it, with the properties frozen there:
  dh_i = K p_mean s_i, p_mean = w / (2 b) = pi Pmax / 4 (mean pressure across the strip) and
  s_i = 2 b v_s / v1 the sliding distance while the strip of width 2b passes.  This equals
  K w v_s / v1: both variants remove the same volume for a smooth load.

Per-cycle wear is speed-independent (it depends on v_s / v1 only); ``omega1`` acts through the
load.  Only the pinion flank is worn (the pinion wears much faster than the gear on this rig,
Feng et al. section 3.1); wear changes the load only through the co-simulation, which the
caller re-samples between jumps.
"""
from __future__ import annotations

import math

import numpy as np

from twin.degradation.base import DegradationModel, WearState
from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad
from twin.errors import ParameterError

#: Default dimensional wear coefficient K [m^2/N] (= Pa^-1).  Chosen so that the dry test of
#: Feng et al. (10 Hz, 5 N.m brake torque -> 1.83 N.m on the pinion, no lubricant) removes 60 um
#: mean depth per degradation stage (the paper's 4 stages are ~60 um apart) in 3.3e5 pinion
#: revolutions (9.2 h at 10 Hz, ~1.5 days for the 4 stages: a "relatively short" test) under the
#: healthy static load.  With H ~ 2 GPa (S45C, ~200 HB) the dimensionless Archard coefficient is
#: k = K H ~ 4e-4, inside the range measured for unlubricated mild steel on mild steel
#: (Archard & Hirst, Proc. R. Soc. A 236, 1956: 1e-4 .. 7e-3).  See README.md.
DEFAULT_WEAR_COEFFICIENT = 2.0e-13

# Contact cells per Hertzian half-width, and the bounds on the number of cells.
_CELLS_PER_HALF_WIDTH = 4
_MAX_CELLS = 20000
# Budget of matrix entries per block of flank points (memory bound of the vectorised sum).
_BLOCK_ENTRIES = 2_000_000


def _semi_ellipse_integral(t: np.ndarray) -> np.ndarray:
    """Antiderivative of sqrt(1 - t^2) on [-1, 1] (t clipped there)."""
    t = np.clip(t, -1.0, 1.0)
    return 0.5 * (t * np.sqrt(1.0 - t * t) + np.arcsin(t))


class ArchardWear(DegradationModel):
    """Archard wear law, Feng et al. Eq. (10), optionally with adjacent contact points.

    Parameters
    ----------
    wear_coefficient : float
        Dimensional wear coefficient K [m^2/N] (wear depth per unit pressure and sliding distance).
    adjacent : bool
        True: pressure from every contact whose Hertzian zone covers the point (the improved
        model); False: classic point-wise Archard.
    """

    state_type = WearState

    def __init__(self, wear_coefficient: float = DEFAULT_WEAR_COEFFICIENT, adjacent: bool = True):
        if not (isinstance(wear_coefficient, (int, float)) and math.isfinite(wear_coefficient)
                and wear_coefficient > 0):
            raise ParameterError(f"wear_coefficient must be a finite number > 0 m^2/N, got {wear_coefficient!r}")
        if not isinstance(adjacent, bool):
            raise ParameterError(f"adjacent must be True or False, got {adjacent!r}")
        self.wear_coefficient = float(wear_coefficient)
        self.adjacent = adjacent

    def __repr__(self) -> str:
        return f"ArchardWear(wear_coefficient={self.wear_coefficient!r}, adjacent={self.adjacent!r})"

    def depth_per_cycle(self, geometry: GearPair, xi, load: MeshLoad) -> np.ndarray:
        """Wear depth removed per pinion revolution [m] at flank points ``xi`` (n,) under ``load``."""
        xi = np.asarray(xi, dtype=float)
        if self.adjacent:
            return self.wear_coefficient * self._pressure_sliding_adjacent(geometry, xi, load)
        return self.wear_coefficient * self._pressure_sliding_pointwise(geometry, xi, load)

    def _advance(self, state: WearState, load: MeshLoad, cycles: float, omega1: float) -> WearState:
        # Cycle jumping: the load is frozen over the jump, so the increment is linear in cycles.
        rate = self.depth_per_cycle(state.geometry, state.xi, load)
        return WearState(state.cycles + cycles, state.xi, state.depth + rate * cycles, state.geometry)

    @staticmethod
    def _pressure_sliding_pointwise(geometry: GearPair, xi: np.ndarray, load: MeshLoad) -> np.ndarray:
        """p_mean * s per pass [Pa.m = N/m] with the contact centred on each point; shape (n,)."""
        force = load.force_at(xi)
        b = geometry.hertz_half_width(force, xi)
        w = force / geometry.face_width
        p_mean = np.divide(w, 2.0 * b, out=np.zeros_like(w), where=b > 0)
        sliding_distance = 2.0 * b * geometry.slide_to_roll_ratio(xi)
        return p_mean * sliding_distance

    @staticmethod
    def _pressure_sliding_adjacent(geometry: GearPair, xi: np.ndarray, load: MeshLoad) -> np.ndarray:
        """integral p_c(u_i - u_c) v_s / v1 du_c [N/m] over all contact positions; shape (n,)."""
        u_start, u_end = (float(v) for v in geometry.flank_position(np.array([0.0, 1.0])))
        u_points = geometry.flank_position(xi)

        # Cell width from the narrowest loaded contact (contacts carrying < 0.1 % of the peak
        # force, e.g. in the FMU's entry/exit ramps, do not set the resolution).
        u_probe = np.linspace(u_start, u_end, 2001)
        xi_probe = geometry.xi_at_flank_position(u_probe)
        f_probe = load.force_at(xi_probe)
        if f_probe.max() <= 0:
            return np.zeros_like(xi)
        loaded = f_probe > 1e-3 * f_probe.max()
        b_min = geometry.hertz_half_width(f_probe[loaded], xi_probe[loaded]).min()
        n_cells = math.ceil((u_end - u_start) * _CELLS_PER_HALF_WIDTH / b_min)
        n_cells = int(min(max(n_cells, 4 * xi.size), _MAX_CELLS))

        edges = np.linspace(u_start, u_end, n_cells + 1)
        centres = 0.5 * (edges[:-1] + edges[1:])
        xi_c = geometry.xi_at_flank_position(centres)
        force_c = load.force_at(xi_c)
        b_c = geometry.hertz_half_width(force_c, xi_c)
        weight = geometry.hertz_max_pressure(force_c, xi_c) * b_c * geometry.slide_to_roll_ratio(xi_c)
        b_safe = np.where(b_c > 0, b_c, 1.0)                          # weight is 0 where b is 0

        out = np.empty(u_points.size)
        block = max(1, _BLOCK_ENTRIES // n_cells)
        for start in range(0, u_points.size, block):
            u = u_points[start:start + block, None]
            # Fraction of the unit semi-ellipse of cell c lying over point u:
            # integral over the cell of sqrt(1 - ((u - u_c)/b)^2) du_c / b.
            covered = (_semi_ellipse_integral((edges[None, 1:] - u) / b_safe)
                       - _semi_ellipse_integral((edges[None, :-1] - u) / b_safe))
            out[start:start + block] = covered @ weight
        return out
