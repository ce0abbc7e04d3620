"""fmu_build.symbolic: equation sorting into a states-only ODE, and what it refuses.

These tests stop before code generation (rumoca -> flat parser -> CasADi functions), so they
need no C compiler; the CasADi functions are evaluated numerically.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import fmu_build
from fmu_build.flat import parse_flat
from fmu_build.symbolic import build_ode
from twin.errors import BuildError

REPO = Path(__file__).resolve().parents[2]


def _ode(root: Path, model: str):
    return build_ode(parse_flat(fmu_build.flatten(root, model)))


def _names(variables) -> list[str]:
    return [v.name for v in variables]


def test_two_mass_oscillator_becomes_its_linear_ode(two_mass):
    ode = _ode(REPO / "modelica", "GearTwin.Examples.TwoMassOscillator")
    assert _names(ode.states) == ["x1", "v1", "x2", "v2"]
    assert _names(ode.inputs) == ["force"]
    assert _names(ode.outputs) == ["a2", "position2"]
    assert _names(ode.parameters) == ["m1", "m2", "k1", "k12", "d1"]
    assert _names(ode.calculated) == ["f1"]
    assert [v.start for v in ode.parameters] == [1.0, 0.5, 100.0, 50.0, 0.2]
    assert [v.start for v in ode.states] == list(two_mass.x0)

    rng = np.random.default_rng(1)
    for _ in range(5):
        params = dict(zip(two_mass.defaults, rng.uniform(0.5, 2.0, 5) * list(two_mass.defaults.values())))
        p = np.array(list(params.values()))
        q = np.array(ode.derived(p)).ravel()
        assert q == pytest.approx([math.sqrt(params["k1"] / params["m1"]) / (2 * math.pi)], rel=1e-15)
        x, u, t = rng.normal(size=4), rng.normal(), rng.uniform(0, 1)
        xdot = np.array(ode.rhs(t, x, u, p, q)).ravel()
        expected = (two_mass.matrix(**params) @ [*x, u])[:4]
        assert np.allclose(xdot, expected, rtol=1e-14, atol=1e-14)
        y = np.array(ode.outputs_fn(t, x, u, p, q)).ravel()
        assert np.allclose(y, [expected[3], x[2]], rtol=1e-14, atol=1e-14)   # a2 = der(v2), position2 = x2
        assert np.array(ode.init(p, q)).ravel().tolist() == list(two_mass.x0)


def test_equations_in_any_order_are_sorted_and_solved(tmp_path, write_package):
    """An algebraic chain written backwards, one equation with a non-unit coefficient."""
    write_package(tmp_path, "Chain", """
        model M
          parameter Real g = 3 "Gain";
          input Real u(start = 0);
          Real a;
          Real b;
          Real c;
          Real x(start = 2, fixed = true);
          output Real y;
        equation
          y = c * 2;
          c = b + a;
          b = g * a - x;
          2 * a = u;
          der(x) = -c * x;
        end M;
    """)
    ode = _ode(tmp_path, "Chain.M")
    assert _names(ode.states) == ["x"] and _names(ode.outputs) == ["y"]
    for x, u, g in [(2.0, 0.5, 3.0), (-1.0, 4.0, 0.5), (0.3, -2.0, 7.0)]:
        a = u / 2
        c = (g * a - x) + a
        assert float(ode.rhs(0.0, x, u, g, [])) == pytest.approx(-c * x, rel=1e-14)
        assert float(ode.outputs_fn(0.0, x, u, g, [])) == pytest.approx(2 * c, rel=1e-14)


def test_time_varying_index_looks_up_exactly(tmp_path, write_package):
    """f[noEvent(integer(...))] reads the element the Modelica expression names (1-based,
    mod() as in Modelica for negative values too), one lookup call per array."""
    write_package(tmp_path, "Look", """
        model M
          parameter Integer n = 5;
          parameter Real f[n] = {10.0 * j for j in 1:n};
          parameter Real g[2 * n] = fill(0.0, 2 * n);
          Real x(start = 0, fixed = true);
          Real k "Integer valued";
          output Real y;
          output Real z;
        equation
          der(x) = 1;
          k = noEvent(mod(integer(x * 3), n)) + 1;
          y = f[noEvent(integer(k))] + g[noEvent(integer(k)) + n];
          z = f[noEvent(min(integer(abs(x)), n - 1)) + 1] * 2;
        end M;
    """)
    ode = _ode(tmp_path, "Look.M")
    rng = np.random.default_rng(3)
    f, g = rng.normal(size=5), rng.normal(size=10)
    p = np.concatenate([f, g])
    for x in [0.0, 0.34, 1.0, 2.99, 7.2, -0.2, -4.01]:
        k = math.floor(x * 3) % 5                               # Python % is Modelica's mod
        y, z = np.array(ode.outputs_fn(0.0, x, [], p, [])).ravel()
        assert y == f[k] + g[k + 5]                             # exact: a lookup, not a weighted sum
        assert z == f[min(math.floor(abs(x)), 4)] * 2
    expression = str(ode.outputs_fn.call(ode.outputs_fn.sx_in())[0])
    assert expression.count("lookup_5_2(") == 1 and expression.count("lookup_10_1(") == 1


def test_index_that_needs_its_own_lookup_is_an_algebraic_loop(tmp_path, write_package):
    write_package(tmp_path, "Look", """
        model M
          parameter Real f[3] = {1, 2, 3};
          Real x(start = 0, fixed = true);
          Real k;
          output Real y;
        equation
          der(x) = 1;
          k = x * 2;
          y = f[noEvent(integer(f[noEvent(integer(y))]))];
        end M;
    """)
    with pytest.raises(BuildError, match="algebraic loop through an array index"):
        _ode(tmp_path, "Look.M")


def _loop_package(write_package, root: Path, equations: str, decls: str):
    write_package(root, "Bad", f"""
        model M
          input Real x(start = 1);
          Real s(start = 0, fixed = true);
          {decls}
        equation
          der(s) = -s + x;
          {equations}
        end M;
    """)


def test_algebraic_loop_is_refused_naming_its_equations(tmp_path, write_package):
    _loop_package(write_package, tmp_path, "a = b + 1;\n          b = a*0.5 + x;", "Real a;\n          Real b;")
    with pytest.raises(BuildError, match="algebraic loop") as info:
        fmu_build.build_fmu("Bad.M", tmp_path, tmp_path / "out")
    message = str(info.value)
    unknowns = re.search(r"unknowns (.*?) appear", message).group(1).split(", ")
    assert set(unknowns) == {"a", "b"}
    assert re.search(r"a = \(?b \+ 1\)?", message) and re.search(r"b = \(*a \* 0\.5\)? \+ x", message)
    assert not (tmp_path / "out" / "Bad.M.fmu").exists()


def test_nonlinear_equation_is_refused_naming_equation_and_variable(tmp_path, write_package):
    _loop_package(write_package, tmp_path, "y*y = x;", "output Real y;")
    with pytest.raises(BuildError) as info:
        fmu_build.build_fmu("Bad.M", tmp_path, tmp_path / "out")
    message = str(info.value)
    assert "nonlinear in its unknown y" in message
    assert re.search(r"'\(?y \* y\)? = x'", message), message


def test_nonlinear_in_known_values_is_fine(tmp_path, write_package):
    """Only the solved-for unknown must enter linearly; states and inputs may enter any way."""
    _loop_package(write_package, tmp_path, "y = sin(s) * s + x * x;\n          der(z) = -z * z;",
                  "output Real y;\n          Real z(start = 1, fixed = true);")
    ode = _ode(tmp_path, "Bad.M")
    assert _names(ode.states) == ["s", "z"]
    xdot = np.array(ode.rhs(0.0, [0.5, 2.0], 3.0, [], [])).ravel()
    assert xdot.tolist() == [-0.5 + 3.0, -4.0]
    assert float(ode.outputs_fn(0.0, [0.5, 2.0], 3.0, [], [])) == pytest.approx(math.sin(0.5) * 0.5 + 9.0)


def test_unbalanced_model_is_refused(tmp_path, write_package):
    # rumoca usually catches this first; symbolic.build_ode has the same check as a backstop
    _loop_package(write_package, tmp_path, "y = 2 * s;\n          y = 3 * x;", "output Real y;")
    with pytest.raises(BuildError, match=r"(unbalanced|not balanced)\W.*3 (scalar )?equations(,| for) 2 unknowns"):
        _ode(tmp_path, "Bad.M")
