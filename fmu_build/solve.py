"""Solving the equations in causal order, and hoisting parameter-only subexpressions.

:func:`sort_and_solve` picks, again and again, an equation with exactly one unknown left and
solves it symbolically (it must be linear in that unknown); what never gets down to one unknown
is an algebraic loop, reported as a :class:`BuildError`.  :func:`hoist_static` moves the
subexpressions free of time, states and inputs out of the right-hand side, so that they are
computed once per parameter change.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from twin.errors import BuildError

def hoist_static(exprs: list, dynamic: set[int]) -> tuple[list, list, list]:
    """Replace every maximal subexpression free of ``dynamic`` symbols by a new symbol.

    Parameters
    ----------
    exprs : scalar SX expressions (the right-hand side and the outputs).
    dynamic : hashes of the time, state and input symbols.

    Returns the rewritten expressions, the new symbols and the subexpressions they stand for.
    Leaves (symbols, constants) are never hoisted.
    """
    memo: dict[int, tuple[ca.SX, bool]] = {}      # hash -> (rewritten node, depends on dynamic)
    hoisted: dict[int, ca.SX] = {}
    h_syms: list = []
    h_exprs: list = []

    def replacement(node, is_dyn):
        if is_dyn or node.is_leaf():
            return node
        key = node.__hash__()
        if key not in hoisted:
            sym = ca.SX.sym(f"_h{len(h_syms)}")
            hoisted[key] = sym
            h_syms.append(sym)
            h_exprs.append(node)
        return hoisted[key]

    for root in exprs:
        stack = [(ca.SX(root), False)]
        while stack:
            node, expanded = stack.pop()
            key = node.__hash__()
            if key in memo:
                continue
            if node.is_leaf():
                memo[key] = (node, node.is_symbolic() and key in dynamic)
                continue
            deps = [node.dep(i) for i in range(node.n_dep())]
            if not expanded:
                stack.append((node, True))
                stack.extend((d, False) for d in deps if d.__hash__() not in memo)
                continue
            parts = [memo[d.__hash__()] for d in deps]
            is_dyn = any(dyn for _, dyn in parts)
            if not is_dyn or node.n_dep() not in (1, 2):
                memo[key] = (node, is_dyn)
                continue
            args = [replacement(d, dyn) if not dyn else r for d, (r, dyn) in zip(deps, parts)]
            new = ca.SX.unary(node.op(), args[0]) if node.n_dep() == 1 else ca.SX.binary(node.op(), *args)
            memo[key] = (new, True)
    out = []
    for root in exprs:
        r, dyn = memo[ca.SX(root).__hash__()]
        out.append(r if dyn else replacement(r, False))
    return out, h_syms, h_exprs


@dataclass
class Solution:
    order: list[int]
    values: dict


def sort_and_solve(residuals, unknowns, names) -> Solution:
    """Causal sorting: repeatedly solve an equation that has exactly one unsolved unknown."""
    n = len(unknowns)
    unk_index = {u.__hash__(): i for i, u in enumerate(unknowns)}
    deps = []
    for r, _ in residuals:
        ids = set()
        for s in ca.symvar(r):
            i = unk_index.get(s.__hash__())
            if i is not None:
                ids.add(i)
        deps.append(ids)
    solved: dict[int, ca.SX] = {}
    order: list[int] = []
    pending = set(range(len(residuals)))
    # Map unknown -> equations mentioning it, for quick updates.
    mention: dict[int, set[int]] = {i: set() for i in range(n)}
    for e, ids in enumerate(deps):
        for i in ids:
            mention[i].add(e)
    remaining = [set(d) for d in deps]
    ready = [e for e in pending if len(remaining[e]) == 1]
    while ready:
        e = ready.pop()
        if e not in pending:
            continue
        if len(remaining[e]) != 1:
            if not remaining[e]:
                raise BuildError(f"equation is redundant or over-determined: {residuals[e][1]}")
            continue
        (i,) = tuple(remaining[e])
        r, text = residuals[e]
        u = unknowns[i]
        a = ca.jacobian(r, u)
        if ca.depends_on(a, u):
            raise BuildError(f"equation '{text}' is nonlinear in its unknown {names[i]}; "
                             "only equations linear in the solved variable are supported")
        b = ca.substitute(r, u, ca.SX(0))
        solved[i] = -b / a
        order.append(i)
        pending.discard(e)
        for e2 in mention[i]:
            if e2 in pending:
                remaining[e2].discard(i)
                if len(remaining[e2]) == 1:
                    ready.append(e2)
                elif not remaining[e2]:
                    raise BuildError(f"equation '{residuals[e2][1]}' over-determines {names[i]}")
    if len(order) != n:
        left = [names[i] for i in range(n) if i not in solved]
        eqs = [residuals[e][1] for e in sorted(pending)][:5]
        raise BuildError("algebraic loop or under-determined system (not supported): unknowns "
                         f"{', '.join(left[:10])} appear only in coupled equations, e.g. " + " | ".join(eqs))
    return Solution(order, solved)
