"""Evaluating flat-Modelica expression trees (:mod:`fmu_build.flat`) to numbers or CasADi ``SX``.

Structural values (Integer parameters, dimensions, indices) evaluate to Python numbers; anything
that depends on time, states, inputs or Real parameters to ``SX`` expressions.  Arrays are
(nested) lists.  ``der(x)`` is resolved to a derivative symbol by :func:`eval_with_der`; an
index that varies in time becomes a placeholder of :mod:`fmu_build.lookup`.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from twin.errors import BuildError

from . import lookup

_UNARY = {
    "sin": ca.sin, "cos": ca.cos, "tan": ca.tan, "asin": ca.asin, "acos": ca.acos, "atan": ca.atan,
    "sinh": ca.sinh, "cosh": ca.cosh, "tanh": ca.tanh, "exp": ca.exp, "log": ca.log,
    "log10": lambda a: ca.log(a) / math.log(10.0), "sqrt": ca.sqrt, "abs": ca.fabs, "sign": ca.sign,
}
_NUM_UNARY = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh, "exp": math.exp,
    "log": math.log, "log10": math.log10, "sqrt": math.sqrt, "abs": abs,
    "sign": lambda a: float(np.sign(a)),
}


def is_sym(v) -> bool:
    return isinstance(v, (ca.SX, ca.MX))


class Env:
    """Evaluation environment: name -> value (float, int, SX, or list thereof)."""

    def __init__(self, values: dict, symbolic: bool):
        self.values = values
        self.symbolic = symbolic
        self.locals: list[dict] = []
        # While equations are evaluated: the array lookups with a time-varying index, resolved
        # into calls of a lookup function once the equations are solved (fmu_build.lookup).
        self.lookups: list[lookup.Lookup] | None = None

    def lookup(self, name: str):
        for scope in reversed(self.locals):
            if name in scope:
                return scope[name]
        if name in self.values:
            return self.values[name]
        raise KeyError(name)


def elementwise(f, a, b):
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            raise BuildError(f"array size mismatch ({len(a)} vs {len(b)})")
        return [elementwise(f, x, y) for x, y in zip(a, b)]
    if isinstance(a, list):
        return [elementwise(f, x, b) for x in a]
    if isinstance(b, list):
        return [elementwise(f, a, y) for y in b]
    return f(a, b)


def _pow(a, b):
    if is_sym(a) or is_sym(b):
        if not is_sym(b) and float(b) == int(b) and abs(b) <= 4:
            return ca.constpow(a, b) if False else a ** int(b)
        return a ** b
    return float(a) ** float(b)


def _cmp(op):
    def f(a, b):
        if is_sym(a) or is_sym(b):
            return {"<": lambda: a < b, "<=": lambda: a <= b, ">": lambda: a > b, ">=": lambda: a >= b,
                    "==": lambda: a == b, "<>": lambda: a != b}[op]()
        return {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b, "==": a == b, "<>": a != b}[op]
    return f


def evaluate(node, env: Env):
    """Evaluate an expression node to a float/int/SX or (nested) list of them."""
    kind = node[0]
    if kind == "num":
        v = node[1]
        return int(v) if float(v).is_integer() and abs(v) < 2**31 else v
    if kind == "bool":
        return 1 if node[1] else 0
    if kind == "str":
        raise BuildError(f"string expression {node[1]!r} is not supported in equations")
    if kind == "ref":
        name, subs = node[1], node[2]
        try:
            val = env.lookup(name)
        except KeyError:
            raise BuildError(f"unknown name {name!r}") from None
        for k, s in enumerate(subs):
            idx = evaluate(s, env)
            if is_sym(idx) and env.lookups is not None and k == len(subs) - 1 and isinstance(val, list):
                return lookup.placeholder(name, val, idx, env.lookups)
            if is_sym(idx) or not float(idx).is_integer():
                raise BuildError(f"index of {name!r} must be a structural integer, got {idx}")
            if not isinstance(val, list):
                raise BuildError(f"{name!r} is not an array but is indexed")
            i = int(idx)
            if not 1 <= i <= len(val):
                raise BuildError(f"index {i} out of range 1..{len(val)} for {name!r}")
            val = val[i - 1]
        return val
    if kind == "neg":
        v = evaluate(node[1], env)
        return elementwise(lambda a, _: -a, v, 0)
    if kind == "not":
        v = evaluate(node[1], env)
        return ca.logic_not(v) if is_sym(v) else int(not v)
    if kind == "bin":
        op, a, b = node[1], evaluate(node[2], env), evaluate(node[3], env)
        if op in ("+", "-"):
            return elementwise((lambda x, y: x + y) if op == "+" else (lambda x, y: x - y), a, b)
        if op == "*":
            if isinstance(a, list) and isinstance(b, list):
                raise BuildError("'*' between two arrays is ambiguous in flat Modelica; "
                                 "write the product elementwise with a comprehension")
            return elementwise(lambda x, y: x * y, a, b)
        if op == ".*":
            return elementwise(lambda x, y: x * y, a, b)
        if op in ("/", "./"):
            def div(x, y):
                if not is_sym(x) and not is_sym(y):
                    return float(x) / float(y)
                return x / y
            return elementwise(div, a, b)
        if op in ("^", ".^"):
            return elementwise(_pow, a, b)
        if op in ("<", "<=", ">", ">=", "==", "<>"):
            return elementwise(_cmp(op), a, b)
        if op == "and":
            return elementwise(lambda x, y: ca.logic_and(x, y) if is_sym(x) or is_sym(y) else int(bool(x) and bool(y)), a, b)
        if op == "or":
            return elementwise(lambda x, y: ca.logic_or(x, y) if is_sym(x) or is_sym(y) else int(bool(x) or bool(y)), a, b)
        raise BuildError(f"operator {op!r} is not supported")
    if kind == "if":
        branches, other = node[1], node[2]
        result = evaluate(other, env)
        for cond, val in reversed(branches):
            c = evaluate(cond, env)
            v = evaluate(val, env)
            if is_sym(c):
                result = elementwise(lambda x, y, c=c: ca.if_else(c, x, y), v, result)
            else:
                result = v if c else result
        return result
    if kind == "array":
        return [evaluate(it, env) for it in node[1]]
    if kind == "range":
        a, b = evaluate(node[1], env), evaluate(node[2], env)
        if is_sym(a) or is_sym(b):
            raise BuildError("range bounds must be structural integers")
        return list(range(int(a), int(b) + 1))
    if kind == "comp":
        return _comprehension(node[1], node[2], env)
    if kind == "call":
        return _call(node, env)
    raise BuildError(f"unsupported expression node {kind!r}")


def _comprehension(body, iters, env: Env):
    (it, rng), rest = iters[0], iters[1:]
    values = evaluate(rng, env)
    if not isinstance(values, list):
        raise BuildError(f"iterator {it!r} needs a range")
    out = []
    for v in values:
        env.locals.append({it: v})
        try:
            out.append(_comprehension(body, rest, env) if rest else evaluate(body, env))
        finally:
            env.locals.pop()
    return out


def flatten(v):
    if isinstance(v, list):
        return [y for x in v for y in flatten(x)]
    return [v]


def _call(node, env: Env):
    fname, args, named = node[1], node[2], node[3]
    if named:
        raise BuildError(f"named arguments in {fname}({', '.join(named)}=...) are not supported")
    if fname in ("noEvent", "smooth"):
        return evaluate(args[-1], env)
    if fname == "der":
        raise BuildError("der() is only supported on a state variable")
    vals = [evaluate(a, env) for a in args]
    if fname in _UNARY and len(vals) == 1:
        def f(a):
            if is_sym(a):
                return _UNARY[fname](a)
            return _NUM_UNARY[fname](float(a))
        return elementwise(lambda a, _: f(a), vals[0], 0)
    if fname == "atan2" and len(vals) == 2:
        return elementwise(lambda a, b: ca.atan2(a, b) if is_sym(a) or is_sym(b) else math.atan2(a, b), *vals)
    if fname in ("min", "max"):
        items = flatten(vals[0]) if len(vals) == 1 else vals
        if len(vals) == 2:
            fs, fn = (ca.fmin, min) if fname == "min" else (ca.fmax, max)
            return elementwise(lambda a, b: fs(a, b) if is_sym(a) or is_sym(b) else fn(a, b), *vals)
        acc = items[0]
        for it in items[1:]:
            acc = (ca.fmin if fname == "min" else ca.fmax)(acc, it) if is_sym(acc) or is_sym(it) else \
                (min if fname == "min" else max)(acc, it)
        return acc
    if fname == "sum":
        items = flatten(vals[0]) if len(vals) == 1 else flatten(vals)
        acc = 0
        for it in items:
            acc = acc + it
        return acc
    if fname == "product":
        acc = 1
        for it in flatten(vals[0]):
            acc = acc * it
        return acc
    if fname in ("div", "mod", "rem", "floor", "ceil", "integer"):
        if any(is_sym(v) for v in flatten(vals)):
            # rumoca drops noEvent(); the subset check has made sure that each of these calls
            # on a time-varying argument sits inside one, so no event is wanted.
            return elementwise(lambda a, b: lookup.integer_function(fname, a, b), vals[0],
                                vals[1] if len(vals) > 1 else 0)
        a = vals[0]
        if fname == "div":
            return int(a / vals[1]) if isinstance(a, int) and isinstance(vals[1], int) else math.trunc(a / vals[1])
        if fname == "mod":
            return a - math.floor(a / vals[1]) * vals[1]
        if fname == "rem":
            return a - math.trunc(a / vals[1]) * vals[1]
        if fname == "floor":
            return math.floor(a)
        if fname == "ceil":
            return math.ceil(a)
        return int(math.floor(a))
    if fname == "size":
        v = vals[0]
        if len(vals) == 1:
            return [len(v)]
        return len(v)
    if fname in ("zeros", "ones", "fill"):
        fillv = 0 if fname == "zeros" else 1 if fname == "ones" else vals[0]
        dims = vals if fname != "fill" else vals[1:]
        out = fillv
        for d in reversed(dims):
            out = [out for _ in range(int(d))]
        return out
    raise BuildError(f"function {fname}() is not supported")


def const_value(v, what: str):
    if isinstance(v, list):
        return [const_value(x, what) for x in v]
    if is_sym(v):
        v = ca.evalf(v) if not ca.symvar(v) else None
        if v is None:
            raise BuildError(f"{what} does not evaluate to a constant")
        return float(v)
    return v


def eval_with_der(node, env, der_eval):
    """evaluate() with der() resolved to derivative symbols."""
    if isinstance(node, tuple) and node[0] == "call" and node[1] == "der":
        return der_eval(node)
    if isinstance(node, tuple):
        if node[0] in ("num", "bool", "str", "ref", "range"):
            return evaluate(node, env)
        if _contains_der(node):
            # rebuild evaluation for nodes containing der(): evaluate children with the hook
            return _evaluate_der_aware(node, env, der_eval)
    return evaluate(node, env)


def _contains_der(node) -> bool:
    if isinstance(node, tuple):
        if node[0] == "call" and node[1] == "der":
            return True
        return any(_contains_der(p) for p in node[1:])
    if isinstance(node, list):
        return any(_contains_der(p) for p in node)
    return False


def _evaluate_der_aware(node, env, der_eval):
    # Replace der(...) sub-nodes by placeholder refs bound in a local scope, then evaluate.
    counter = [0]
    scope = {}

    def replace(n):
        if isinstance(n, tuple):
            if n[0] == "call" and n[1] == "der":
                key = f"__der{counter[0]}"
                counter[0] += 1
                scope[key] = der_eval(n)
                return ("ref", key, [])
            return tuple(replace(p) if isinstance(p, (tuple, list)) else p for p in n)
        if isinstance(n, list):
            return [replace(p) if isinstance(p, (tuple, list)) else p for p in n]
        return n

    new = replace(node)
    env.locals.append(scope)
    try:
        return evaluate(new, env)
    finally:
        env.locals.pop()
