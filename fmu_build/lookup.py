"""Array lookups with a time-varying Integer index, and the Integer functions that make one.

``f[noEvent(integer(x)) + 1]`` reads one element of ``f`` in constant time, whatever the length
of ``f``.  While the equations are evaluated each such lookup stands in as a placeholder
symbol (:func:`placeholder`); once the equations are solved, :func:`resolve` replaces the
placeholders by calls of a CasADi function that indexes the array in place (parametric
indexing of MX; the generated C code reads the element through a pointer, no copy), one call
per array for all its lookups whose indices are known.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from twin.errors import BuildError


@dataclass
class Lookup:
    """``array[index]`` with a time-varying Integer index, standing in as ``placeholder``."""

    name: str
    array: list           # the array's scalars (SX or numbers)
    index: ca.SX          # 1-based index, integer valued
    placeholder: ca.SX


def integer_function(fname: str, a, b):
    """div, mod, rem, floor, ceil, integer of a time-varying value, as in Modelica (no events)."""
    a = ca.SX(a)
    if fname in ("floor", "integer"):
        return ca.floor(a)
    if fname == "ceil":
        return ca.ceil(a)
    quotient = ca.floor(a / b) if fname == "mod" else ca.sign(a / b) * ca.floor(ca.fabs(a / b))
    if fname == "div":
        return quotient
    return a - quotient * b


_INTEGER_OPS = {ca.OP_ADD, ca.OP_SUB, ca.OP_MUL, ca.OP_NEG, ca.OP_FMIN, ca.OP_FMAX, ca.OP_FABS}


def integer_valued(e: ca.SX) -> bool:
    """Whether an index expression takes only integer values: integer constants, structural
    integers and floor/ceil combined by + - * min max abs (what integer(), mod() and Integer
    arithmetic evaluate to)."""
    if e.is_constant():
        return float(e).is_integer()
    if e.is_symbolic():
        return False
    op = e.op()
    if op in (ca.OP_FLOOR, ca.OP_CEIL):
        return True
    if op == ca.OP_IF_ELSE_ZERO:
        return integer_valued(e.dep(1))
    if op in _INTEGER_OPS:
        return all(integer_valued(e.dep(i)) for i in range(e.n_dep()))
    return False


def placeholder(name: str, array: list, index, lookups: list[Lookup]) -> ca.SX:
    """``array[index]`` for a time-varying Integer index: a new placeholder symbol, recorded in
    ``lookups`` until :func:`resolve` turns it into a lookup call."""
    if any(isinstance(v, list) for v in array):
        raise BuildError(f"{name!r}: a time-varying index is supported on 1-D arrays only")
    if not integer_valued(ca.SX(index)):
        raise BuildError(f"index of {name!r} must be an Integer expression (structural, or "
                         f"noEvent(integer(...)) of a time-varying one), got {index}")
    sym = ca.SX.sym(f"{name}[_lookup{len(lookups)}]")
    lookups.append(Lookup(name, list(array), ca.SX(index), sym))
    return sym


def lookup_function(n: int, m: int) -> ca.Function:
    """``(array[n], index[m]) -> array[index]`` with 0-based indices, in constant time per index
    (an index out of range gives NaN, which fails the step)."""
    array, index = ca.MX.sym("array", n), ca.MX.sym("index", m)
    return ca.Function(f"lookup_{n}_{m}", [array, index], [array[index]], ["array", "index"], ["value"],
                       {"never_inline": True})


def operands(lookups: list[Lookup]) -> list:
    """The 0-based index and the array's scalars of each lookup, flattened: the expressions
    :func:`resolve` takes back (after they are written in the ODE's terms)."""
    out = []
    for lk in lookups:
        out += [lk.index - 1, *(ca.SX(v) for v in lk.array)]
    return out


def resolve(lookups: list[Lookup], exprs: list, xdot: list, y_exprs: list) -> tuple[list, list]:
    """Replace the placeholders in ``xdot`` and ``y_exprs`` by calls of :func:`lookup_function`.

    ``exprs`` is :func:`operands` in the ODE's terms.  Each round calls, once per array, every
    lookup whose index and array are free of unresolved placeholders; an index that needs its
    own lookup's value is an algebraic loop."""
    parts, k = [], 0
    for lk in lookups:
        parts.append((exprs[k], exprs[k + 1:k + 1 + len(lk.array)]))
        k += 1 + len(lk.array)
    pending = list(range(len(lookups)))
    while pending:
        waiting = ca.vertcat(*(lookups[i].placeholder for i in pending))
        ready = [i for i in pending if not ca.depends_on(ca.vertcat(*parts[i][1], parts[i][0]), waiting)]
        if not ready:
            raise BuildError("algebraic loop through an array index: the index of "
                             + ", ".join(sorted({lookups[i].name for i in pending}))
                             + " depends on the looked-up value")
        groups: dict[tuple, list[int]] = {}
        for i in ready:
            key = tuple(float(e) if e.is_constant() else e.__hash__() for e in parts[i][1])
            groups.setdefault(key, []).append(i)
        syms, vals = [], []
        for members in groups.values():
            array = ca.vertcat(*parts[members[0]][1])
            index = ca.vertcat(*(parts[i][0] for i in members))
            value = lookup_function(array.numel(), index.numel())(array, index)
            syms += [lookups[i].placeholder for i in members]
            vals += [value[j] for j in range(len(members))]
        pending = [i for i in pending if i not in ready]
        xdot = ca.substitute(xdot, syms, vals)
        y_exprs = ca.substitute(y_exprs, syms, vals)
        for i in pending:
            index, *array = ca.substitute([parts[i][0], *parts[i][1]], syms, vals)
            parts[i] = (index, array)
    return xdot, y_exprs
