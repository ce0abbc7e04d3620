"""Turn a :class:`~fmu_build.flat.FlatModel` into CasADi functions of a states-only ODE.

The result is an :class:`OdeModel`::

    x' = rhs(t, x, u, p, q)        x: states, u: inputs, p: tunable parameters
    y  = outputs(t, x, u, p, q)    q: calculated parameters = derived(p)
    x0 = init(p, q)

Algebraic variables are eliminated by sorting the equations (:mod:`fmu_build.solve`): each
step picks an equation with exactly one unknown left and solves it symbolically, which must be
linear in that unknown.  An algebraic loop or a nonlinear equation is reported as a
:class:`BuildError`.  Integer parameters are structural: they are evaluated here (expressions by
:mod:`fmu_build.evaluate`) and fixed in the FMU.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from twin.errors import BuildError

from . import lookup
from .evaluate import Env, const_value, elementwise, eval_with_der, evaluate, flatten, is_sym
from .flat import Decl, FlatModel
from .solve import hoist_static, sort_and_solve

__all__ = ["Variable", "OdeModel", "build_ode", "evaluate", "hoist_static"]


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


def _scalar_names(decl: Decl, dims: list[int]) -> list[str]:
    if not dims:
        return [decl.name]
    if len(dims) > 1:
        raise BuildError(f"{decl.name}: only 1-D arrays are supported")
    return [f"{decl.name}[{i}]" for i in range(1, dims[0] + 1)]


def build_ode(flat: FlatModel) -> OdeModel:
    """Classify variables, evaluate parameters, eliminate algebraics, return CasADi functions."""
    consts: dict = {}          # structural values (Integer/Boolean parameters, constants)
    notes: list[str] = []

    # Pass 1: structural integers.  rumoca lists an extended base class first, so a binding may
    # name a structural value declared further down (``extends Base(z2 = wheel_teeth)``): sweep
    # until every binding has been evaluated, and report the ones that never resolve.
    num_env = Env(consts, symbolic=False)
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
                consts[d.name] = const_value(evaluate(d.binding, num_env), d.name)
            except BuildError as exc:
                waiting.append(d)
                error = error or exc
        if len(waiting) == len(pending):
            raise error
        pending = waiting

    def dims_of(d: Decl) -> list[int]:
        out = []
        for e in d.dims:
            v = const_value(evaluate(e, num_env), f"dimension of {d.name}")
            out.append(int(v))
        return out

    values: dict = dict(consts)
    t = ca.SX.sym("time")
    values["time"] = t
    env = Env(values, symbolic=True)

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
            v = const_value(evaluate(d.binding, env), d.name)
            values[d.name] = v
            continue
        dims = dims_of(d)
        names = _scalar_names(d, dims)
        if d.prefix == "parameter":
            syms = param_syms[d.name]
            if d.binding is None:
                raise BuildError(f"parameter {d.name} has no value")
            bval = evaluate(d.binding, env)
            bflat = flatten(bval) if dims else [bval]
            if len(bflat) != len(names):
                raise BuildError(f"parameter {d.name}: binding has {len(bflat)} elements, expected {len(names)}")
            for n, s, b, lim in zip(names, syms, bflat, bounds(d, names)):
                if is_sym(b) and ca.symvar(b):
                    calc.append(Variable(n, "calculated", attr_str(d, "unit"), d.description, 0.0, **lim))
                    q_syms.append(s)
                    q_exprs.append(b)
                else:
                    val = float(ca.evalf(b)) if is_sym(b) else float(b)
                    params.append(Variable(n, "parameter", attr_str(d, "unit"), d.description, val, **lim))
                    p_syms.append(s)
        elif d.prefix == "input" and d.binding is None and "." not in d.name:
            syms = [ca.SX.sym(n) for n in names]
            values[d.name] = syms if dims else syms[0]
            start = d.attrs.get("start")
            sval = evaluate(start, env) if start is not None else 0.0
            sflat = flatten(sval) if isinstance(sval, list) else [sval] * len(names)
            for n, s, sv, lim in zip(names, syms, sflat, bounds(d, names)):
                sv = const_value(sv, f"start of input {n}")
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
                idx = const_value(evaluate(arg[2][0], env), "der() index")
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
        if not is_sym(s) or not s.is_symbolic():
            raise BuildError("der() of an expression is outside the supported subset")
        return s.__hash__()

    # Residuals
    residuals: list[tuple[ca.SX, str]] = []
    env.lookups = []
    for eq in flat.equations:
        lhs = eval_with_der(eq.lhs, env, der_eval)
        rhs = eval_with_der(eq.rhs, env, der_eval)
        diff = elementwise(lambda a, b: a - b, lhs, rhs)
        for r in flatten(diff):
            residuals.append((ca.SX(r), eq.text))
    lookups, env.lookups = env.lookups, None

    unknowns = dx_list + alg_syms
    unknown_names = [f"der({v.name})" for v in states] + alg_names
    if len(residuals) != len(unknowns):
        raise BuildError(f"model is not balanced: {len(residuals)} scalar equations for "
                         f"{len(unknowns)} unknowns (derivatives and algebraic variables)")

    solution = sort_and_solve(residuals, unknowns, unknown_names)

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
        sflat = flatten(sval) if isinstance(sval, list) else [sval] * len(names)
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


def _bounds(d: Decl, names: list[str], env: Env) -> list[dict]:
    """``min``/``max``/``nominal`` of each scalar of a declaration, as floats (absent: not set).

    The attribute may be a scalar (``each min = 0``, or a plain scalar on a scalar) or an array
    with one value per element, and must evaluate to constants at build time."""
    out: list[dict] = [{} for _ in names]
    for key in ("min", "max", "nominal"):
        e = d.attrs.get(key)
        if e is None:
            continue
        v = evaluate(e, env)
        vals = flatten(v) if isinstance(v, list) else [v] * len(names)
        if len(vals) != len(names):
            raise BuildError(f"{d.name}: attribute {key} has {len(vals)} elements, expected {len(names)}")
        for o, x, n in zip(out, vals, names):
            x = float(const_value(x, f"attribute {key} of {n}"))
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
