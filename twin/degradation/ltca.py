"""Loaded tooth contact analysis (LTCA) of a spur pair with worn or pitted flanks.

Quasi-static, transverse plane, after the influence-coefficient formulation of Conry & Seireg
(1971) as used for spur gears by e.g. Kahraman's load distribution models: at one mesh position
every tooth pair in the path of contact is discretised along the common tangent of its flanks
into cells of width w; the unknowns are the forces q carried by the cells and the rigid approach
delta of the gears (the loaded static transmission error along the line of action).

    g_i + c_b,j F_j + sum_k A_ik q_k = delta   on loaded cells,   >= delta on the others
    q >= 0,   sum q = F (the transmitted normal force),   F_j = sum of q over pair j

* ``g_i``: the no-load separation of the two flanks at cell i of pair j, at tangent distance x
  from the nominal (involute) contact point: ``x^2 / (2 R) + h1(u1 + x) + h2(u2 - x)`` with R
  the equivalent radius and h1, h2 the material missing from the pinion and the gear flank at
  those points (wear depth); u1, u2 are the involute arc lengths of the nominal contact point.
  Only points on both active flanks are candidates (tip-edge contact is not modelled).
* ``c_b,j``: the tooth-body compliance of the pair, bending, shear, axial compression and fillet
  foundation of both teeth (:func:`twin.degradation.stiffness.pair_compliance`).
* ``A_ik``: the contact compliance of two elastic half-planes in plane strain (Johnson, *Contact
  Mechanics*, 1985, eq. 2.25): a uniform pressure on cell k displaces the surface at x_i by
  ``(2 / (pi E* L w)) int_cell ln(d / |x_i - s|) ds`` per newton, with the reference depth d the
  tooth half-thickness at the contact (Weber 1949); a cell whose face width is pitted over a
  fraction D carries its force on ``L (1 - D)`` and its column of A is divided by ``1 - D``.

Solved by an active-set method (cells enter where they would interpenetrate, leave where their
force would turn negative).  Nothing here is random.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from twin.degradation.geometry import GearPair
from twin.degradation._contact_kernels import gap as _gap_kernel
from twin.degradation._contact_kernels import half_plane_kernel as _half_plane_kernel
from twin.degradation._contact_kernels import pair_cells as _pair_cells
from twin.errors import ParameterError

# Cells per Hertz half-width of the healthy contact, cap on cells per pair, active-set iterations.
_CELLS_PER_HALF_WIDTH = 3
_MAX_CELLS = 160
_MAX_ITER = 200
_XI_TABLE = 201


@dataclass(frozen=True)
class FlankDamage:
    """Damage of the two flanks of a pair, on a roll-position grid.

    The pinion flank point at roll position xi is the one in contact (nominally) when the pair is
    at xi; the same for the gear flank.  All arrays (n,).

    Attributes
    ----------
    xi : roll positions, 0 .. 1, increasing.
    pinion_depth, gear_depth : material missing along the flank normal [m] (wear), >= 0.
    pinion_pitted, gear_pitted : pitted fraction of the face width [-], in [0, 1).
    """

    xi: np.ndarray
    pinion_depth: np.ndarray
    gear_depth: np.ndarray
    pinion_pitted: np.ndarray
    gear_pitted: np.ndarray

    @functools.cached_property
    def table(self) -> np.ndarray:
        """(5, n): xi, pinion and gear depth, pinion and gear pitted fraction (for compiled code)."""
        return np.ascontiguousarray(np.stack([self.xi, self.pinion_depth, self.gear_depth, self.pinion_pitted,
                                              self.gear_pitted]), dtype=float)

    @classmethod
    def healthy(cls, n: int = 2) -> "FlankDamage":
        z = np.zeros(n)
        return cls(np.linspace(0.0, 1.0, n), z, z, z, z)

    @classmethod
    def of(cls, xi, *, pinion_depth=None, gear_depth=None, pinion_pitted=None, gear_pitted=None) -> "FlankDamage":
        xi = np.asarray(xi, dtype=float)
        z = np.zeros(xi.shape)
        def arr(v, lo, hi, name):
            a = z if v is None else np.asarray(v, dtype=float)
            if a.shape != xi.shape or not np.all(np.isfinite(a)) or a.min() < lo or a.max() > hi:
                raise ParameterError(f"{name} must be finite values in [{lo}, {hi}] on the xi grid "
                                     f"({xi.size} points), got shape {a.shape}")
            return a
        if xi.ndim != 1 or xi.size < 2 or np.any(np.diff(xi) <= 0):
            raise ParameterError(f"xi must be 1-D, increasing, with >= 2 points, got {xi!r}")
        return cls(xi, arr(pinion_depth, 0.0, math.inf, "pinion_depth"), arr(gear_depth, 0.0, math.inf, "gear_depth"),
                   arr(pinion_pitted, 0.0, 0.999, "pinion_pitted"), arr(gear_pitted, 0.0, 0.999, "gear_pitted"))


@dataclass(frozen=True)
class PairContact:
    """Solution for one tooth pair at one mesh position.

    x : (c,) cell centres along the common tangent from the nominal contact point [m]
        (positive towards the pinion tip).
    force : (c,) force carried by each cell [N].
    width : cell width [m].
    """

    xi: float
    x: np.ndarray
    force: np.ndarray
    width: float
    separation: float          # least no-load separation of the flanks (rigid TE of this pair) [m]

    @property
    def total(self) -> float:
        return float(self.force.sum())


@dataclass(frozen=True)
class MeshPosition:
    """All pairs at one mesh position and the approach delta [m] (loaded static TE)."""

    approach: float
    pairs: tuple[PairContact, ...]


class LoadedContact:
    """Quasi-static LTCA of one spur pair (see the module docstring).

    Parameters
    ----------
    geometry : GearPair
    cells_per_half_width : int
        Resolution of the contact: cells per Hertz half-width of the healthy contact at the
        transmitted force.
    """

    def __init__(self, geometry: GearPair, *, cells_per_half_width: int = _CELLS_PER_HALF_WIDTH):
        from twin.degradation.stiffness import _tooth, pair_compliance
        if not isinstance(geometry, GearPair):
            raise ParameterError(f"geometry must be a GearPair, got {geometry!r}")
        self.geometry = geometry
        self.cells_per_half_width = int(cells_per_half_width)
        xi = np.linspace(0.0, 1.0, _XI_TABLE)
        comp = pair_compliance(geometry, xi)
        self._xi_table = xi
        self._bulk = comp.bulk                              # (T,) m/N
        self._hertz = float(comp.hertz[0])                  # m/N (for sizing windows only)
        # reference depth of the half-plane kernel: the tooth half-thicknesses at the contact
        t1, t2 = _tooth(geometry, "pinion"), _tooth(geometry, "gear")
        r1 = np.sqrt(geometry.base_radius_pinion ** 2 + geometry.rho1(xi) ** 2)
        r2 = np.sqrt(geometry.base_radius_gear ** 2 + geometry.rho2(xi) ** 2)
        h1 = r1 * np.sin(t1.half_angle(np.clip(r1, t1.root_radius, t1.tip_radius)))
        h2 = r2 * np.sin(t2.half_angle(np.clip(r2, t2.root_radius, t2.tip_radius)))
        self._depth = np.sqrt(h1 * h2)
        self._e_star = geometry.contact_modulus
        # scalars of the geometry, read once (the GearPair properties recompute them on each call)
        self._rb1, self._rb2 = geometry.base_radius_pinion, geometry.base_radius_gear
        self._s_a, self._len = geometry.contact_start, geometry.path_of_contact_length
        self._loa = geometry.line_of_action_length
        s = self._s_a + np.array([0.0, 1.0]) * self._len
        self._u1_0, self._u1_1 = (float(v) for v in s ** 2 / (2.0 * self._rb1))
        self._u2 = (self._loa - s) ** 2 / (2.0 * self._rb2)   # gear arc at xi = 0 (its tip) and xi = 1
        self._constants = np.array([self._rb1, self._rb2, self._s_a, self._len, self._loa, self._u1_0, self._u1_1,
                                    self._u2[0], self._u2[1]])

    # ---- geometry of one pair ------------------------------------------------------------
    def bulk_compliance(self, xi) -> np.ndarray:
        """Tooth-body compliance of the pair at roll positions xi [m/N]."""
        return np.interp(xi, self._xi_table, self._bulk)

    def _flank_points(self, xi_c: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Roll coordinates of the pinion and gear flank points at tangent distance x, and the
        mask of points on both active flanks."""
        rho1c = self._s_a + xi_c * self._len
        rho2c = self._loa - rho1c
        u1 = rho1c * rho1c / (2 * self._rb1) + x
        u2 = rho2c * rho2c / (2 * self._rb2) - x
        ok = (u1 >= self._u1_0 - 1e-15) & (u1 <= self._u1_1 + 1e-15) & (u2 <= self._u2[0] + 1e-15) & (
            u2 >= self._u2[1] - 1e-15)
        rho1 = np.sqrt(2 * self._rb1 * np.maximum(u1, 0.0))
        rho2 = np.sqrt(2 * self._rb2 * np.maximum(u2, 0.0))
        xi1 = np.minimum(np.maximum((rho1 - self._s_a) / self._len, 0.0), 1.0)
        xi2 = np.minimum(np.maximum((self._loa - rho2 - self._s_a) / self._len, 0.0), 1.0)
        return xi1, xi2, ok

    def _radius(self, xi_c):
        rho1 = self._s_a + xi_c * self._len
        rho2 = self._loa - rho1
        return rho1 * rho2 / (rho1 + rho2)

    def gap(self, xi_c: float, x: np.ndarray, damage: FlankDamage) -> tuple[np.ndarray, np.ndarray]:
        """No-load separation [m] of the pair at roll ``xi_c`` at tangent offsets x, and the
        pitted fraction of the face width there (both flanks, independent pits)."""
        if np.ndim(xi_c) == 0 and np.ndim(x) == 1:
            # one pair: the compiled loop (the same formula, no temporaries)
            return _gap_kernel(np.asarray(x, dtype=float), float(xi_c), self._constants, damage.table, True)
        r = self._radius(xi_c)
        xi1, xi2, ok = self._flank_points(xi_c, x)
        sep = x * x / (2.0 * r) + np.interp(xi1, damage.xi, damage.pinion_depth) + np.interp(
            xi2, damage.xi, damage.gear_depth)
        pitted = 1.0 - (1.0 - np.interp(xi1, damage.xi, damage.pinion_pitted)) * (
            1.0 - np.interp(xi2, damage.xi, damage.gear_pitted))
        return np.where(ok, sep, np.inf), pitted

    def separation(self, xi, damage: FlankDamage) -> np.ndarray:
        """Least no-load separation of the pair at roll positions xi [m]: the rigid-body
        transmission error of the worn pair relative to conjugate (involute) action."""
        xi = np.atleast_1d(np.asarray(xi, dtype=float))
        out = np.empty(xi.shape)
        for start in range(0, xi.size, 32):
            xc = xi[start:start + 32, None]
            rho1c = self._s_a + xc * self._len
            u1c = rho1c * rho1c / (2 * self._rb1)
            t = np.linspace(0.0, 1.0, 801)[None, :]
            x = (self._u1_0 - u1c) + t * (self._u1_1 - self._u1_0)
            gap, _ = self.gap(xc, x, damage)
            j = np.argmin(gap, axis=1)
            rows = np.arange(xc.shape[0])
            lo = x[rows, np.maximum(j - 1, 0)][:, None]
            hi = x[rows, np.minimum(j + 1, x.shape[1] - 1)][:, None]
            fine = lo + np.linspace(0.0, 1.0, 101)[None, :] * (hi - lo)
            out[start:start + 32] = np.minimum(gap[rows, j], self.gap(xc, fine, damage)[0].min(axis=1))
        return out

    # ---- contact solution ---------------------------------------------------------------
    def _cells(self, xi_c: float, damage: FlankDamage, threshold: float, width: float):
        """Cells of one pair where the separation is within ``threshold`` of its least value.

        A coarse scan of the whole active flank finds the stretch that can touch (allowing for
        the separation's change between scan points); only that stretch is resolved."""
        rho1c = self._s_a + xi_c * self._len
        u1c = rho1c * rho1c / (2 * self._rb1)
        coarse = np.linspace(self._u1_0 - u1c, self._u1_1 - u1c, 301)
        # compiled: the scan of the coarse points, a fine scan at half a cell of the stretch that
        # can touch, and the cells (:func:`twin.degradation._contact_kernels.pair_cells`)
        found, x, w, sep, pitted, gmin = _pair_cells(coarse, float(xi_c), self._constants, damage.table,
                                                     float(threshold), float(width), _MAX_CELLS)
        if not found:
            return None
        return x, w, sep, pitted, gmin

    def _kernel(self, x: np.ndarray, w: float, depth: float, intact: np.ndarray) -> np.ndarray:
        """A[i, k]: contact approach at x_i per newton on cell k [m/N] (two half-planes): equal
        cells, so A depends on i - k only, ``2 / (pi E* L w) int_cell ln(depth / |x_i - s|) ds``
        divided by the intact fraction of cell k (compiled:
        :func:`twin.degradation._contact_kernels.half_plane_kernel`)."""
        scale = 2.0 / (math.pi * self._e_star * self.geometry.face_width * w)
        return _half_plane_kernel(x.size, w, depth, scale, np.ascontiguousarray(intact, dtype=float))

    def solve(self, xi_pairs, force: float, damage: FlankDamage | None = None, *,
              damages: list[FlankDamage] | None = None) -> MeshPosition:
        """Load distribution among the pairs at roll positions ``xi_pairs`` (those in [0, 1])
        carrying the normal force ``force`` [N] together.  ``damages`` gives one damage per pair
        (per-tooth fields); otherwise ``damage`` applies to all."""
        if not (math.isfinite(force) and force > 0):
            raise ParameterError(f"force must be a finite number > 0 N, got {force!r}")
        xi_pairs = [float(v) for v in np.atleast_1d(xi_pairs)]
        if damages is None:
            damages = [damage or FlankDamage.healthy()] * len(xi_pairs)
        g = self.geometry
        # window and resolution from the healthy contact at the whole force
        r_min = min(self._radius(v) for v in xi_pairs)
        b = math.sqrt(4.0 * (force / g.face_width) * r_min / (math.pi * self._e_star))
        width = b / self.cells_per_half_width
        c_max = float(self._bulk.max()) + 12.0 * self._hertz
        threshold = 1.5 * force * c_max
        blocks = []
        for xc, dmg in zip(xi_pairs, damages):
            cells = self._cells(xc, dmg, threshold, width)
            if cells is None:
                continue
            x, w, sep, pitted, gmin = cells
            usable = np.isfinite(sep) & (pitted < 0.999)
            if not usable.any():
                continue
            x, sep, pitted = x[usable], sep[usable], pitted[usable]
            depth = float(np.interp(xc, self._xi_table, self._depth))
            a = self._kernel(x, w, depth, 1.0 - pitted)
            blocks.append((xc, x, w, sep, a, float(self.bulk_compliance(xc)), gmin))
        if not blocks:
            raise ParameterError(f"no tooth pair can carry the load at roll positions {xi_pairs}")
        # keep only pairs that can come into contact
        gmin_all = min(bl[6] for bl in blocks)
        blocks = [bl for bl in blocks if bl[6] <= gmin_all + threshold]
        sizes = [bl[1].size for bl in blocks]
        n = sum(sizes)
        c = np.zeros((n, n))
        sep = np.concatenate([bl[3] for bl in blocks])
        start = 0
        for bl, m in zip(blocks, sizes):
            c[start:start + m, start:start + m] = bl[4] + bl[5]
            start += m
        q, delta = _active_set(c, sep, force)
        out, start = [], 0
        for bl, m in zip(blocks, sizes):
            out.append(PairContact(bl[0], bl[1], q[start:start + m], bl[2], bl[6]))
            start += m
        return MeshPosition(float(delta), tuple(out))

    def pair_compliance(self, xi, force: float, damage: FlankDamage | None = None) -> np.ndarray:
        """Approach per newton [m/N] of a single pair at roll positions xi carrying ``force`` [N]
        alone, measured from its least no-load separation (the loaded single-pair compliance)."""
        xi = np.atleast_1d(np.asarray(xi, dtype=float))
        out = np.empty(xi.shape)
        for i, xc in enumerate(xi):
            sol = self.solve([float(xc)], force, damage)
            out[i] = (sol.approach - sol.pairs[0].separation) / force
        return out

    def mesh_cycle(self, force: float, damage: FlankDamage | None = None, *, n_positions: int = 96,
                   damages_by_slot=None, offset: float = 0.5) -> "MeshCycle":
        """LTCA over one mesh cycle at ``n_positions`` equally spaced phases (phase of the first:
        ``offset / n_positions``, offset in [0, 1)).

        Pair slot k is at roll (phase + k) / contact_ratio.  ``damages_by_slot`` (optional) is
        a list of FlankDamage per slot (e.g. the tooth pairs of one mesh cycle of a pinion with
        per-tooth damage)."""
        g = self.geometry
        cr = g.contact_ratio
        n_slots = int(math.ceil(cr))
        phases = (np.arange(n_positions) + offset % 1.0) / n_positions
        approach = np.empty(n_positions)
        slot_xi = np.full((n_positions, n_slots), np.nan)
        slot_force = np.zeros((n_positions, n_slots))
        slot_sep = np.full((n_positions, n_slots), np.nan)
        positions = []
        for m, f in enumerate(phases):
            slots = [k for k in range(n_slots) if (f + k) / cr <= 1.0]
            xis = [(f + k) / cr for k in slots]
            dmg = None if damages_by_slot is None else [damages_by_slot[k] for k in slots]
            pos = self.solve(xis, force, damage, damages=dmg)
            positions.append(pos)
            approach[m] = pos.approach
            for k, xc in zip(slots, xis):
                slot_xi[m, k] = xc
            for p in pos.pairs:
                k = slots[int(np.argmin([abs(p.xi - v) for v in xis]))]
                slot_force[m, k] = p.total
                slot_sep[m, k] = p.separation
        return MeshCycle(phases, approach, slot_xi, slot_force, slot_sep, tuple(positions), force)


