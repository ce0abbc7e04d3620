"""Pitting mapped to the FMU's mesh parameters through the loaded tooth contact analysis.

A pit is a hole in the flank deeper than any elastic approach: where a fraction D of the face
width is pitted at a flank point, the contact there is carried by the remaining ``L (1 - D)``.
In the LTCA (:mod:`twin.degradation.ltca`) this divides the contact compliance of the cells at
that point by ``1 - D``; the tooth body (bending, shear, axial, fillet foundation) keeps its
compliance.  So a pitted pair gives way more than a healthy one under the same force by

    dc(xi) = c_LTCA(xi; D) - c_LTCA(xi; 0)          [m/N]

(single-pair approach per newton at the pair force the load sharing gives it there), and the
FMU, whose pair law is linear, gets ``k_pair(xi) = 1 / (1 / k_healthy(xi) + dc(xi))``: the
stiffness that gives the same approach at the operating force.  The lumped rule it replaces,
``k_healthy (1 - D)``, also scaled the body's compliance; the contact carries only a part of
the pair's compliance (about a third here), so the LTCA loses less stiffness at low density and
more where a flank point is nearly all pitted.

**Per-tooth pits.**  The law gives the probability D(xi) that the stressed material at roll xi
has failed; real flanks fail in discrete pits, unequally from tooth to tooth.  Each pinion
flank is divided into pit-sized cells, :data:`PIT_SIZE` along the flank and across the face,
and each cell carries a seeded uniform quantile u; the cell has pitted once the law's failure
probability at its centre reaches u.  A cell's pit, once formed, stays as the density grows, and
the expected pitted fraction is the law's D.  Pits do not fail independently of their
neighbours: growing pits join into craters.  With a cluster length (opt-in,
:data:`PIT_CLUSTER_LENGTH`) the quantiles are a Gaussian field of that correlation length mapped
to uniform marginals (:meth:`ToothScatter.cell_quantiles`; the expected pitted fraction is
unchanged, the pits cluster); by default they are independent.  Teeth also differ in load and strength: tooth j
has a strength factor lambda_j (seeded, lognormal, median 1, log-sd ``scatter``) and, under the
Weibull law of :class:`~twin.degradation.pitting.FatiguePitting` at constant load, its cells
fail with probability ``D_j = 1 - (1 - D)^lambda_j``.

A pit wider than the Hertzian contact (initial macropits are about 0.5 mm across, the contact
2b = 35-75 um wide here) leaves the contact line unsupported over the pit's length: at roll xi
tooth j carries its load on the face width its pits leave, the fraction ``1 - f_j(xi)``, where
f_j is the pitted share of the face weighted by the overlap of each cell with the contact band
[u - b, u + b].  By the uniform-pit law below its compliance is that of the typical tooth plus
``pitted_contact_compliance(f_j) - pitted_contact_compliance(D)``, so under the pair force F(xi)
it gives way by ``e_j(xi) = F (c_j - c_typical)`` more than the tooth ``k_pair`` describes; where
the pits leave no support across the face the contact reaches the pit bottom, and the extra
approach over the healthy tooth is at most the pit depth, the law's crack depth
``z0 = 0.786 b`` (Eq. 13).  The FMU takes the whole (z1, N) field e_j(xi): each tooth's row is
fitted on the ``n_profile`` nodes along the path (least squares on the FMU's hat functions) and
written as ``tooth_pit_field[(j - 1) n_profile + n]`` [m] (tooth-major), which each pair reads for
the pinion tooth it holds.  The node fit along xi is the only approximation;
:attr:`PittingMap.pit_truncation_error` is its relative error.  ``tooth_stiffness_factor`` is
left to the scenario (it is not written).

**Why the whole field.**  Pits sit at different places on different teeth, so the field has no
common shape: its leading singular pair (a shape times a scale per tooth) leaves 45-70 % of its
norm out.  That remainder differs from tooth to tooth and repeats every pinion revolution, so it is
a transmission error at shaft orders locked to the mesh: the sidebands of the mesh harmonics a
pitted pinion shows, with phases fixed by where the pits are, not a random-phase roughness.  The
field on 11 nodes resolves the path of contact (contact ratio ~1.6 of the 19 pitches) up to about
order 5 / (1.6 / 19) = 60 per tooth; the 41-point field's finer detail is the node-fit error.

For a contact whose pitted fraction is uniform across the contact width, the LTCA's cells all
carry their force on ``L (1 - D)``: the contact is that of a modulus ``E* (1 - D)``, wider by
``1 / sqrt(1 - D)``, and its compliance is exactly ``(c_contact + ln(1 - D) / (pi E* L)) / (1 - D)``
(:func:`pitted_contact_compliance`; test_ltca checks it against the LTCA) with c_contact the
contact part of the healthy LTCA compliance.

**The gear's flank.**  The pinion flank point at roll xi meshes with the gear flank point at xi
under the same Hertz contact; the gear point meets it z1/z2 as often, so under the same Weibull
law its density is ``1 - (1 - D)^((z1/z2)^m)``; both flanks' pits enter the LTCA (independent
pits: intact width ``(1 - D1)(1 - D2)``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from twin.degradation._nodes import interp_nodes
from twin.degradation.base import PittingState
from twin.degradation.geometry import GearPair
from twin.degradation.ltca import FlankDamage, contact_for
from twin.errors import ParameterError

#: Roll positions the single-pair compliance is evaluated at.
_N_XI = 41
#: Highest local density the pairs are allowed (a flank point never loses all its contact width).
_MAX_DENSITY = 0.98
#: Surface size of a pit [m], along the flank and across the face: initial (non-progressive)
#: macropits are under 0.020 in (0.5 mm) across and progressive ones grow beyond 0.032 in
#: (R. Errichello, "Morphology of micropitting", and the macropitting classes of ANSI/AGMA
#: 1010-F14, as summarised in Gear Solutions, "Gear wear and failure modes"; ISO 10825-1:2022
#: uses the same progression).  Not fitted to any rig.
PIT_SIZE = 0.5e-3
#: Correlation length of the pit cells' strengths across the flank [m] (the standard deviation of
#: the Gaussian kernel that correlates them): pits that grow join their neighbours into irregular
#: craters, and progressive pits are those beyond 0.032 in (0.8 mm) across (same sources as
#: :data:`PIT_SIZE`), so a cell's neighbours within about a progressive pit's size fail together.
#: Fixed from that morphology before the twin was compared with any rig; not fitted.  An opt-in
#: (``degradation.pit_cluster_length``); the default is independent cells (docs/experiments.md).
PIT_CLUSTER_LENGTH = 0.8e-3
#: Depth of a pit below the flank over its Hertz half-width: the law's z0 / b (Eq. 13), the depth
#: of the shear stress whose cracks break the pit out.
PIT_DEPTH_OVER_B = 0.786


@dataclass(frozen=True)
class ToothScatter:
    """Per-tooth pitting strength factors lambda_j (z1,), median 1, the seed of the pit cells and
    the correlation length of their strengths [m] (0: independent cells; module docstring)."""

    factors: np.ndarray
    seed: int = 0
    cluster_length: float = 0.0

    @classmethod
    def draw(cls, teeth: int, scatter: float, seed: int, cluster_length: float = 0.0) -> "ToothScatter":
        """lambda_j = exp(scatter * n_j), n_j standard normal from ``seed``; scatter 0: all ones."""
        if not (isinstance(scatter, (int, float)) and math.isfinite(scatter) and scatter >= 0):
            raise ParameterError(f"tooth scatter must be a finite number >= 0, got {scatter!r}")
        if not (isinstance(teeth, (int, np.integer)) and teeth >= 1):
            raise ParameterError(f"teeth must be an integer >= 1, got {teeth!r}")
        if not (isinstance(cluster_length, (int, float)) and math.isfinite(cluster_length)
                and 0 <= cluster_length <= 0.1):
            raise ParameterError(f"pit cluster length must be a finite number in [0, 0.1] m, got {cluster_length!r}")
        rng = np.random.default_rng(seed)
        return cls(np.exp(float(scatter) * rng.standard_normal(int(teeth))), int(seed), float(cluster_length))

    def cell_quantiles(self, n_profile: int, n_face: int) -> np.ndarray:
        """Seeded uniform strength quantiles of the pit cells, shape (z1, n_profile, n_face).

        Independent cells for ``cluster_length`` 0; otherwise a Gaussian field of that correlation
        length over each flank (white noise smoothed by a Gaussian kernel of standard deviation
        ``cluster_length`` on a grid padded by 4 kernel widths, so every cell sees the whole kernel),
        scaled to unit variance and mapped through the normal CDF: each cell's quantile stays
        uniform on [0, 1], so the expected pitted fraction is the law's; only neighbours now fail
        together."""
        rng = np.random.default_rng([self.seed, 1])
        shape = (self.factors.size, n_profile, n_face)
        if self.cluster_length == 0.0:
            return rng.random(shape)
        from scipy.ndimage import gaussian_filter
        from scipy.special import ndtr
        sigma = self.cluster_length / PIT_SIZE                      # kernel sd in cells
        pad = int(math.ceil(4.0 * sigma))
        noise = rng.standard_normal((shape[0], n_profile + 2 * pad, n_face + 2 * pad))
        field = gaussian_filter(noise, sigma=(0.0, sigma, sigma), mode="constant", truncate=4.0)
        field = field[:, pad:pad + n_profile, pad:pad + n_face]
        # the variance of a filtered unit white noise is the sum of the squared kernel weights
        delta = np.zeros((1, 2 * pad + 1, 2 * pad + 1))
        delta[0, pad, pad] = 1.0
        weights = gaussian_filter(delta, sigma=(0.0, sigma, sigma), mode="constant", truncate=4.0)
        return ndtr(field / math.sqrt(float(np.sum(weights ** 2))))


def gear_density(geometry: GearPair, density: np.ndarray, weibull_slope: float) -> np.ndarray:
    """Pitted fraction of the gear flank meeting a pinion flank of density D: 1 - (1 - D)^((z1/z2)^m)."""
    d = np.minimum(np.asarray(density, dtype=float), _MAX_DENSITY)
    return 1.0 - (1.0 - d) ** ((geometry.z1 / geometry.z2) ** weibull_slope)


@dataclass(frozen=True)
class PittingMap:
    """LTCA-based FMU parameters for a pitting state.

    Attributes
    ----------
    parameters : dict
        ``k_pair[1..n]`` [N/m] and ``tooth_pit_field[1..z1 n]`` [m] (tooth-major).
    compliance_change : (N,) the LTCA's dc(xi) of the typical tooth [m/N] on ``xi``.
    tooth_compliance_change : (z1, N) dc of each tooth [m/N].
    tooth_deviation : (z1, N) e_j(xi), each tooth's extra approach over the typical tooth [m].
    pitted_share : (z1, N) f_j(xi), the share of the face the contact finds pitted.
    pit_depth : (N,) depth of a pit at xi [m].
    xi : (N,) roll positions.
    truncation_error : max |k(xi) - interp(nodes)(xi)| / k_healthy(xi).
    pit_truncation_error : ||e - interp(tooth_pit_field)|| / ||e||, the node fit along xi (0 if e = 0).
    """

    parameters: dict
    compliance_change: np.ndarray
    tooth_compliance_change: np.ndarray
    tooth_deviation: np.ndarray
    pitted_share: np.ndarray
    pit_depth: np.ndarray
    xi: np.ndarray
    truncation_error: float
    pit_truncation_error: float


def pitting_parameters(geometry: GearPair, pitting: PittingState, force: float, k_pair_healthy,
                       *, scatter: ToothScatter | None = None, weibull_slope: float = 9.0 / 8.0) -> PittingMap:
    """The FMU's ``k_pair`` and per-tooth stiffness factors for ``pitting`` (module docstring).

    Parameters
    ----------
    geometry : GearPair
    pitting : PittingState of the pinion flank (the typical tooth, lambda = 1).
    force : transmitted normal force [N] (> 0), the operating point the linear pair law must match.
    k_pair_healthy : (n,) healthy node stiffnesses [N/m].
    scatter : per-tooth strength factors (None: all teeth alike, factors 1).
    weibull_slope : m of the pitting law (gear flank cycles).
    """
    from twin.degradation.mapping import project_on_nodes

    if not isinstance(pitting, PittingState):
        raise ParameterError(f"pitting must be a PittingState, got {type(pitting).__name__}")
    if pitting.geometry != geometry:
        raise ParameterError(f"pitting state was computed for {pitting.geometry!r}, not for {geometry!r}")
    if not (isinstance(force, (int, float)) and math.isfinite(force) and force > 0):
        raise ParameterError(f"force must be a finite number > 0 N, got {force!r}")
    healthy = np.asarray(k_pair_healthy, dtype=float)
    n_nodes = healthy.size
    if n_nodes < 2 or not np.all(np.isfinite(healthy)) or healthy.min() <= 0:
        raise ParameterError(f"k_pair_healthy must be >= 2 finite values > 0 N/m, got {healthy.tolist()!r}")
    contact = contact_for(geometry)
    xi = np.linspace(0.0, 1.0, _N_XI)
    xi_in = np.clip(xi, 1e-3, 1 - 1e-3)
    # the healthy LTCA is cached on a 2 % grid of the force (the mean force varies a little
    # from update to update)
    pair_force, c_healthy = _healthy(geometry, 1.02 ** round(math.log(force) / math.log(1.02)))
    d1 = np.minimum(pitting.density, _MAX_DENSITY)
    d2 = gear_density(geometry, d1, weibull_slope)
    pitted = FlankDamage.of(pitting.xi, pinion_pitted=d1, gear_pitted=d2)
    if np.any(d1 > 0):
        dc = np.maximum(0.0, _single_pair(contact, xi_in, pair_force, pitted) - c_healthy)
    else:
        dc = np.zeros(xi.size)
    k_h = interp_nodes(healthy, xi)
    k_field = 1.0 / (1.0 / k_h + dc)
    loss_nodes, _ = project_on_nodes(xi, k_h - k_field, n_nodes)
    k_nodes = healthy - np.minimum(loss_nodes, 0.98 * healthy)
    err = float(np.max(np.abs(interp_nodes(k_nodes, xi) - k_field) / k_h))
    params = {f"k_pair[{i}]": float(v) for i, v in enumerate(k_nodes, start=1)}
    lam = np.ones(geometry.z1) if scatter is None else np.asarray(scatter.factors, dtype=float)
    if lam.size != geometry.z1:
        raise ParameterError(f"scatter has {lam.size} tooth factors, the pinion has {geometry.z1} teeth")
    scatter = scatter if scatter is not None else ToothScatter(lam, 0)
    c_contact = c_healthy - contact.bulk_compliance(xi_in)
    d_xi = np.interp(xi, pitting.xi, d1)
    g_xi = gear_density(geometry, d_xi, weibull_slope)
    share = pitted_share(geometry, pitting, scatter, xi_in, pair_force)                 # (z1, N)
    # the tooth's pits, the typical gear flank's (the gear teeth meet every pinion tooth in turn)
    intact_typ = (1.0 - d_xi) * (1.0 - g_xi)
    intact = np.maximum((1.0 - share) * (1.0 - g_xi)[None, :], 1e-9)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        c_tooth = pitted_contact_compliance(geometry, c_contact[None, :], 1.0 - intact)
        c_typ = pitted_contact_compliance(geometry, c_contact, 1.0 - intact_typ)[None, :]
        # where the typical tooth's face is pitted through (its law unbounded) a tooth with support
        # left gives way by its own contact compliance over the healthy contact's
        dc_tooth = np.where(np.isfinite(c_typ), dc[None, :] + (c_tooth - c_typ), c_tooth - c_contact[None, :])
    depth = PIT_DEPTH_OVER_B * geometry.hertz_half_width(pair_force, xi_in)
    # extra approach over the typical tooth; over the healthy one at most the pit depth
    # (a tooth and the typical one both pitted through, inf - inf: the pit depth too)
    # and never less than none: pits only take support away
    extra = np.clip(np.fmin(pair_force[None, :] * dc_tooth, depth[None, :]), 0.0, None)
    # the differences between the teeth: their mean is the law's typical tooth, which k_pair
    # carries (the cells' mean departs from it only by their sampling of D(xi))
    deviation = extra - np.mean(extra, axis=0)[None, :]
    nodes, pit_err = _fit_teeth(deviation, xi, n_nodes)
    params.update({f"tooth_pit_field[{k}]": float(v) for k, v in enumerate(nodes.ravel(), start=1)})
    return PittingMap(params, dc, dc_tooth, deviation, share, depth, xi, err, pit_err)


def pitted_share(geometry: GearPair, pitting: PittingState, scatter: ToothScatter, xi, pair_force) -> np.ndarray:
    """f_j(xi): share of the face width tooth j's pits leave without support under the contact
    band of half-width b(xi) at pair force ``pair_force`` [N] (module docstring), shape (z1, N)."""
    u0, u1 = (float(v) for v in geometry.flank_position(np.array([0.0, 1.0])))
    n_prof = max(1, math.ceil((u1 - u0) / PIT_SIZE))
    n_face = max(1, round(geometry.face_width / PIT_SIZE))
    edges = u0 + PIT_SIZE * np.arange(n_prof + 1)
    centres = np.minimum(0.5 * (edges[:-1] + edges[1:]), u1)
    # the law's density averaged over each cell (5 points), the cell's failure probability
    sub = np.minimum(edges[:-1, None] + PIT_SIZE * (np.arange(5)[None, :] + 0.5) / 5, u1)
    d_cell = np.interp(geometry.xi_at_flank_position(sub), pitting.xi, np.minimum(pitting.density, 1.0)).mean(axis=1)
    lam = np.asarray(scatter.factors, dtype=float)
    d_tooth = 1.0 - (1.0 - d_cell[None, :]) ** lam[:, None]                          # (z1, cells)
    pitted = scatter.cell_quantiles(n_prof, n_face) < d_tooth[:, :, None]
    face_share = pitted.mean(axis=2)                                                    # (z1, cells)
    u = geometry.flank_position(np.asarray(xi, dtype=float))
    b = geometry.hertz_half_width(np.asarray(pair_force, dtype=float), xi)
    lo = np.maximum(u[:, None] - b[:, None], edges[None, :-1])
    hi = np.minimum(u[:, None] + b[:, None], edges[None, 1:])
    overlap = np.maximum(0.0, hi - lo) / (2.0 * b[:, None])                             # (N, cells)
    return face_share @ overlap.T


def _fit_teeth(field: np.ndarray, xi: np.ndarray, n_nodes: int):
    """Node values (z1, n_nodes) [m] whose hat interpolation fits each tooth's row of ``field``
    (z1, N) on ``xi`` in least squares, and the relative error of that fit (0 if the field is 0)."""
    from twin.degradation._nodes import hat_matrix
    norm = float(np.linalg.norm(field))
    if norm == 0.0:
        return np.zeros((field.shape[0], n_nodes)), 0.0
    basis = hat_matrix(xi, n_nodes)                                                    # (N, n_nodes)
    nodes = np.linalg.lstsq(basis, field.T, rcond=None)[0].T
    return nodes, float(np.linalg.norm(field - nodes @ basis.T) / norm)


def pitted_contact_compliance(geometry: GearPair, contact_compliance, pitted):
    """Contact compliance [m/N] of a contact whose face width is pitted over the fraction
    ``pitted`` everywhere under it, from the healthy one: the load is carried on L (1 - D), as by
    a contact of modulus E* (1 - D), so (c + ln(1 - D) / (pi E* L)) / (1 - D); infinite where that
    is not positive (the face pitted through).  Broadcasts."""
    d = np.asarray(pitted, dtype=float)
    bracket = (np.asarray(contact_compliance, dtype=float)
               + np.log1p(-d) / (math.pi * geometry.contact_modulus * geometry.face_width))
    # the line-contact law holds while the contact is narrower than the flank; a face pitted (almost)
    # through leaves the contact no support: unbounded compliance (the caller caps the approach at
    # the pit depth)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(bracket > 0, bracket / (1.0 - d), np.inf)


@lru_cache(maxsize=16)
def _healthy(geometry: GearPair, force: float) -> tuple[np.ndarray, np.ndarray]:
    """Healthy pair forces and single-pair compliances on the xi grid (cached per force, 3 digits)."""
    contact = contact_for(geometry)
    xi = np.clip(np.linspace(0.0, 1.0, _N_XI), 1e-3, 1 - 1e-3)
    pair_force = _pair_force(contact, force, xi)
    return pair_force, _single_pair(contact, xi, pair_force, None)


def _pair_force(contact, force: float, xi: np.ndarray) -> np.ndarray:
    """Force the healthy load sharing gives the pair at roll xi [N], (N,)."""
    cr = contact.geometry.contact_ratio
    out = np.empty(xi.size)
    for i, x in enumerate(xi):
        others = [x + k / cr for k in (-2, -1, 1, 2) if 0.0 <= x + k / cr <= 1.0]
        sol = contact.solve([x, *others], force)
        own = min(sol.pairs, key=lambda p: abs(p.xi - x))
        out[i] = max(own.total, 0.05 * force) if abs(own.xi - x) < 1e-9 else 0.05 * force
    return out


def _single_pair(contact, xi: np.ndarray, pair_force: np.ndarray, damage) -> np.ndarray:
    """Approach per newton of a single pair carrying pair_force at each xi [m/N], (N,)."""
    out = np.empty(xi.size)
    for i, (x, f) in enumerate(zip(xi, pair_force)):
        sol = contact.solve([float(x)], float(f), damage)
        out[i] = (sol.approach - sol.pairs[0].separation) / f
    return out
