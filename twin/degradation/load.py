"""Load carried by one tooth pair along the path of contact, for one pass of a pinion tooth.

The degradation models need, at each roll position xi, the normal force F(xi) [N] pressing the
pinion flank point in contact against the gear flank.  Two sources:

* :meth:`MeshLoad.from_samples` - the co-simulated FMU outputs ``roll[1..3]`` and
  ``pair_force[1..3]``: every sample of every tracked pair with ``0 <= roll <= 1`` is a
  (position, force) observation; they are binned on a uniform xi grid and averaged.  The average
  runs over all pinion teeth and all passes in the recording (the degradation fields are common
  to all teeth, like ``profile_deviation``).
* :meth:`MeshLoad.static` - quasi-static load sharing: the pairs in contact at the same time sit
  one base pitch apart (``1 / contact_ratio`` in xi) and share the transmitted force
  ``F = T1 / rb1`` as springs in parallel with clearances, exactly the FMU's pair law
  ``F_i = k_i max(0, delta - e_i)`` at equilibrium (no dynamics, no entry/exit ramp).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from twin.degradation._nodes import HEALTHY_K_PAIR, interp_nodes, node_array
from twin.degradation.geometry import GearPair
from twin.errors import ParameterError

# Tolerance when checking that a grid reaches xi = 0 and xi = 1.
_COVER_TOL = 1e-9


@dataclass(frozen=True)
class TransmittedLoad:
    """The normal force the mesh transmits, F = T1 / rb1 [N] (> 0), for models that share it
    among the tooth pairs themselves by a loaded tooth contact analysis."""

    force: float

    def __post_init__(self):
        ok = isinstance(self.force, (int, float, np.floating)) and math.isfinite(float(self.force))
        if not (ok and float(self.force) > 0):
            raise ParameterError(f"transmitted force must be a finite number > 0 N, got {self.force!r}")
        object.__setattr__(self, "force", float(self.force))


@dataclass(frozen=True, eq=False)
class MeshLoad:
    """Pair force along the path of contact.

    Attributes
    ----------
    xi : (n,) float array
        Roll positions, strictly increasing, dimensionless.
    force : (n,) float array
        Normal force carried by the tooth pair in contact at xi [N], >= 0.
    """

    xi: np.ndarray
    force: np.ndarray

    def __post_init__(self):
        xi = np.array(self.xi, dtype=float)
        force = np.array(self.force, dtype=float)
        if xi.ndim != 1 or force.shape != xi.shape or xi.size < 2:
            raise ParameterError(f"MeshLoad needs 1-D xi and force of the same length >= 2, "
                                 f"got shapes {xi.shape} and {force.shape}")
        if not np.all(np.isfinite(xi)) or np.any(np.diff(xi) <= 0):
            raise ParameterError(f"MeshLoad xi must be finite and strictly increasing, got {xi!r}")
        if not np.all(np.isfinite(force)) or force.min() < 0:
            bad = force[~np.isfinite(force) | (force < 0)][0]
            raise ParameterError(f"MeshLoad force must be finite and >= 0 N, got {bad!r}")
        xi.setflags(write=False)
        force.setflags(write=False)
        object.__setattr__(self, "xi", xi)
        object.__setattr__(self, "force", force)

    @property
    def covers_path(self) -> bool:
        """True when the grid spans the whole path of contact [0, 1]."""
        return self.xi[0] <= _COVER_TOL and self.xi[-1] >= 1.0 - _COVER_TOL

    def force_at(self, xi) -> np.ndarray:
        """Pair force [N] at roll positions ``xi`` (any shape), by linear interpolation."""
        return np.interp(np.asarray(xi, dtype=float), self.xi, self.force)

    @classmethod
    def from_samples(cls, roll, pair_force, n_grid: int = 101, *, max_gap: float = 0.05) -> "MeshLoad":
        """Bin co-simulated samples by roll position and average.

        Parameters
        ----------
        roll : (m, p) array
            FMU output ``roll[1..p]`` (p = 3 tracked pairs) at m sample times; values outside
            [0, 1] mean "not in contact" and are dropped.
        pair_force : (m, p) array
            FMU output ``pair_force[1..p]`` [N] at the same times.
        n_grid : int
            Number of grid points xi_j = j / (n_grid - 1); sample xi goes to the nearest one.
        max_gap : float
            Largest stretch of the path of contact (in xi, including the stretches before the
            first and after the last sampled bin) that may hold no sample.  Empty bins inside
            shorter gaps are filled by linear interpolation, at the ends by the nearest value.

        Raises
        ------
        ParameterError
            Shapes differ, values are not finite, a force is negative, n_grid < 2, or the
            recording leaves a gap longer than ``max_gap`` on the path of contact.
        """
        roll = np.asarray(roll, dtype=float)
        pair_force = np.asarray(pair_force, dtype=float)
        if roll.shape != pair_force.shape or roll.ndim not in (1, 2):
            raise ParameterError(f"roll and pair_force must be (m, p) arrays of the same shape, "
                                 f"got {roll.shape} and {pair_force.shape}")
        if not (isinstance(n_grid, (int, np.integer)) and n_grid >= 2):
            raise ParameterError(f"n_grid must be an integer >= 2, got {n_grid!r}")
        if not (math.isfinite(max_gap) and max_gap > 0):
            raise ParameterError(f"max_gap must be > 0, got {max_gap!r}")
        if not (np.all(np.isfinite(roll)) and np.all(np.isfinite(pair_force))):
            raise ParameterError("roll and pair_force must be finite (the co-simulation diverged?)")
        x = roll.ravel()
        f = pair_force.ravel()
        if f.size and f.min() < 0:
            raise ParameterError(f"pair_force must be >= 0 N (elastic force of a pair), got {f.min()!r}")
        inside = (x >= 0.0) & (x <= 1.0)
        x, f = x[inside], f[inside]
        grid = np.linspace(0.0, 1.0, n_grid)
        if x.size == 0:
            raise ParameterError("the recording has no sample on the path of contact (no roll in [0, 1])")
        idx = np.rint(x * (n_grid - 1)).astype(int)
        counts = np.bincount(idx, minlength=n_grid)
        sums = np.bincount(idx, weights=f, minlength=n_grid)
        filled = counts > 0
        covered = grid[filled]
        gaps = np.diff(np.concatenate(([0.0], covered, [1.0])))
        if gaps.max() > max_gap:
            k = int(np.argmax(gaps))
            lo = 0.0 if k == 0 else covered[k - 1]
            hi = 1.0 if k == covered.size else covered[k]
            raise ParameterError(f"the recording never covers xi in ({lo:.3f}, {hi:.3f}) of the path of contact "
                                 f"(gap {gaps.max():.3f} > max_gap {max_gap}); record longer or finer")
        force = np.interp(grid, covered, sums[filled] / counts[filled])
        return cls(grid, force)

    @classmethod
    def static(cls, geometry: GearPair, torque_pinion: float, *, n_grid: int = 101,
               parameters: Mapping[str, float] | None = None) -> "MeshLoad":
        """Quasi-static load sharing for a pinion torque ``torque_pinion`` [N.m].

        The transmitted force F = T1 / rb1 [N] is shared by the pairs in contact (roll positions
        xi + k / contact_ratio inside [0, 1]) as in the FMU at equilibrium:
        sum_i k_i max(0, delta - e_i) = F, solved exactly for the approach delta.  Without
        profile deviation the single-pair zone carries F and a double-pair zone splits it in
        proportion to the pair stiffnesses.

        Parameters
        ----------
        geometry : GearPair
        torque_pinion : float
            Torque on the pinion [N.m], >= 0.  For the rig, the brake torque T2 gives
            T1 = T2 z1 / z2 (20 N.m -> 7.31 N.m).
        n_grid : int
            Number of equally spaced grid points on [0, 1].
        parameters : mapping, optional
            FMU parameters ``k_pair[i]`` [N/m], ``profile_deviation[i]`` [m] and
            ``mesh_stiffness_scale`` (e.g. ``MeshUpdate.parameters``); missing ones take the FMU
            defaults (healthy stiffness, no deviation).  Per-tooth factors are not used: this
            is the load on the average tooth.
        """
        if not (isinstance(torque_pinion, (int, float)) and math.isfinite(torque_pinion) and torque_pinion >= 0):
            raise ParameterError(f"torque_pinion must be a finite torque >= 0 N.m, got {torque_pinion!r}")
        if not (isinstance(n_grid, (int, np.integer)) and n_grid >= 2):
            raise ParameterError(f"n_grid must be an integer >= 2, got {n_grid!r}")
        parameters = {} if parameters is None else parameters
        k_nodes = node_array(parameters, "k_pair")
        k_nodes = np.asarray(HEALTHY_K_PAIR) if k_nodes is None else k_nodes
        if k_nodes.min() < 0:
            raise ParameterError(f"k_pair must be >= 0 N/m, got {k_nodes.min()!r}")
        e_nodes = node_array(parameters, "profile_deviation")
        e_nodes = np.zeros(2) if e_nodes is None else e_nodes
        scale = float(parameters.get("mesh_stiffness_scale", 1.0))
        if not (math.isfinite(scale) and scale > 0):
            raise ParameterError(f"mesh_stiffness_scale must be > 0, got {scale!r}")

        grid = np.linspace(0.0, 1.0, n_grid)
        total = torque_pinion / geometry.base_radius_pinion
        cr = geometry.contact_ratio
        shifts = np.arange(-math.floor(cr), math.floor(cr) + 1) / cr        # column of the pair at xi: shift 0
        pos = grid[:, None] + shifts[None, :]                                # (n, P) positions of all pairs
        active = (pos >= -_COVER_TOL) & (pos <= 1.0 + _COVER_TOL)
        k = np.where(active, scale * interp_nodes(k_nodes, pos), 0.0)
        e = np.where(active, interp_nodes(e_nodes, pos), np.inf)
        delta = _approach(k, e, total, grid)
        own = int(np.flatnonzero(shifts == 0)[0])
        force = k[:, own] * np.maximum(0.0, delta - e[:, own])
        return cls(grid, force)


def _approach(k: np.ndarray, e: np.ndarray, total: float, grid: np.ndarray) -> np.ndarray:
    """Solve sum_i k_i max(0, delta - e_i) = total for delta, row by row.

    k, e : (n, P) pair stiffness [N/m] and deviation [m] (inactive pairs: k = 0, e = inf).
    The left side is piecewise linear and non-decreasing in delta; with the pairs sorted by
    deviation, the first n_active for which the candidate delta lies between the n-th and the
    (n+1)-th deviation is the solution.
    """
    order = np.argsort(e, axis=1)
    ks = np.take_along_axis(k, order, axis=1)
    es = np.take_along_axis(e, order, axis=1)
    es_finite = np.where(np.isfinite(es), es, 0.0)
    cum_k = np.cumsum(ks, axis=1)
    cum_ke = np.cumsum(ks * es_finite, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cand = (total + cum_ke) / cum_k
    nxt = np.concatenate([es[:, 1:], np.full((es.shape[0], 1), np.inf)], axis=1)
    valid = (cum_k > 0) & (cand >= es - 1e-18) & (cand <= nxt + 1e-18)
    if not np.all(valid.any(axis=1)):
        bad = grid[~valid.any(axis=1)][0]
        raise ParameterError(f"no pair stiffness to carry the load at xi={bad:.3f} (k_pair is zero there)")
    first = np.argmax(valid, axis=1)
    return cand[np.arange(k.shape[0]), first]
