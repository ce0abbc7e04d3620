"""The ModelStructure of an FMU, read from the structure of the generated CasADi functions.

For each output and state derivative, the knowns it depends on (states ``x`` and inputs ``u``)
are the structural non-zeros of the Jacobian of the generated expression, and the kind of each
dependency follows from the Jacobian entry itself:

- ``constant``: the entry is a number (the known enters as ``c*v``);
- ``tunable``: the entry depends on parameters only (``p*v``; every parameter of these FMUs is
  tunable);
- ``dependent``: anything else (the known enters nonlinearly, or through a factor that changes
  with time, states or inputs).

Initial unknowns (calculated parameters, states, derivatives and outputs after initialisation)
depend on the exact parameters ``p`` and the inputs ``u``: their dependencies come from the
Jacobian of the initialisation chain ``q = derived(p)``, ``x0 = init(p, q)``, then the outputs
and derivatives at ``x0``.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

#: One dependency: (block, index within the block, kind); block is "x", "u" or "p".
Dependency = tuple[str, int, str]


@dataclass(frozen=True)
class ModelStructure:
    outputs: list[list[Dependency]]          # per output, in output order
    derivatives: list[list[Dependency]]      # per state derivative, in state order
    initial_outputs: list[list[Dependency]]
    initial_calculated: list[list[Dependency]]   # per exposed calculated parameter
    initial_states: list[list[Dependency]]
    initial_derivatives: list[list[Dependency]]


def _kind(entry: ca.SX, dynamic: ca.SX) -> str | None:
    if entry.is_zero():
        return None
    if entry.is_constant():
        return "constant"
    if dynamic.numel() and ca.depends_on(entry, dynamic):
        return "dependent"
    return "tunable"


def _rows(expr: ca.SX, knowns: list[tuple[str, ca.SX]], dynamic: ca.SX, n_rows: int) -> list[list[Dependency]]:
    blocks = [(name, sym) for name, sym in knowns if sym.numel()]
    out: list[list[Dependency]] = [[] for _ in range(n_rows)]
    if not blocks or n_rows == 0:
        return out
    wrt = ca.vertcat(*(sym for _, sym in blocks))
    jac = ca.jacobian(expr, wrt)
    offsets, start = [], 0
    for name, sym in blocks:
        offsets.append((start, start + sym.numel(), name))
        start += sym.numel()
    rows, cols = jac.sparsity().get_triplet()
    for r, c in sorted(zip(rows, cols)):
        kind = _kind(jac[r, c], dynamic)
        if kind is None:
            continue
        for lo, hi, name in offsets:
            if lo <= c < hi:
                out[r].append((name, c - lo, kind))
                break
    return out


def model_structure(ode) -> ModelStructure:
    """Dependencies of the outputs, derivatives and initial unknowns of an :class:`OdeModel`."""
    t, x, u, p, q = ode.rhs.sx_in()
    xdot = ode.rhs.call([t, x, u, p, q])[0]
    y = ode.outputs_fn.call([t, x, u, p, q])[0]
    dynamic = ca.vertcat(t, x, u)
    knowns = [("x", x), ("u", u)]
    outputs = _rows(y, knowns, dynamic, y.numel())
    derivatives = _rows(xdot, knowns, dynamic, xdot.numel())

    # initialisation: everything as a function of the exact parameters p and the inputs u
    q0 = ode.derived.call([p])[0]
    x0 = ode.init.call([p, q0])[0]
    y0 = ode.outputs_fn.call([t, x0, u, p, q0])[0]
    xdot0 = ode.rhs.call([t, x0, u, p, q0])[0]
    init_knowns = [("p", p), ("u", u)]
    n_calc = len(ode.calculated)
    initial_calculated = _rows(q0[:n_calc] if n_calc else ca.SX(0, 1), init_knowns, ca.vertcat(t, u), n_calc)
    initial_states = _rows(x0, init_knowns, ca.vertcat(t, u), x0.numel())
    initial_outputs = _rows(y0, init_knowns, ca.vertcat(t, u), y0.numel())
    initial_derivatives = _rows(xdot0, init_knowns, ca.vertcat(t, u), xdot0.numel())
    return ModelStructure(outputs, derivatives, initial_outputs, initial_calculated, initial_states,
                          initial_derivatives)
