"""Wear from tooth to tooth: Archard's law under the mesh's load sharing, along each tooth's flank.

A pinion's teeth do not start alike (pitch deviations, run-out) and do not wear alike (hardness
and roughness scatter: a wear coefficient factor c_j per tooth).  The deviations that remain
decide the shaft-order sidebands of a worn gearbox.  Spreading the mean depth over the teeth by
c_j alone (tooth j worn c_j times the mean; the archive's rule before 2026-11-28) lets the
tooth-to-tooth differences grow in proportion to the depth and ignores what decides how hard each
tooth is pressed: its neighbours.

Under the FMU's pair law (``pair_force = k_pair(xi) max(0, delta - deviation)`` for each pair in
contact at the common approach delta) a tooth that stands proud of its neighbours by more than the
static deflection delta_s = W / k carries the whole mesh force W in the double-contact zones of
its engagement, one that is recessed carries less there.  By Archard the depth a flank point loses
in one engagement is K x contact pressure x sliding distance; the contact band 2b passes the
point at the pinion flank's rolling speed v1 while the flanks slide at v_s, so per engagement

    dh_j(xi) = K c_j  F_j(xi) / L  x  v_s(xi) / v1(xi)  (x a constant)                   (1)

with F_j(xi) the force on tooth j when its contact is at roll position xi along the path and
v_s / v1 the pinion's slide-to-roll ratio (zero at the pitch point, largest at the pinion root).
In the **single-contact zone** F_j = W whatever the tooth's offset: there nothing levels, and a
tooth of c_j > 1 loses (c_j - 1) x the local depth more than the mean tooth, for ever.  In the
**double-contact zones** the share decides: a proud spot carries more and wears faster, a recessed
one less, until the two teeth meeting there share as identical teeth do.  So rigid differences
(pitch errors, run-out) wear away only at the flank ends and stay in the single zone, while
differences of wear coefficient reshape each tooth's flank: deeper in its single zone, a
transmission error from tooth to tooth that grows with the depth.  (Before 2026-11-28 a tooth was
one rigid offset, its rate the mean of (1) over the engagement; that levelled every difference,
because the single zone's share of the volume was met by a shift of the whole tooth.)

:class:`ToothLoadSharing` solves the quasi-static load sharing of one pinion revolution (every
mesh position, all pairs in contact, each with the common worn profile plus its tooth's own field)
and integrates each tooth's field at the ``k_pair`` nodes by (1), minus the mean tooth's, in steps
of the mean depth small against delta_s, keeping the teeth's mean shape the common profile's (the
degradation run's).  On the rig's 19/52 pair at 5 N.m, from 10 um of run-out and 2 um pitch
errors, the teeth stay 14 um apart in the single zone after 60 um of wear; with wear coefficients
of sd 0.1 they move 16 and 24 um apart there after 60 and 240 um (``make demo``, step 5).  Left out:
the gear's (wheel's) tooth-to-tooth wear (52 teeth meet every pinion tooth: a hunting ratio), the
change of the pair stiffness and of the load along the history (the record's are used
throughout), dynamic load, the Hertz band's smoothing (2b is 3-5 % of a node interval here).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.degradation._nodes import interp_nodes, node_xi
from twin.degradation._tooth_kernels import integrate_two_pairs
from twin.errors import ParameterError

#: Integration step, as a fraction of the static deflection W / k, of the depth a node would wear
#: carrying the whole force at the path's largest sliding (the fastest any node can go).  A field
#: change d then changes a node's next step by at most STEP_FRACTION x (k / mean k) x d, so 1 keeps
#: the explicit steps stable (below 2) along the whole path; on the rig's pair (60 um of wear, c_j
#: sd 0.1, 5 and 20 N.m) it stays within 0.6 nm of 0.125.
STEP_FRACTION = 1.0
#: Mesh positions per base pitch in the load-sharing sum of one revolution.  The force jumps where a
#: pair enters or leaves, so the nodes' sums converge slowly: on the rig's pair (240 um at 5 N.m, c_j
#: sd 0.1, teeth 45 um apart) 32, 64, 128 and 256 are 1.5, 0.9, 1.0 and 0.02 um from 512.
SAMPLES_PER_PITCH = 64
#: Largest number of integration steps: 1 mm of wear on an 18/35 pair at 10 N.m takes about 7000
#: (2 s); beyond this the depth is refused rather than integrated with unstable steps.
MAX_STEPS = 200000


def _positive_nodes(name: str, values, n_min: int = 2) -> np.ndarray:
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size < n_min or not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise ParameterError(f"{name} needs >= {n_min} finite values >= 0, got {arr.tolist()!r}")
    return arr


@dataclass(frozen=True)
class ToothLoadSharing:
    """The quasi-static mesh of one record: who carries the force, tooth by tooth.

    Attributes
    ----------
    k_pair : ndarray (n,)
        Single-pair stiffness [N/m] at equally spaced roll positions along the path of contact
        (the FMU's ``k_pair`` times ``mesh_stiffness_scale``), > 0.
    contact_ratio : float
        Transverse contact ratio, 1 <= eps < 3.
    mesh_force : float
        Transmitted normal mesh force W [N] (brake torque / gear base radius), > 0.
    sliding : ndarray (n,)
        Sliding per unit of the pinion flank's rolling, v_s / v1, at the same nodes [-; only its
        shape matters], >= 0: the depth a pass wears per unit force (1).
    profile : ndarray (n,)
        Material missing along the path common to all teeth [m] (the worn ``profile_deviation``),
        or all zeros.
    """

    k_pair: np.ndarray
    contact_ratio: float
    mesh_force: float
    sliding: np.ndarray
    profile: np.ndarray

    def __post_init__(self):
        k = _positive_nodes("k_pair", self.k_pair)
        if np.any(k <= 0):
            raise ParameterError(f"k_pair must be > 0 N/m at every node, got {k.tolist()!r}")
        eps = float(self.contact_ratio)
        if not (math.isfinite(eps) and 1.0 <= eps < 3.0):
            raise ParameterError(f"contact_ratio must lie in [1, 3), got {self.contact_ratio!r}")
        w = float(self.mesh_force)
        if not (math.isfinite(w) and w > 0):
            raise ParameterError(f"mesh_force must be a finite force > 0 N, got {self.mesh_force!r}")
        s = _positive_nodes("sliding", self.sliding)
        p = np.asarray(self.profile, dtype=float).ravel()
        if p.size != k.size or not np.all(np.isfinite(p)):
            raise ParameterError(f"profile needs {k.size} finite node values (as k_pair), got {p.tolist()!r}")
        for name, value in (("k_pair", k), ("sliding", s), ("profile", p)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "contact_ratio", eps)
        object.__setattr__(self, "mesh_force", w)

    @classmethod
    def for_gears(cls, geometry, k_pair, mesh_force: float, profile=None) -> "ToothLoadSharing":
        """From a :class:`~twin.degradation.geometry.GearPair`: its contact ratio and slide-to-roll ratio."""
        k = np.asarray(k_pair, dtype=float).ravel()
        sliding = geometry.slide_to_roll_ratio(node_xi(k.size))
        return cls(k, geometry.contact_ratio, mesh_force, sliding,
                   np.zeros(k.size) if profile is None else np.asarray(profile, dtype=float))

    @property
    def static_deflection(self) -> float:
        """W / k of one pair at its mean stiffness [m]: the width of the elastic band."""
        return self.mesh_force / float(np.mean(self.k_pair))

    def _mesh(self, teeth: int):
        """What does not change as the teeth wear, at the pairs of P mesh positions, each (P, m)
        (m = 2 pairs for a contact ratio below 2, else 3): the tooth index, the pair stiffness (0 out
        of mesh), the common profile there (inf out of mesh), the sliding (1), the lower node of the
        contact point and its hat weight there; and (z * n,) the hat weights each tooth's nodes
        collect over its engagement."""
        phi = np.arange(teeth * SAMPLES_PER_PITCH) / SAMPLES_PER_PITCH + 0.5 / SAMPLES_PER_PITCH
        base = np.floor(phi).astype(int)
        slots = np.arange(2 if self.contact_ratio < 2.0 else 3)
        tooth = (base[:, None] - slots[None, :]) % teeth                 # the tooth that entered last first
        travel = (phi - base)[:, None] + slots[None, :]                  # pitches since each entered
        engaged = travel < self.contact_ratio
        xi = np.clip(travel / self.contact_ratio, 0.0, 1.0)
        n = self.k_pair.size
        lower = np.minimum(np.floor(xi * (n - 1)).astype(int), n - 2)
        weight = 1.0 - (xi * (n - 1) - lower)                            # of the lower node
        cell = (tooth * n + lower).ravel()
        on = engaged.ravel()
        hats = (np.bincount(cell, weights=np.where(on, weight.ravel(), 0.0), minlength=teeth * n)
                + np.bincount(cell + 1, weights=np.where(on, 1.0 - weight.ravel(), 0.0), minlength=teeth * n))
        return (tooth, np.where(engaged, interp_nodes(self.k_pair, xi), 0.0),
                np.where(engaged, interp_nodes(self.profile, xi), np.inf), interp_nodes(self.sliding, xi),
                lower, weight, np.maximum(hats, 1e-300))

    def node_rates(self, field, wear_factors) -> np.ndarray:
        """(z, n) depth each tooth loses per engagement at each node, Eq. (1), relative to the mean
        over teeth and nodes of a pinion with identical teeth (c_j = 1, no field).

        ``field`` (z, n) [m]: each tooth's material loss beyond the common profile at the nodes
        (positive = recessed), or (z,) rigid offsets; ``wear_factors`` (z,) [-]: c_j, > 0.
        """
        f, c = self._field(field), np.asarray(wear_factors, dtype=float).ravel()
        mesh = self._mesh(f.shape[0])
        return self._node_rates(f, c, mesh) / self._reference(mesh).mean()

    def _field(self, field) -> np.ndarray:
        f = np.atleast_1d(np.asarray(field, dtype=float))
        if f.ndim == 1:
            f = np.repeat(f[:, None], self.k_pair.size, axis=1)
        return f

    def _node_rates(self, field: np.ndarray, c: np.ndarray, mesh) -> np.ndarray:
        tooth, k, profile, sliding, lower, weight, hats = mesh
        z, n = field.shape
        own = field[tooth, lower] * weight + field[tooth, lower + 1] * (1.0 - weight)
        share = _share_two if k.shape[1] == 2 else _share
        work = c[tooth] * share(k, own + profile, self.mesh_force) * sliding
        cell = (tooth * n + lower).ravel()
        acc = (np.bincount(cell, weights=(work * weight).ravel(), minlength=z * n)
               + np.bincount(cell + 1, weights=(work * (1.0 - weight)).ravel(), minlength=z * n))
        return (acc / hats).reshape(z, n)                           # a local mean of (1) at each node

    def _reference(self, mesh) -> np.ndarray:
        """(n,) the identical teeth's depth per engagement at the nodes, Eq. (1)."""
        z = int(mesh[0].max()) + 1
        ref = self._node_rates(np.zeros((z, self.k_pair.size)), np.ones(z), mesh).mean(axis=0)
        if float(ref.mean()) <= 0:
            raise ParameterError("no tooth slides under load along this path of contact (sliding is zero)")
        return ref

    def wear(self, offsets, wear_factors, mean_depth: float) -> np.ndarray:
        """(z, n) each tooth's material loss beyond the common profile [m] at the ``k_pair`` nodes
        after ``mean_depth`` [m] of mean wear (the mean over the nodes of the common profile's
        depth), shifted to a least-cut point at zero (a common offset only moves the static
        deflection).

        ``offsets`` (z,) [m]: the teeth before the wear (pitch deviations, run-out), or (z, n)
        fields; ``wear_factors`` (z,) [-]: c_j, > 0, each tooth's wear coefficient over the mean's.
        The teeth's mean shape stays the common profile's: only differences from tooth to tooth
        are integrated.
        """
        e = self._field(offsets).copy()
        c = np.asarray(wear_factors, dtype=float).ravel()
        if (e.ndim != 2 or e.shape != (c.size, self.k_pair.size) or not np.all(np.isfinite(e))
                or not (np.all(np.isfinite(c)) and np.all(c > 0))):
            raise ParameterError(f"offsets and wear_factors need one finite value per tooth (factors > 0), "
                                 f"got {np.asarray(offsets).shape} and {c.size}")
        depth = float(mean_depth)
        if not (math.isfinite(depth) and depth >= 0):
            raise ParameterError(f"mean_depth must be a finite depth >= 0 m, got {mean_depth!r}")
        mesh = self._mesh(c.size)
        ref = self._reference(mesh)
        norm = float(ref.mean())
        # a node's rate can reach c_max x the whole force x its sliding (a proud spot carrying the mesh
        # alone); per step that node moves at most STEP_FRACTION of delta_s, which keeps the explicit
        # steps stable even where the common profile leaves a flank end nearly unloaded (ref small)
        fastest = float(c.max() * self.mesh_force * self.sliding.max())
        steps = math.ceil(depth * fastest / norm / (STEP_FRACTION * self.static_deflection))
        if steps > MAX_STEPS:
            raise ParameterError(f"mean_depth {depth:.3g} m is {steps} stable steps of the static deflection "
                                 f"{self.static_deflection:.3g} m (at most {MAX_STEPS}): too deep for this load")
        if steps == 0:
            return e - e.min()
        tooth, k, profile, sliding, lower, weight, hats = mesh
        if k.shape[1] == 2:                 # the compiled loop (what the else-branch states in NumPy)
            integrate_two_pairs(e, c, ref, norm, tooth, k, profile, sliding, lower, weight, hats,
                                self.mesh_force, steps, depth / steps)
        else:
            for _ in range(steps):
                grow = (self._node_rates(e, c, mesh) - ref) / norm
                e += (depth / steps) * (grow - grow.mean(axis=0))
        if not np.all(np.isfinite(e)):
            raise ParameterError(f"the teeth's wear over {depth:.3g} m did not stay finite (k_pair, profile or "
                                 "mesh_force out of range?)")
        return e - e.min()


