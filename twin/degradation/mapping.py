"""Damage states -> FMU mesh parameters ``k_pair[1..n]`` and ``profile_deviation[1..n]``.

Physics (details, units and references in README.md):

* Wear -> profile deviation.  Worn material is a deviation of the pinion flank from the
  involute, measured along the flank normal; on an involute the normal at the contact point is
  the line of action, so the wear depth h(xi) [m] is the FMU's ``profile_deviation`` at the same
  roll position, the clearance e in the pair law F = k max(0, delta - e) (Kuang & Lin, 2001;
  Brauer & Andersson, 2003).
* Pitting -> pair stiffness.  Pits remove load-bearing flank area; a local pitting density D
  (pitted area fraction) reduces the effective contact width to (1 - D) of the face width, and
  the pair stiffness, proportional to the loaded width, to k_healthy(xi) (1 - D(xi)) (the
  width-reduction model of Chaari et al., 2008, for spalls).  Scaling the whole pair stiffness
  is an approximation: the tooth body under a pit keeps its width, so the bending, shear and
  fillet-foundation compliances barely change; the stiffness loss is overestimated.

Both fine fields (the state's xi grid) are projected on the FMU's piecewise-linear hat basis
(n_nodes equally spaced nodes) by non-negative least squares on the fine samples, so the FMU
interpolation is the best L2 fit on that grid that keeps a deviation / stiffness >= 0.  The
reported truncation error is the largest pointwise difference between the fine field and the
FMU's interpolation of the node values.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from twin.degradation._nodes import HEALTHY_K_PAIR, hat_matrix, interp_nodes
from twin.degradation.base import PittingState, WearState
from twin.degradation.geometry import GearPair
from twin.errors import ParameterError

__all__ = ["HEALTHY_K_PAIR", "MeshUpdate", "contact_k_pair", "mesh_parameters", "project_on_nodes", "project_wear", "wear_deviation"]

#: Roll positions the worn pair's separation is evaluated at before it is fitted on the nodes.
_SEPARATION_GRID = 201


@dataclass(frozen=True)
class MeshUpdate:
    """FMU parameters for the current damage, and how well the node representation fits it.

    Attributes
    ----------
    parameters : dict
        ``k_pair[1]``..``k_pair[n]`` [N/m] and ``profile_deviation[1]``..``profile_deviation[n]`` [m].
    truncation_error : dict
        ``profile_deviation``: max |h(xi) - interp(nodes)(xi)| over the fine grid [m];
        ``k_pair``: max |k(xi) - interp(nodes)(xi)| / k_healthy(xi) over the fine grid
        (relative to the local healthy stiffness, dimensionless).
    """

    parameters: dict[str, float]
    truncation_error: dict[str, float]


def project_on_nodes(xi, values, n_nodes: int) -> tuple[np.ndarray, float]:
    """Non-negative least-squares fit of hat functions on ``n_nodes`` equally spaced nodes.

    Parameters
    ----------
    xi : (n,) roll positions in [0, 1] of the fine samples.
    values : (n,) field values (>= 0) at xi, any unit.
    n_nodes : number of nodes (the FMU's ``n_profile``).

    Returns
    -------
    nodes : (n_nodes,) node values, same unit as ``values``.
    max_error : float, max |values - interp(nodes)(xi)|, same unit.

    A field that is piecewise linear on the nodes (and >= 0) is reproduced exactly.
    """
    xi = np.asarray(xi, dtype=float)
    values = np.asarray(values, dtype=float)
    basis = hat_matrix(xi, n_nodes)
    if np.linalg.matrix_rank(basis) < n_nodes:
        raise ParameterError(f"the damage grid ({xi.size} points) is too coarse to determine {n_nodes} nodes; "
                             "use a finer grid (several points per node interval)")
    scale = float(np.max(np.abs(values)))
    if scale == 0:
        return np.zeros(n_nodes), 0.0
    from scipy.optimize import nnls          # imported here: scipy.optimize costs seconds to import
    # Unit-scaled problem: nnls's tolerances are absolute.
    coeffs, _ = nnls(basis, values / scale)
    nodes = coeffs * scale
    return nodes, float(np.max(np.abs(basis @ nodes - values)))


def mesh_parameters(geometry: GearPair, *, wear: WearState | None = None, pitting: PittingState | None = None,
                    k_pair_healthy: Sequence[float] = HEALTHY_K_PAIR, n_nodes: int = 11,
                    force: float | None = None) -> MeshUpdate:
    """FMU mesh parameters for the given damage states.

    Parameters
    ----------
    geometry : GearPair
        Must be the geometry the states were computed for.
    wear : WearState, optional
        Wear depth field -> ``profile_deviation`` (zeros when None).
    pitting : PittingState, optional
        Pitting density field -> ``k_pair`` scaled by (1 - D) (``k_pair_healthy`` when None).
    k_pair_healthy : sequence of n_nodes floats
        Undamaged pair stiffness [N/m] at the nodes (e.g. calibrated values).
    n_nodes : int
        Number of FMU nodes (``n_profile``, 11).
    force : float, optional
        Transmitted normal force [N]: the worn flanks are seen through the Hertz contact width of
        that force (:func:`wear_deviation`); the rigid flanks when None.

    Zero damage returns ``k_pair_healthy`` and zero deviation exactly.
    """
    if not isinstance(geometry, GearPair):
        raise ParameterError(f"geometry must be a GearPair, got {geometry!r}")
    if not (isinstance(n_nodes, (int, np.integer)) and n_nodes >= 2):
        raise ParameterError(f"n_nodes must be an integer >= 2, got {n_nodes!r}")
    healthy = np.asarray(k_pair_healthy, dtype=float)
    if healthy.shape != (n_nodes,):
        raise ParameterError(f"k_pair_healthy must have n_nodes={n_nodes} values, got {len(healthy)}: "
                             f"{healthy.tolist()!r}")
    if not np.all(np.isfinite(healthy)) or healthy.min() <= 0:
        raise ParameterError(f"k_pair_healthy must be finite and > 0 N/m, got {healthy.tolist()!r}")
    for name, state, kind in (("wear", wear, WearState), ("pitting", pitting, PittingState)):
        if state is None:
            continue
        if not isinstance(state, kind):
            raise ParameterError(f"{name} must be a {kind.__name__} or None, got {type(state).__name__}")
        if state.geometry != geometry:
            raise ParameterError(f"{name} state was computed for {state.geometry!r}, not for {geometry!r}")

    params: dict[str, float] = {}
    errors: dict[str, float] = {}

    if pitting is None or not np.any(pitting.density > 0):
        k_nodes, k_err = healthy.copy(), 0.0
    else:
        k_local_healthy = interp_nodes(healthy, pitting.xi)
        k_field = k_local_healthy * (1.0 - pitting.density)
        # Fit the stiffness *loss* (>= 0), not the stiffness: the non-negative fit then cannot
        # overshoot above the healthy stiffness next to the density jump at the start of
        # single-tooth contact -- pitting never adds stiffness.
        loss_nodes, _ = project_on_nodes(pitting.xi, k_local_healthy * pitting.density, n_nodes)
        k_nodes = healthy - np.minimum(loss_nodes, healthy)
        k_err = float(np.max(np.abs(interp_nodes(k_nodes, pitting.xi) - k_field) / k_local_healthy))
    if wear is None or not (np.any(wear.depth > 0) or np.any(wear.gear_depth > 0)
                            or np.any(wear.pinion_form > 0) or np.any(wear.gear_form > 0)):
        e_nodes, e_err = np.zeros(n_nodes), 0.0
    else:
        xi, separation = wear_deviation(geometry, wear, force=force)
        e_nodes, e_err = project_on_nodes(xi, separation, n_nodes)

    for i, value in enumerate(k_nodes, start=1):
        params[f"k_pair[{i}]"] = float(value)
    for i, value in enumerate(e_nodes, start=1):
        params[f"profile_deviation[{i}]"] = float(value)
    errors["k_pair"] = k_err
    errors["profile_deviation"] = e_err
    return MeshUpdate(params, errors)


def wear_deviation(geometry: GearPair, wear: WearState, n_grid: int = _SEPARATION_GRID, *,
                   force: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The pair's no-load separation along the path of contact [m], from both worn flanks.

    At roll xi the flanks touch where ``h1 + h2 + x^2 / (2 R)`` is least over the tangent
    distance x from the involute contact point (conjugate action of the worn profiles,
    :meth:`twin.degradation.ltca.LoadedContact.separation`): a narrow groove narrower than the
    mating flank's curvature bridges is not seen, uniform thinning of both flanks is a constant
    (backlash).  With ``force`` [N] (the transmitted normal force) each flank is first taken as
    the loaded contact sees it, its Hertz-weighted mean over the contact half-width b of that
    force (:func:`twin.degradation._hertz.contact_average`): a feature narrower than the contact
    is bridged.  Returns ``(xi, separation)``, (n_grid,) each.
    """
    from twin.degradation.ltca import FlankDamage, contact_for
    xi = np.linspace(0.0, 1.0, n_grid)
    d1, d2 = wear.deviations()
    if force is not None:
        from twin.degradation._hertz import contact_average
        if not (isinstance(force, (int, float, np.floating)) and np.isfinite(force) and force > 0):
            raise ParameterError(f"force must be a finite number > 0 N, got {force!r}")
        b = geometry.hertz_half_width(float(force), wear.xi)
        d1 = contact_average(geometry.flank_position(wear.xi), b) @ d1
        rho2 = geometry.rho2(wear.xi)
        d2 = contact_average(rho2 * rho2 / (2.0 * geometry.base_radius_gear), b) @ d2
    damage = FlankDamage.of(wear.xi, pinion_depth=d1, gear_depth=d2)
    return xi, contact_for(geometry).separation(xi, damage)


def project_wear(wear: WearState, n_nodes: int = 11) -> WearState:
    """The wear state as the FMU sees it: depth replaced by the interpolation of its node fit.

    Use it after every :func:`mesh_parameters` in a wear/co-simulation loop (README.md,
    "Coupling").  The load only responds to the node representation, so detail of the fine
    depth field between nodes gets no feedback: a flank point that has worn more than its node
    interpolation says keeps carrying load and keeps wearing, and the fine field drifts into a
    saw-tooth far from what the FMU simulates.  Projecting back keeps state and FMU identical;
    the least-squares fit preserves the worn volume to ~1e-5 per step.

    Returns a new WearState with the same cycles, grid and geometry; shape (n,) depth [m].
    """
    if not isinstance(wear, WearState):
        raise ParameterError(f"wear must be a WearState, got {type(wear).__name__}")
    if not (isinstance(n_nodes, (int, np.integer)) and n_nodes >= 2):
        raise ParameterError(f"n_nodes must be an integer >= 2, got {n_nodes!r}")
    nodes, _ = project_on_nodes(wear.xi, wear.depth, n_nodes)
    return WearState(wear.cycles, wear.xi, interp_nodes(nodes, wear.xi), wear.geometry)


def contact_k_pair(geometry: GearPair, force: float, n_nodes: int = 11) -> np.ndarray:
    """Single-pair stiffness [N/m] at the ``n_nodes`` equally spaced roll positions as the LTCA
    gives it at the transmitted normal force ``force`` [N]: the secant ``F_j / (approach -
    separation)`` of a healthy pair carrying the force F_j the healthy load sharing gives it there.

    The FMU's pair law ``k (delta - e)`` is linear; the LTCA's contact (two elastic half-planes)
    is not: its compliance grows as the load falls (logarithmically with the contact width), so
    at light load a pair gives way more than a load-independent stiffness (potential energy with
    a linearised Hertz term) says, 30-40 % more on an 18/35 module-3 pair at 200 N.  With the
    secant at the operating force, the FMU's pairs share a load of that size the way the LTCA's
    do, so which pair of worn flanks goes slack is decided by the same compliances.  (n_nodes,).
    """
    from twin.degradation.pitting_map import _N_XI, _healthy
    if not isinstance(geometry, GearPair):
        raise ParameterError(f"geometry must be a GearPair, got {geometry!r}")
    if not (isinstance(force, (int, float, np.floating)) and np.isfinite(force) and force > 0):
        raise ParameterError(f"force must be a finite number > 0 N, got {force!r}")
    if not (isinstance(n_nodes, (int, np.integer)) and n_nodes >= 2):
        raise ParameterError(f"n_nodes must be an integer >= 2, got {n_nodes!r}")
    import math
    # the healthy LTCA is cached on a 2 % grid of the force, as for pitting
    _, compliance = _healthy(geometry, 1.02 ** round(math.log(float(force)) / math.log(1.02)))
    return np.interp(np.linspace(0.0, 1.0, n_nodes), np.linspace(0.0, 1.0, _N_XI), 1.0 / compliance)