_CONTACTS: dict = {}


def contact_for(geometry: GearPair) -> LoadedContact:
    """The :class:`LoadedContact` of ``geometry``, built once per geometry (a few tenths of a second)."""
    if geometry not in _CONTACTS:
        if len(_CONTACTS) > 16:
            _CONTACTS.clear()
        _CONTACTS[geometry] = LoadedContact(geometry)
    return _CONTACTS[geometry]


@dataclass(frozen=True)
class MeshCycle:
    """LTCA over one mesh cycle.  Arrays (M,) or (M, slots); slot k is at roll (phase + k) / eps."""

    phase: np.ndarray
    approach: np.ndarray          # loaded static TE along the line of action [m]
    slot_xi: np.ndarray           # roll position of each slot (nan: not in the path of contact)
    slot_force: np.ndarray        # force carried by each slot [N]
    slot_separation: np.ndarray   # no-load separation of each slot's flanks [m] (nan: no candidate cell)
    positions: tuple[MeshPosition, ...]
    force: float

    @property
    def unloaded(self) -> np.ndarray:
        """(M, slots) True where a pair is in the path of contact but carries < 0.1 % of the force."""
        inside = np.isfinite(self.slot_xi)
        return inside & (self.slot_force < 1e-3 * self.force)

    def te_peak_to_peak(self) -> float:
        """Peak-to-peak of the loaded static transmission error over the cycle [m]."""
        return float(self.approach.max() - self.approach.min())


