"""Wear from tooth to tooth: Archard's law under the mesh's load sharing levels the pinion's teeth.

A pinion's teeth do not start alike (pitch deviations, run-out) and do not wear alike (hardness
and roughness scatter: a wear coefficient factor c_j per tooth).  The deviations that remain
decide the shaft-order sidebands of a worn gearbox.  Spreading the mean depth over the teeth by
c_j alone (tooth j worn c_j times the mean; the archive's rule before 2026-11-28) lets the
tooth-to-tooth differences grow in proportion to the depth, to tens of um at 200 um of wear,
far beyond the mesh's elastic deflection, and ignores what decides how hard each tooth is
pressed: its neighbours.

Under the FMU's pair law (``pair_force = k_pair(xi) max(0, delta - deviation)`` for each pair in
contact at the common approach delta) a tooth that stands proud of its neighbours by more than the
static deflection delta_s = W / k carries the whole mesh force W in both double-contact zones of
its engagement, one that is recessed carries it only in its single-contact zone.  By Archard the
volume a tooth loses per engagement is K x (force x sliding distance), i.e. proportional to

    R_j = c_j  integral over its engagement of  F_j(xi) v_s(xi) dxi                    (1)

with v_s the sliding speed (zero at the pitch point) and xi the roll position along the path of
contact.  So a proud tooth wears faster than the mean, a recessed one slower, and the differences
shrink: at contact ratio eps a deviation far outside the elastic band closes at up to (eps - 1)
per unit of mean depth, and inside it relaxes over a depth of the order of delta_s (0.2-1 um
here).  Once levelled, the teeth stand where every tooth wears at the mean rate: a tooth of
higher c_j a little recessed, c_j R_j equal for all j, deviations a fraction of delta_s.
Running-in thereby removes the pitch errors and run-out of the pinion (the conformity of worn
gears; e.g. Flodin & Andersson, Wear 207, 1997, who compute the same feedback on a single
profile).

:class:`ToothLoadSharing` solves the quasi-static load sharing of one pinion revolution (every
mesh position, all pairs in contact, each with the common worn profile and its tooth's offset)
and integrates the per-tooth mean depths of (1) over the mean depth in steps of delta_s / 2.
Once every tooth wears at the mean rate (within :data:`EQUAL_RATES`) further depth moves the
teeth together, which changes no difference, and the integration stops.  A deviation smooth over
the revolution (run-out) levels slowest, as only neighbouring teeth share load: on the rig's 19/52
pair from 8 um of run-out and 2 um pitch errors, the teeth are level to 0.13 um sd after about
60 um of wear at 5 N.m, to 0.5 um after about 150 um at 20 N.m.  Left out: the gear's (wheel's) tooth-to-tooth wear, the change of the pair stiffness and
of the load along the history (the record's are used throughout), dynamic load.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.degradation._nodes import interp_nodes, node_xi
from twin.errors import ParameterError

#: Integration step of the mean depth as a fraction of the static deflection W / k.  The explicit
#: steps are stable up to about 1 (unstable at 2); 0.5 stays within 12 nm of 0.25 on the rig's
#: pair at 5 and 20 N.m (offsets of 60-1400 nm), at half the cost.
STEP_FRACTION = 0.5
#: Spread of the teeth's relative wear rates below which they are taken to wear alike: the
#: remaining spread decays over a few um of depth, so it moves the teeth by some nm more.
EQUAL_RATES = 1e-3
#: Mesh positions per base pitch in the load-sharing sum of one revolution.
SAMPLES_PER_PITCH = 32
#: Largest number of integration steps (a guard; the defaults need a few hundred).
MAX_STEPS = 20000


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
        Sliding speed along the path at the same nodes [any unit; only its shape matters], >= 0.
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
        """From a :class:`~twin.degradation.geometry.GearPair`: its contact ratio and sliding speed."""
        k = np.asarray(k_pair, dtype=float).ravel()
        sliding = geometry.sliding_speed(node_xi(k.size), 1.0)
        return cls(k, geometry.contact_ratio, mesh_force, sliding,
                   np.zeros(k.size) if profile is None else np.asarray(profile, dtype=float))

    @property
    def static_deflection(self) -> float:
        """W / k of one pair at its mean stiffness [m]: the width of the elastic band."""
        return self.mesh_force / float(np.mean(self.k_pair))

    def _mesh(self, teeth: int):
        """What does not change as the teeth wear, at the pairs of P mesh positions, each (P, 3):
        the tooth index, the pair stiffness (0 out of mesh), the common profile there (inf out of
        mesh) and the sliding speed."""
        phi = np.arange(teeth * SAMPLES_PER_PITCH) / SAMPLES_PER_PITCH + 0.5 / SAMPLES_PER_PITCH
        base = np.floor(phi).astype(int)
        tooth = (base[:, None] - np.arange(3)[None, :]) % teeth        # the tooth that entered last first
        travel = (phi - base)[:, None] + np.arange(3)[None, :]           # pitches since each entered
        engaged = travel < self.contact_ratio
        xi = np.clip(travel / self.contact_ratio, 0.0, 1.0)
        return (tooth, np.where(engaged, interp_nodes(self.k_pair, xi), 0.0),
                np.where(engaged, interp_nodes(self.profile, xi), np.inf), interp_nodes(self.sliding, xi))

    def wear_rates(self, offsets, wear_factors) -> np.ndarray:
        """(z,) relative mean wear rate of each tooth, Eq. (1) normalised to mean 1.

        ``offsets`` (z,) [m]: each tooth's extra material loss (positive = recessed);
        ``wear_factors`` (z,) [-]: c_j, > 0.
        """
        e = np.asarray(offsets, dtype=float)
        return self._rates(e, np.asarray(wear_factors, dtype=float), self._mesh(e.size))

    def _rates(self, e: np.ndarray, c: np.ndarray, mesh) -> np.ndarray:
        tooth, k, profile, sliding = mesh
        force = _share(k, e[tooth] + profile, self.mesh_force)
        rate = c * np.bincount(tooth.ravel(), weights=(force * sliding).ravel(), minlength=e.size)
        mean = float(rate.mean())
        if mean <= 0:
            raise ParameterError("no tooth slides under load along this path of contact (sliding is zero)")
        return rate / mean

    def level(self, offsets, wear_factors, mean_depth: float) -> np.ndarray:
        """(z,) tooth offsets [m] after ``mean_depth`` [m] of mean wear, shifted to a least-cut
        tooth at zero (a common offset only moves the static deflection).

        ``offsets`` (z,) [m]: the teeth before the wear (pitch deviations, run-out);
        ``wear_factors`` (z,) [-]: c_j, > 0, each tooth's wear coefficient over the mean's.
        """
        e = np.asarray(offsets, dtype=float).ravel().copy()
        c = np.asarray(wear_factors, dtype=float).ravel()
        if c.shape != e.shape or not np.all(np.isfinite(e)) or not (np.all(np.isfinite(c)) and np.all(c > 0)):
            raise ParameterError(f"offsets and wear_factors need one finite value per tooth (factors > 0), "
                                 f"got {e.size} and {c.size}")
        depth = float(mean_depth)
        if not (math.isfinite(depth) and depth >= 0):
            raise ParameterError(f"mean_depth must be a finite depth >= 0 m, got {mean_depth!r}")
        steps = min(MAX_STEPS, math.ceil(depth / (STEP_FRACTION * self.static_deflection)))
        mesh = self._mesh(e.size)
        for _ in range(steps):
            rate = self._rates(e, c, mesh)
            if float(np.ptp(rate)) < EQUAL_RATES:
                break                       # level: the rest of the depth moves every tooth alike
            e += (depth / steps) * rate
        return e - e.min()


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
