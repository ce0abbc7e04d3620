"""Picking one calibrated parameter set from a Pareto archive.

The MOGOA of the paper (Feng et al., section 2.2.1) ends with an archive of non-dominated parameter
sets; Eq. 9 then takes the member with the largest ``Pro_i = 1 / hbar_i``, ``hbar_i`` being the
number of archive neighbours of member ``i``: the least crowded member.  That is
:func:`least_crowded`.  :func:`knee_point` is the common alternative (best trade-off).

Both work on objective values only, an ``(n, m)`` array of minimised objectives, and are robust to a
single point and to duplicated rows.  Distances are measured after min-max normalisation of every
objective over the given set, so objectives of very different scales (a waveform RMS error in m/s^2
and a natural-frequency error in Hz) count alike; an objective that is constant over the set is
mapped to 0 so it does not contribute.
"""
from __future__ import annotations

import numpy as np

#: Default neighbourhood radius, in normalised objective space (each objective scaled to [0, 1]
#: over the set): two members are neighbours when their Euclidean distance is below a tenth of an
#: objective's range.  Mirjalili's MOGOA sizes its neighbourhoods as a fixed fraction of the
#: archive's objective range in the same spirit; 0.1 keeps a few neighbours per member for the
#: archive sizes used in calibration (tens to a hundred members on a 2-3 objective front).
DEFAULT_RADIUS = 0.1


def _as_objectives(F) -> np.ndarray:
    """Validate and return ``F`` as a float ``(n, m)`` array with ``n >= 1``."""
    F = np.asarray(F, dtype=float)
    if F.ndim == 1:
        # A 1-d input is a set of single-objective values, not one m-objective point: the
        # archive of a 1-objective run comes out of pymoo as (n, 1) and is squeezed this way.
        F = F[:, None]
    if F.ndim != 2 or F.shape[0] == 0 or F.shape[1] == 0:
        raise ValueError(f"F must be a non-empty (n, m) array, got shape {F.shape}")
    if not np.all(np.isfinite(F)):
        raise ValueError("F must be finite (filter failed evaluations before selecting)")
    return F


def normalise_objectives(F) -> np.ndarray:
    """Min-max normalise every objective over the set.

    Args:
        F: ``(n, m)`` objective values.

    Returns:
        ``(n, m)`` array in [0, 1]; a column with zero range becomes all zeros.
    """
    F = _as_objectives(F)
    lo = F.min(axis=0)
    span = F.max(axis=0) - lo
    # A constant objective carries no information about crowding or trade-off; dividing by 1
    # instead of 0 maps it to 0 for every member.
    span = np.where(span > 0.0, span, 1.0)
    return (F - lo) / span


def pairwise_distances(Z: np.ndarray) -> np.ndarray:
    """Euclidean distance matrix of the rows of ``Z`` (``(n, m)`` -> ``(n, n)``)."""
    diff = Z[:, None, :] - Z[None, :, :]
    return np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))


def neighbour_counts(F, radius: float | None = None) -> np.ndarray:
    """Number of members within ``radius`` of each member, itself included (``hbar_i`` of Eq. 9).

    Counting the member itself makes every count >= 1, so ``1 / hbar_i`` is always defined and an
    isolated member has ``hbar_i = 1``.  Duplicated rows are each other's neighbours (distance 0).

    Args:
        F: ``(n, m)`` objective values.
        radius: Neighbourhood radius in normalised objective space (see :data:`DEFAULT_RADIUS`).

    Returns:
        ``(n,)`` int array of counts.
    """
    radius = DEFAULT_RADIUS if radius is None else float(radius)
    if not radius > 0.0:
        raise ValueError(f"radius must be > 0, got {radius}")
    D = pairwise_distances(normalise_objectives(F))
    return (D < radius).sum(axis=1)


def least_crowded(F, *, radius: float | None = None) -> int:
    """Index of the archive member with the fewest neighbours (the paper's Eq. 9 pick).

    Eq. 9 selects the member maximising ``1 / hbar_i``.  Ties (common: on a sparse archive many
    members have no neighbour but themselves) are broken by the larger distance to the nearest
    other member, i.e. the member that is least crowded at a finer scale, then by the lower index,
    so the pick is deterministic.  Note that on an evenly spread front the ends of the front have
    about half the neighbours of interior members, so this criterion tends to return an extreme
    solution; :func:`knee_point` is the balanced alternative.

    Args:
        F: ``(n, m)`` objective values (minimised).
        radius: Neighbourhood radius in normalised objective space; ``None`` uses
            :data:`DEFAULT_RADIUS` (0.1 of every objective's range over ``F``).

    Returns:
        Row index into ``F``.
    """
    F = _as_objectives(F)
    n = F.shape[0]
    if n == 1:
        return 0
    counts = neighbour_counts(F, radius)
    candidates = np.flatnonzero(counts == counts.min())
    if candidates.size == 1:
        return int(candidates[0])
    D = pairwise_distances(normalise_objectives(F))
    np.fill_diagonal(D, np.inf)
    nearest = D[candidates].min(axis=1)
    # argmax returns the first maximum, i.e. the lowest index among exact ties.
    return int(candidates[np.argmax(nearest)])


def _extreme_indices(Fn: np.ndarray) -> np.ndarray:
    """For each objective, the member minimising it (ties: smallest sum of the other objectives)."""
    n, m = Fn.shape
    total = Fn.sum(axis=1)
    idx = np.empty(m, dtype=int)
    for k in range(m):
        # lexsort sorts by the last key first: primary = objective k, secondary = the rest.
        idx[k] = np.lexsort((total - Fn[:, k], Fn[:, k]))[0]
    return idx


def knee_point(F) -> int:
    """Index of the knee of a front: the member farthest below the hyperplane through the extremes.

    Procedure (Das 1999 / Deb & Gupta style "maximum distance to the extreme-point hyperplane"):

    1. min-max normalise every objective over the set, so the ideal point is the origin;
    2. for every objective take the member that minimises it (the ``m`` extreme points) and fit the
       hyperplane ``w . z = 1`` through them (in 2-D: the straight line joining the two ends);
    3. return the member with the largest signed distance ``(1 - w . z) / |w|`` towards the ideal
       point, i.e. the one that bulges most from the linear trade-off.

    If the extremes do not span a proper hyperplane (coincident extremes, a constant objective,
    fewer distinct points than objectives) or the plane has a non-positive intercept, the plane
    ``sum(z) = 1`` through the unit points of the normalised axes is used instead, which is exactly
    the extreme-point plane in the regular 2-D case.  With one objective the knee is undefined and
    the minimiser is returned.  On a linear or concave front no member lies below the plane and an
    extreme (distance 0) or the member closest to the plane is returned.  Near-ties (within 1e-12)
    go to the lower index.

    Args:
        F: ``(n, m)`` objective values (minimised).

    Returns:
        Row index into ``F``.
    """
    F = _as_objectives(F)
    n, m = F.shape
    if n == 1:
        return 0
    if m == 1:
        return int(np.argmin(F[:, 0]))
    Fn = normalise_objectives(F)
    E = Fn[_extreme_indices(Fn)]
    w = np.ones(m)
    if np.linalg.matrix_rank(E) == m:
        w_fit = np.linalg.solve(E, np.ones(m))
        if np.all(np.isfinite(w_fit)) and np.all(w_fit > 0.0):
            w = w_fit
    dist = (1.0 - Fn @ w) / np.linalg.norm(w)
    return int(np.flatnonzero(dist >= dist.max() - 1e-12)[0])
