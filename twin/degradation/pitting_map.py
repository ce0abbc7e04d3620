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

**Per-tooth damage.**  Teeth do not pit alike: tooth j has a strength factor lambda_j (seeded,
lognormal, median 1, log-sd ``scatter``) and, under the Weibull law of
:class:`~twin.degradation.pitting.FatiguePitting` at constant load, its density is
``D_j = 1 - (1 - D)^lambda_j``.  For a contact whose pitted fraction is uniform across the
contact width the LTCA compliance change is exactly ``c_contact (D / (1 - D))`` with c_contact the
For a contact whose pitted fraction is uniform across the contact width, the LTCA's cells all
carry their force on ``L (1 - D)``: the contact is that of a modulus ``E* (1 - D)``, wider by
``1 / sqrt(1 - D)``, and its compliance is exactly ``(c_contact + ln(1 - D) / (pi E* L)) / (1 - D)``
(:func:`pitted_contact_compliance`; test_ltca checks it against the LTCA) with c_contact the
contact part of the healthy LTCA compliance.  So each tooth's compliance along the path follows
from the LTCA of the healthy tooth at once.  The FMU scales the common
``k_pair`` by one ``tooth_stiffness_factor[j]`` per pinion tooth, chosen to keep the tooth's mean
compliance along the path; the pits remove no material the mating flank touches, so
``tooth_deviation_offset`` stays zero.

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


@dataclass(frozen=True)
class ToothScatter:
    """Per-tooth pitting strength factors lambda_j (z1,), median 1."""

    factors: np.ndarray

    @classmethod
    def draw(cls, teeth: int, scatter: float, seed: int) -> "ToothScatter":
        """lambda_j = exp(scatter * n_j), n_j standard normal from ``seed``; scatter 0: all ones."""
        if not (isinstance(scatter, (int, float)) and math.isfinite(scatter) and scatter >= 0):
            raise ParameterError(f"tooth scatter must be a finite number >= 0, got {scatter!r}")
        if not (isinstance(teeth, (int, np.integer)) and teeth >= 1):
            raise ParameterError(f"teeth must be an integer >= 1, got {teeth!r}")
        rng = np.random.default_rng(seed)
        return cls(np.exp(float(scatter) * rng.standard_normal(int(teeth))))


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
        ``k_pair[1..n]`` [N/m] and ``tooth_stiffness_factor[1..z1]`` [-].
    compliance_change : (N,) the LTCA's dc(xi) of the typical tooth [m/N] on ``xi``.
    tooth_compliance_change : (z1, N) dc of each tooth [m/N].
    xi : (N,) roll positions.
    truncation_error : max |k(xi) - interp(nodes)(xi)| / k_healthy(xi).
    """

    parameters: dict
    compliance_change: np.ndarray
    tooth_compliance_change: np.ndarray
    xi: np.ndarray
    truncation_error: float


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
    # per tooth: contact compliance scaled by D_j / (1 - D_j) minus the typical tooth's
    c_contact = c_healthy - contact.bulk_compliance(xi_in)
    lam = np.ones(geometry.z1) if scatter is None else np.asarray(scatter.factors, dtype=float)
    if lam.size != geometry.z1:
        raise ParameterError(f"scatter has {lam.size} tooth factors, the pinion has {geometry.z1} teeth")
    d_xi = np.interp(xi, pitting.xi, d1)
    intact_typ = (1.0 - d_xi) * (1.0 - gear_density(geometry, d_xi, weibull_slope))
    d_tooth = 1.0 - (1.0 - d_xi[None, :]) ** lam[:, None]
    d_tooth = np.minimum(d_tooth, _MAX_DENSITY)
    intact = (1.0 - d_tooth) * (1.0 - gear_density(geometry, d_tooth, weibull_slope))
    # the typical tooth's change from its full LTCA, plus the difference the tooth's own density
    # makes by the uniform-pit law
    dc_tooth = dc[None, :] + (pitted_contact_compliance(geometry, c_contact[None, :], 1.0 - intact)
                              - pitted_contact_compliance(geometry, c_contact, 1.0 - intact_typ)[None, :])
    c_common = 1.0 / k_h + dc                                              # the typical tooth
    c_tooth = 1.0 / k_h[None, :] + dc_tooth
    factors = np.mean(c_common) / np.mean(c_tooth, axis=1)
    params.update({f"tooth_stiffness_factor[{j}]": float(f) for j, f in enumerate(factors, start=1)})
    return PittingMap(params, dc, dc_tooth, xi, err)


def pitted_contact_compliance(geometry: GearPair, contact_compliance, pitted):
    """Contact compliance [m/N] of a contact whose face width is pitted over the fraction
    ``pitted`` everywhere under it, from the healthy one: the load is carried on L (1 - D), as by
    a contact of modulus E* (1 - D), so (c + ln(1 - D) / (pi E* L)) / (1 - D).  Broadcasts."""
    d = np.asarray(pitted, dtype=float)
    return (np.asarray(contact_compliance, dtype=float)
            + np.log1p(-d) / (math.pi * geometry.contact_modulus * geometry.face_width)) / (1.0 - d)


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