def _active_set(c: np.ndarray, sep: np.ndarray, force: float) -> tuple[np.ndarray, float]:
    """min over q >= 0, delta of the contact LCP: (C q + sep - delta)_i >= 0, complementary to q,
    sum q = force.  Returns (q, delta).  Compiled (:func:`twin.degradation._contact_kernels.active_set`);
    the NumPy loop below takes over where that meets a singular system."""
    from twin.degradation._contact_kernels import active_set
    q, delta, status = active_set(np.ascontiguousarray(c), np.ascontiguousarray(sep), float(force), _MAX_ITER)
    if status < 0:
        return _active_set_numpy(c, sep, force)
    if status == 0:
        raise ParameterError("the contact analysis did not converge (active set cycling)")
    return q, float(delta)


def _active_set_numpy(c: np.ndarray, sep: np.ndarray, force: float) -> tuple[np.ndarray, float]:
    """The active-set loop in NumPy, with a least-squares step where the system is singular."""
    n = sep.size
    active = np.zeros(n, dtype=bool)
    active[np.argsort(sep)[:max(1, min(3, n))]] = True
    q = np.zeros(n)
    delta = 0.0
    tol = 1e-12 + 1e-9 * float(np.max(np.abs(sep[np.isfinite(sep)]), initial=0.0))
    for _ in range(_MAX_ITER):
        idx = np.flatnonzero(active)
        m = idx.size
        mat = np.zeros((m + 1, m + 1))
        mat[:m, :m] = c[idx][:, idx]
        mat[:m, m] = -1.0
        mat[m, :m] = 1.0
        rhs = np.concatenate([-sep[idx], [force]])
        try:
            sol = np.linalg.solve(mat, rhs)
        except np.linalg.LinAlgError:
            sol = np.linalg.lstsq(mat, rhs, rcond=None)[0]
        qa, delta = sol[:m], sol[m]
        if np.any(qa < 0):
            # drop the cells that pull; keep at least the most compressed one
            keep = qa >= 0
            if not keep.any():
                keep[np.argmax(qa)] = True
            active[idx[~keep]] = False
            continue
        q[:] = 0.0
        q[idx] = qa
        gap = c @ q + sep - delta
        gap[active] = 0.0
        worst = np.argmin(gap)
        if gap[worst] >= -tol:
            return q, float(delta)
        # admit every cell that interpenetrates by more than half the worst one
        active |= gap < 0.5 * gap[worst]
    raise ParameterError("the contact analysis did not converge (active set cycling)")
