"""Piecewise-linear fields on equally spaced roll-position nodes, as the FMU interpolates them.

``GearTwin.Gearbox21`` evaluates ``k_pair`` and ``profile_deviation`` at a roll position xi as
``sum_n value[n] * max(0, 1 - |xi (n_nodes - 1) - (n - 1)|)``: hat functions on nodes
xi_n = (n - 1) / (n_nodes - 1).  These helpers reproduce that exactly.
"""
from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import numpy as np

from twin.errors import ParameterError

#: Healthy single-tooth-pair stiffness [N/m] at the 11 FMU nodes (the FMU's ``k_pair`` default).
HEALTHY_K_PAIR: tuple[float, ...] = (1.650e8, 2.136e8, 2.514e8, 2.784e8, 2.946e8, 3.000e8,
                                     2.946e8, 2.784e8, 2.514e8, 2.136e8, 1.650e8)


def node_xi(n_nodes: int) -> np.ndarray:
    """Roll positions of ``n_nodes`` equally spaced nodes on [0, 1], shape (n_nodes,)."""
    return np.linspace(0.0, 1.0, n_nodes)


def hat_matrix(xi: np.ndarray, n_nodes: int) -> np.ndarray:
    """H[j, n] = value of hat function n at xi[j]; shape (len(xi), n_nodes).  Rows sum to 1."""
    x = np.clip(np.asarray(xi, dtype=float), 0.0, 1.0)
    return np.maximum(0.0, 1.0 - np.abs(x[:, None] * (n_nodes - 1) - np.arange(n_nodes)[None, :]))


def interp_nodes(values: Sequence[float] | np.ndarray, xi) -> np.ndarray:
    """Piecewise-linear interpolation of node ``values`` at roll positions ``xi`` (any shape)."""
    v = np.asarray(values, dtype=float)
    x = np.asarray(xi, dtype=float)
    return np.interp(np.clip(x, 0.0, 1.0), node_xi(v.size), v)


def node_array(parameters: Mapping[str, float], name: str) -> np.ndarray | None:
    """Values of the FMU array parameter ``name[1]..name[n]`` in ``parameters``, shape (n,).

    Returns None when no element is present; raises ParameterError when the indices are not
    1..n without gaps or a value is not finite.
    """
    pattern = re.compile(re.escape(name) + r"\[(\d+)\]$")
    found = {}
    for key, value in parameters.items():
        match = pattern.match(key)
        if match:
            found[int(match.group(1))] = value
    if not found:
        return None
    n = max(found)
    missing = [i for i in range(1, n + 1) if i not in found]
    if missing:
        raise ParameterError(f"{name}[{missing[0]}] is missing (got indices {sorted(found)})")
    values = np.array([found[i] for i in range(1, n + 1)], dtype=float)
    if n < 2 or not np.all(np.isfinite(values)):
        raise ParameterError(f"{name} needs >= 2 finite node values, got {values.tolist()!r}")
    return values
