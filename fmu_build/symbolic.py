"""Turn a :class:`~fmu_build.flat.FlatModel` into CasADi functions of a states-only ODE.

The result is an :class:`OdeModel`::

    x' = rhs(t, x, u, p, q)        x: states, u: inputs, p: tunable parameters
    y  = outputs(t, x, u, p, q)    q: calculated parameters = derived(p)
    x0 = init(p, q)

Algebraic variables are eliminated by sorting the equations: each step picks an equation
with exactly one unknown left and solves it symbolically, which must be linear in that
unknown.  An algebraic loop or a nonlinear equation is reported as a :class:`BuildError`.
Integer parameters are structural: they are evaluated here and fixed in the FMU.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from twin.errors import BuildError

from . import lookup
from .flat import Decl, FlatModel

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


@dataclass
class Variable:
    """A scalar variable of the ODE model, as it will appear in the modelDescription."""

    name: str
    kind: str            # parameter, calculated, input, output, state, constant
    unit: str = ""
    description: str = ""
    start: float = 0.0
    type: str = "Real"
    min: float | None = None        # Modelica attributes min, max, nominal (constants)
    max: float | None = None
    nominal: float | None = None


@dataclass
class OdeModel:
    name: str
    description: str
    states: list[Variable]
    inputs: list[Variable]
    outputs: list[Variable]
    parameters: list[Variable]
    calculated: list[Variable]
    constants: list[Variable]
    rhs: ca.Function
    outputs_fn: ca.Function
    init: ca.Function
    derived: ca.Function
    notes: list[str] = field(default_factory=list)
    n_hidden: int = 0          # hoisted parameter-only subexpressions appended to q (not FMU variables)


def _is_sym(v) -> bool:
    return isinstance(v, (ca.SX, ca.MX))


class _Env:
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


def _elementwise(f, a, b):
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            raise BuildError(f"array size mismatch ({len(a)} vs {len(b)})")
        return [_elementwise(f, x, y) for x, y in zip(a, b)]
    if isinstance(a, list):
        return [_elementwise(f, x, b) for x in a]
    if isinstance(b, list):
        return [_elementwise(f, a, y) for y in b]
    return f(a, b)


def _pow(a, b):
    if _is_sym(a) or _is_sym(b):
        if not _is_sym(b) and float(b) == int(b) and abs(b) <= 4:
            return ca.constpow(a, b) if False else a ** int(b)
        return a ** b
    return float(a) ** float(b)


def _cmp(op):
    def f(a, b):
        if _is_sym(a) or _is_sym(b):
            return {"<": lambda: a < b, "<=": lambda: a <= b, ">": lambda: a > b, ">=": lambda: a >= b,
                    "==": lambda: a == b, "<>": lambda: a != b}[op]()
        return {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b, "==": a == b, "<>": a != b}[op]
    return f


def evaluate(node, env: _Env):
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
            if _is_sym(idx) and env.lookups is not None and k == len(subs) - 1 and isinstance(val, list):
                return lookup.placeholder(name, val, idx, env.lookups)
            if _is_sym(idx) or not float(idx).is_integer():
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
        return _elementwise(lambda a, _: -a, v, 0)
    if kind == "not":
        v = evaluate(node[1], env)
        return ca.logic_not(v) if _is_sym(v) else int(not v)
    if kind == "bin":
        op, a, b = node[1], evaluate(node[2], env), evaluate(node[3], env)
        if op in ("+", "-"):
            return _elementwise((lambda x, y: x + y) if op == "+" else (lambda x, y: x - y), a, b)
        if op == "*":
            if isinstance(a, list) and isinstance(b, list):
                raise BuildError("'*' between two arrays is ambiguous in flat Modelica; "
                                 "write the product elementwise with a comprehension")
            return _elementwise(lambda x, y: x * y, a, b)
        if op == ".*":
            return _elementwise(lambda x, y: x * y, a, b)
        if op in ("/", "./"):
            def div(x, y):
                if not _is_sym(x) and not _is_sym(y):
                    return float(x) / float(y)
                return x / y
            return _elementwise(div, a, b)
        if op in ("^", ".^"):
            return _elementwise(_pow, a, b)
        if op in ("<", "<=", ">", ">=", "==", "<>"):
            return _elementwise(_cmp(op), a, b)
        if op == "and":
            return _elementwise(lambda x, y: ca.logic_and(x, y) if _is_sym(x) or _is_sym(y) else int(bool(x) and bool(y)), a, b)
        if op == "or":
            return _elementwise(lambda x, y: ca.logic_or(x, y) if _is_sym(x) or _is_sym(y) else int(bool(x) or bool(y)), a, b)
        raise BuildError(f"operator {op!r} is not supported")
    if kind == "if":
        branches, other = node[1], node[2]
        result = evaluate(other, env)
        for cond, val in reversed(branches):
            c = evaluate(cond, env)
            v = evaluate(val, env)
            if _is_sym(c):
                result = _elementwise(lambda x, y, c=c: ca.if_else(c, x, y), v, result)
            else:
                result = v if c else result
        return result
    if kind == "array":
        return [evaluate(it, env) for it in node[1]]
    if kind == "range":
        a, b = evaluate(node[1], env), evaluate(node[2], env)
        if _is_sym(a) or _is_sym(b):
            raise BuildError("range bounds must be structural integers")
        return list(range(int(a), int(b) + 1))
    if kind == "comp":
        return _comprehension(node[1], node[2], env)
    if kind == "call":
        return _call(node, env)
    raise BuildError(f"unsupported expression node {kind!r}")


def _comprehension(body, iters, env: _Env):
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


def _flatten(v):
    if isinstance(v, list):
        return [y for x in v for y in _flatten(x)]
    return [v]


def _call(node, env: _Env):
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
            if _is_sym(a):
                return _UNARY[fname](a)
            return _NUM_UNARY[fname](float(a))
        return _elementwise(lambda a, _: f(a), vals[0], 0)
    if fname == "atan2" and len(vals) == 2:
        return _elementwise(lambda a, b: ca.atan2(a, b) if _is_sym(a) or _is_sym(b) else math.atan2(a, b), *vals)
    if fname in ("min", "max"):
        items = _flatten(vals[0]) if len(vals) == 1 else vals
        if len(vals) == 2:
            fs, fn = (ca.fmin, min) if fname == "min" else (ca.fmax, max)
            return _elementwise(lambda a, b: fs(a, b) if _is_sym(a) or _is_sym(b) else fn(a, b), *vals)
        acc = items[0]
        for it in items[1:]:
            acc = (ca.fmin if fname == "min" else ca.fmax)(acc, it) if _is_sym(acc) or _is_sym(it) else \
                (min if fname == "min" else max)(acc, it)
        return acc
    if fname == "sum":
        items = _flatten(vals[0]) if len(vals) == 1 else _flatten(vals)
        acc = 0
        for it in items:
            acc = acc + it
        return acc
    if fname == "product":
        acc = 1
        for it in _flatten(vals[0]):
            acc = acc * it
        return acc
    if fname in ("div", "mod", "rem", "floor", "ceil", "integer"):
        if any(_is_sym(v) for v in _flatten(vals)):
            # rumoca drops noEvent(); the subset check has made sure that each of these calls
            # on a time-varying argument sits inside one, so no event is wanted.
            return _elementwise(lambda a, b: lookup.integer_function(fname, a, b), vals[0],
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


# ----------------------------------------------------------------------------------------------
def _scalar_names(decl: Decl, dims: list[int]) -> list[str]:
    if not dims:
        return [decl.name]
    if len(dims) > 1:
        raise BuildError(f"{decl.name}: only 1-D arrays are supported")
    return [f"{decl.name}[{i}]" for i in range(1, dims[0] + 1)]


def _const_value(v, what: str):
    if isinstance(v, list):
        return [_const_value(x, what) for x in v]
    if _is_sym(v):
        v = ca.evalf(v) if not ca.symvar(v) else None
        if v is None:
            raise BuildError(f"{what} does not evaluate to a constant")
        return float(v)
    return v


def build_ode(flat: FlatModel) -> OdeModel:
    """Classify variables, evaluate parameters, eliminate algebraics, return CasADi functions."""
    consts: dict = {}          # structural values (Integer/Boolean parameters, constants)
    notes: list[str] = []

    # Pass 1: structural integers.  rumoca lists an extended base class first, so a binding may
    # name a structural value declared further down (``extends Base(z2 = wheel_teeth)``): sweep
    # until every binding has been evaluated, and report the ones that never resolve.
    num_env = _Env(consts, symbolic=False)
    pending = []
    for d in flat.decls:
        if d.prefix in ("parameter", "constant") and d.type in ("Integer", "Boolean"):
            if d.binding is None:
                raise BuildError(f"structural parameter {d.name} needs a binding")
            pending.append(d)
        elif d.type in ("Integer", "Boolean", "String") and d.prefix not in ("parameter", "constant"):
            raise BuildError(f"variable {d.name}: only Real variables may vary in time "
                             f"(found {d.type}); discrete variables are outside the supported subset")
    while pending:
        waiting, error = [], None
        for d in pending:
            try:
                consts[d.name] = _const_value(evaluate(d.binding, num_env), d.name)
            except BuildError as exc:
                waiting.append(d)
                error = error or exc
        if len(waiting) == len(pending):
            raise error
        pending = waiting

    def dims_of(d: Decl) -> list[int]:
        out = []
        for e in d.dims:
            v = _const_value(evaluate(e, num_env), f"dimension of {d.name}")
            out.append(int(v))
        return out

    values: dict = dict(consts)
    t = ca.SX.sym("time")
    values["time"] = t
    env = _Env(values, symbolic=True)

    params: list[Variable] = []
    p_syms: list = []
    calc: list[Variable] = []
    q_syms: list = []
    q_exprs: list = []           # in terms of p_syms and earlier q_syms
    constants: list[Variable] = []
    inputs: list[Variable] = []
    u_syms: list = []
    unknown_decls: list[tuple[Decl, list[int]]] = []

    def attr_str(d, key):
        e = d.attrs.get(key)
        return e[1] if e is not None and e[0] == "str" else ""

    def bounds(d, names) -> list[dict]:
        return _bounds(d, names, env)

    # Symbols for every Real parameter first: rumoca lists an extended base class before the
    # components of the derived model, so a binding may name a parameter declared further down
    # (``extends Base(p = effect.shape)``).
    param_syms: dict[str, list] = {}
    for d in flat.decls:
        if d.prefix == "parameter" and d.type not in ("Integer", "Boolean"):
            dims = dims_of(d)
            syms = [ca.SX.sym(n) for n in _scalar_names(d, dims)]
            param_syms[d.name] = syms
            values[d.name] = syms if dims else syms[0]

    for d in flat.decls:
        if d.prefix in ("parameter", "constant") and d.type in ("Integer", "Boolean"):
            dims = dims_of(d)
            vals = consts[d.name] if dims else [consts[d.name]]
            for n, v in zip(_scalar_names(d, dims), vals):
                constants.append(Variable(n, "constant", attr_str(d, "unit"), d.description, float(v), d.type))
            continue
        if d.prefix == "constant" and d.type == "Real":
            v = _const_value(evaluate(d.binding, env), d.name)
            values[d.name] = v
            continue
        dims = dims_of(d)
        names = _scalar_names(d, dims)
        if d.prefix == "parameter":
            syms = param_syms[d.name]
            if d.binding is None:
                raise BuildError(f"parameter {d.name} has no value")
            bval = evaluate(d.binding, env)
            bflat = _flatten(bval) if dims else [bval]
            if len(bflat) != len(names):
                raise BuildError(f"parameter {d.name}: binding has {len(bflat)} elements, expected {len(names)}")
            for n, s, b, lim in zip(names, syms, bflat, bounds(d, names)):
                if _is_sym(b) and ca.symvar(b):
                    calc.append(Variable(n, "calculated", attr_str(d, "unit"), d.description, 0.0, **lim))
                    q_syms.append(s)
                    q_exprs.append(b)
                else:
                    val = float(ca.evalf(b)) if _is_sym(b) else float(b)
                    params.append(Variable(n, "parameter", attr_str(d, "unit"), d.description, val, **lim))
                    p_syms.append(s)
        elif d.prefix == "input" and d.binding is None and "." not in d.name:
            syms = [ca.SX.sym(n) for n in names]
            values[d.name] = syms if dims else syms[0]
            start = d.attrs.get("start")
            sval = evaluate(start, env) if start is not None else 0.0
            sflat = _flatten(sval) if isinstance(sval, list) else [sval] * len(names)
            for n, s, sv, lim in zip(names, syms, sflat, bounds(d, names)):
                sv = _const_value(sv, f"start of input {n}")
                inputs.append(Variable(n, "input", attr_str(d, "unit"), d.description, float(sv), **lim))
                u_syms.append(s)
        else:
            unknown_decls.append((d, dims))

    # States: every variable that appears under der().
    state_names: list[str] = []

    def collect_der(node):
        if not isinstance(node, tuple):
            return
        if node[0] == "call" and node[1] == "der":
            arg = node[2][0]
            if arg[0] != "ref":
                raise BuildError("der() of an expression is outside the supported subset; "
                                 "introduce a variable for it")
            base = arg[1]
            if arg[2]:
                idx = _const_value(evaluate(arg[2][0], env), "der() index")
                nm = f"{base}[{int(idx)}]"
                if nm not in state_names:
                    state_names.append(nm)
            else:
                state_names.append(base) if base not in state_names else None
            return
        for part in node[1:]:
            if isinstance(part, tuple):
                collect_der(part)
            elif isinstance(part, list):
                for q in part:
                    if isinstance(q, tuple):
                        collect_der(q)
                    elif isinstance(q, (list, tuple)):
                        for r in q:
                            collect_der(r) if isinstance(r, tuple) else None

    for eq in flat.equations:
        collect_der(eq.lhs)
        collect_der(eq.rhs)

    # Whole arrays under der(x) expand to all their elements.
    decl_dims = {d.name: dims for d, dims in unknown_decls}
    expanded = []
    for nm in state_names:
        if nm in decl_dims and decl_dims[nm]:
            expanded += [f"{nm}[{i}]" for i in range(1, decl_dims[nm][0] + 1)]
        else:
            expanded.append(nm)
    state_names = list(dict.fromkeys(expanded))

    x_syms, states = [], []
    alg_syms, alg_names, outputs_decl = [], [], []
    sym_of: dict[str, ca.SX] = {}
    for d, dims in unknown_decls:
        names = _scalar_names(d, dims)
        syms = [ca.SX.sym(n) for n in names]
        values[d.name] = syms if dims else syms[0]
        for n, s in zip(names, syms):
            sym_of[n] = s
        if d.binding is not None:
            # declaration equation, e.g. output Real y = x;
            from .flat import Equation
            flat.equations.append(Equation(("ref", d.name, []), d.binding, f"{d.name} = <binding>"))
        if d.prefix == "output" and "." not in d.name:
            # outputs of sub-components (effect blocks) stay internal; the FMU interface is the
            # top-level model's
            outputs_decl.append((d, names))

    for n in state_names:
        if n not in sym_of:
            raise BuildError(f"der({n}): {n} is not a declared Real variable")
    der_sym = {}
    for d, dims in unknown_decls:
        names = _scalar_names(d, dims)
        for n, lim in zip(names, bounds(d, names)):
            if n in state_names:
                x_syms.append(sym_of[n])
                dsym = ca.SX.sym(f"der({n})")
                der_sym[n] = dsym
                states.append(Variable(n, "state", attr_str(d, "unit"), d.description, **lim))
            else:
                alg_syms.append(sym_of[n])
                alg_names.append(n)
    dx_list = [der_sym[v.name] for v in states]

    # der() evaluation: substitute the derivative symbols.
    def der_eval(node):
        arg = node[2][0]
        val = evaluate(arg, env)
        if isinstance(val, list):
            return [der_of[id_of(v)] for v in val]
        return der_of[id_of(val)]

    der_of = {}
    for v, s in zip(states, x_syms):
        der_of[s.__hash__()] = der_sym[v.name]

    def id_of(s):
        if not _is_sym(s) or not s.is_symbolic():
            raise BuildError("der() of an expression is outside the supported subset")
        return s.__hash__()

    # Residuals
    residuals: list[tuple[ca.SX, str]] = []
    env.lookups = []
    for eq in flat.equations:
        lhs = _eval_with_der(eq.lhs, env, der_eval)
        rhs = _eval_with_der(eq.rhs, env, der_eval)
        diff = _elementwise(lambda a, b: a - b, lhs, rhs)
        for r in _flatten(diff):
            residuals.append((ca.SX(r), eq.text))
    lookups, env.lookups = env.lookups, None

    unknowns = dx_list + alg_syms
    unknown_names = [f"der({v.name})" for v in states] + alg_names
    if len(residuals) != len(unknowns):
        raise BuildError(f"model is not balanced: {len(residuals)} scalar equations for "
                         f"{len(unknowns)} unknowns (derivatives and algebraic variables)")

    solution = _sort_and_solve(residuals, unknowns, unknown_names)

    # Express everything in terms of (t, x, u, p, q).
    subs_syms = [unknowns[i] for i in solution.order]
    subs_vals = [solution.values[i] for i in solution.order]
    # Forward substitution in causal order.
    resolved: list = []
    for k, val in enumerate(subs_vals):
        if k:
            val = ca.substitute([val], subs_syms[:k], resolved)[0]
        resolved.append(val)
    idx_of = {unknowns[i].__hash__(): i for i in range(len(unknowns))}
    final = [None] * len(unknowns)
    for s, v in zip(subs_syms, resolved):
        final[idx_of[s.__hash__()]] = v
    xdot = final[: len(dx_list)]

    # Outputs
    outputs: list[Variable] = []
    y_exprs = []
    alg_index = {n: i for i, n in enumerate(alg_names)}
    state_index = {v.name: i for i, v in enumerate(states)}
    for d, names in outputs_decl:
        for n, lim in zip(names, bounds(d, names)):
            outputs.append(Variable(n, "output", attr_str(d, "unit"), d.description, **lim))
            if n in alg_index:
                y_exprs.append(final[len(dx_list) + alg_index[n]])
            else:
                y_exprs.append(x_syms[state_index[n]])

    # Calculated parameters in terms of p only.
    # Bindings may name calculated parameters declared later, so substitute to a fixed point;
    # a chain can be at most len(q_syms) deep, anything longer is a cycle.
    q_final = list(q_exprs)
    for _ in range(len(q_syms) + 1):
        if not q_syms or not ca.depends_on(ca.vertcat(*q_final), ca.vertcat(*q_syms)):
            break
        q_final = ca.substitute(q_final, q_syms, q_final)
    else:
        raise BuildError("parameter bindings form a cycle: "
                         + ", ".join(v.name for v, e in zip(calc, q_final)
                                     if ca.depends_on(e, ca.vertcat(*q_syms))))

    # Start values of states.
    x0 = []
    for (d, dims) in unknown_decls:
        names = _scalar_names(d, dims)
        if not any(n in state_index for n in names):
            continue
        start = d.attrs.get("start")
        sval = evaluate(start, env) if start is not None else 0.0
        sflat = _flatten(sval) if isinstance(sval, list) else [sval] * len(names)
        for n, sv in zip(names, sflat):
            if n in state_index:
                x0.append((state_index[n], sv))
    x0.sort()
    x0_exprs = [ca.SX(v) for _, v in x0]

    # Parameter-only subexpressions (sin(alpha), products of parameters, ...) are moved into the
    # derived function, which runs once per parameter change instead of 4x per RK4 step.
    # Array lookups with a time-varying index: their indices (and arrays) in the same terms.
    lk_exprs = ca.substitute(lookup.operands(lookups), subs_syms, resolved) if lookups else []
    dynamic = {s.__hash__() for s in [t, *x_syms, *u_syms, *(lk.placeholder for lk in lookups)]}
    rebuilt, h_syms, h_exprs = hoist_static([*xdot, *y_exprs, *lk_exprs], dynamic)
    n_x, n_y = len(xdot), len(y_exprs)
    xdot, y_exprs = rebuilt[:n_x], rebuilt[n_x:n_x + n_y]
    if lookups:
        xdot, y_exprs = lookup.resolve(lookups, rebuilt[n_x + n_y:], xdot, y_exprs)
    if h_exprs:
        h_in_p = ca.substitute(h_exprs, q_syms, q_final) if q_syms else h_exprs
        q_final = [*q_final, *h_in_p]
        q_syms = [*q_syms, *h_syms]

    X = ca.vertcat(*x_syms)
    U = ca.vertcat(*u_syms) if u_syms else ca.SX(0, 1)
    P = ca.vertcat(*p_syms) if p_syms else ca.SX(0, 1)
    Q = ca.vertcat(*q_syms) if q_syms else ca.SX(0, 1)
    opts = {"cse": True}
    rhs = ca.Function("rhs", [t, X, U, P, Q], [ca.vertcat(*xdot)], ["t", "x", "u", "p", "q"], ["xdot"], opts)
    outf = ca.Function("outputs", [t, X, U, P, Q], [ca.vertcat(*y_exprs) if y_exprs else ca.SX(0, 1)],
                       ["t", "x", "u", "p", "q"], ["y"], opts)
    init = ca.Function("init", [P, Q], [ca.vertcat(*x0_exprs) if x0_exprs else ca.SX(0, 1)], ["p", "q"], ["x0"], opts)
    derived = ca.Function("derived", [P], [ca.vertcat(*q_final) if q_final else ca.SX(0, 1)], ["p"], ["q"], opts)
    for f in (rhs, outf, init, derived):
        if f.has_free():
            raise BuildError(f"internal: {f.name()} has free symbols {f.get_free()}")
    # Default values of calculated parameters and initial states, for the modelDescription.
    p0 = np.array([v.start for v in params])
    qv = np.array(derived(p0)).ravel()
    for v, val in zip(calc, qv):
        v.start = float(val)
    for v, val in zip(states, np.array(init(p0, qv)).ravel()):
        v.start = float(val)
    for v in [*params, *calc, *inputs, *states]:
        _check_in_bounds(v)
    return OdeModel(flat.name, flat.description, states, inputs, outputs, params, calc, constants,
                    rhs, outf, init, derived, notes, n_hidden=len(h_syms))


def _bounds(d: Decl, names: list[str], env: _Env) -> list[dict]:
    """``min``/``max``/``nominal`` of each scalar of a declaration, as floats (absent: not set).

    The attribute may be a scalar (``each min = 0``, or a plain scalar on a scalar) or an array
    with one value per element, and must evaluate to constants at build time."""
    out: list[dict] = [{} for _ in names]
    for key in ("min", "max", "nominal"):
        e = d.attrs.get(key)
        if e is None:
            continue
        v = evaluate(e, env)
        vals = _flatten(v) if isinstance(v, list) else [v] * len(names)
        if len(vals) != len(names):
            raise BuildError(f"{d.name}: attribute {key} has {len(vals)} elements, expected {len(names)}")
        for o, x, n in zip(out, vals, names):
            x = float(_const_value(x, f"attribute {key} of {n}"))
            if not math.isfinite(x):
                raise BuildError(f"attribute {key} of {n} must be finite, got {x}")
            if key == "nominal" and not x > 0:
                raise BuildError(f"attribute nominal of {n} must be > 0, got {x}")
            o[key] = x
    for o, n in zip(out, names):
        if "min" in o and "max" in o and o["min"] > o["max"]:
            raise BuildError(f"{n}: min = {o['min']} is above max = {o['max']}")
    return out


def _check_in_bounds(v: Variable) -> None:
    if v.min is not None and v.start < v.min:
        raise BuildError(f"{v.name}: default value {v.start} is below its min = {v.min}")
    if v.max is not None and v.start > v.max:
        raise BuildError(f"{v.name}: default value {v.start} is above its max = {v.max}")


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


def _eval_with_der(node, env, der_eval):
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


@dataclass
class _Solution:
    order: list[int]
    values: dict


def _sort_and_solve(residuals, unknowns, names) -> _Solution:
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
    return _Solution(order, solved)