def _share_two(k: np.ndarray, dev: np.ndarray, force: float) -> np.ndarray:
    """:func:`_share` for at most two pairs in mesh (contact ratio below 2), in closed form, shape (P, 2)."""
    k0, k1 = k[:, 0], k[:, 1]
    in0, in1 = np.isfinite(dev[:, 0]), np.isfinite(dev[:, 1])
    d0, d1 = np.where(in0, dev[:, 0], 0.0), np.where(in1, dev[:, 1], 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = (force + k0 * d0 + k1 * d1) / (k0 + k1)             # both loaded
    both = in0 & in1 & (delta >= np.maximum(d0, d1))
    first = in0 & ~(in1 & (d1 < d0))                                # the closer pair, when it carries alone
    out = np.empty_like(k)
    out[:, 0] = np.where(both, k0 * (delta - d0), np.where(first, force, 0.0))
    out[:, 1] = np.where(both, k1 * (delta - d1), np.where(first, 0.0, force))
    if not np.all(in0 | in1):
        raise ParameterError("no pair in contact at some mesh position (contact ratio below 1?)")
    return out


def _share(k: np.ndarray, dev: np.ndarray, force: float) -> np.ndarray:
    """Pair forces [N], shape (P, m): at each of P positions the common approach delta with
    sum_i k_i max(0, delta - dev_i) = force; pairs out of mesh have k = 0, dev = inf."""
    order = np.argsort(dev, axis=1)
    ks = np.take_along_axis(k, order, axis=1)
    ds = np.take_along_axis(dev, order, axis=1)
    finite = np.isfinite(ds)
    kd = ks * np.where(finite, ds, 0.0)             # out of mesh: k = 0 (and 0 x inf would be nan)
    ksum, kdsum = np.cumsum(ks, axis=1), np.cumsum(kd, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = (force + kdsum) / ksum                               # the first m pairs loaded
    nxt = np.concatenate([ds[:, 1:], np.full((ds.shape[0], 1), np.inf)], axis=1)
    ok = finite & (ksum > 0) & (delta >= ds) & (delta <= nxt)
    m = np.argmax(ok, axis=1)
    if not np.all(ok[np.arange(ok.shape[0]), m]):
        raise ParameterError("no pair in contact at some mesh position (contact ratio below 1?)")
    d = delta[np.arange(delta.shape[0]), m]
    return k * np.maximum(0.0, d[:, None] - np.where(np.isfinite(dev), dev, d[:, None]))
