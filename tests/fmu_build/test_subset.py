"""fmu_build.subset: every unsupported construct is reported with its file and line.

The models are written to tmp_path at test time.  The line expected in a report is marked
in the model text with a trailing ``// <-`` comment (comments are invisible to the scanner).
No C compiler is needed: the subset check runs before flattening and code generation.
"""
from __future__ import annotations

from pathlib import Path

import pytest

import fmu_build
from fmu_build.subset import check_subset
from twin.errors import BuildError, ModelicaSubsetError

REPO = Path(__file__).resolve().parents[2]
MARK = "// <-"


def _marked_lines(path: Path) -> list[int]:
    return [i for i, line in enumerate(path.read_text().splitlines(), start=1) if MARK in line]


# case id -> (construct reported, body of package Sub: model M plus helper classes)
CASES = {
    "when": ("when", """
        model M
          Real x(start = 1, fixed = true);
        equation
          der(x) = -x;
          when x < 0.5 then // <-
            reinit(x, 1);
          end when;
        end M;
    """),
    "algorithm": ("algorithm", """
        model M
          Real x(start = 1, fixed = true);
          Real y;
        equation
          der(x) = -x;
        algorithm // <-
          y := 2 * x;
        end M;
    """),
    "function": ("function", """
        model M
          Real x(start = 1, fixed = true);
        equation
          der(x) = -twice(x);
        end M;
        function twice "User function" // <-
          input Real u;
          output Real v;
        algorithm
          v := 2 * u;
        end twice;
    """),
    "initial equation": ("initial equation", """
        model M
          Real x;
        initial equation // <-
          x = 1;
        equation
          der(x) = -x;
        end M;
    """),
    "if-expression": ("if-expression", """
        model M
          Real x(start = 1, fixed = true);
        equation
          der(x) =
            if x > 0 then -x else 0; // <-
        end M;
    """),
    "if-equation": ("if-equation", """
        model M
          Real x(start = 1, fixed = true);
        equation
          if x > 0 then // <-
            der(x) = -x;
          else
            der(x) = 0;
          end if;
        end M;
    """),
    "for-loop equation": ("for-loop equation", """
        model M
          Real x[2](each start = 1, each fixed = true);
        equation
          for i in 1:2 loop // <-
            der(x[i]) = -x[i];
          end for;
        end M;
    """),
    "mod()": ("mod()", """
        model M
          Real x(start = 1, fixed = true);
        equation
          der(x) = -mod(x, 0.3); // <-
        end M;
    """),
    "pre()": ("pre()", """
        model M
          Real x(start = 1, fixed = true);
        equation
          der(x) = -pre(x); // <-
        end M;
    """),
    "Boolean variable": ("Boolean variable", """
        model M
          Real x(start = 1, fixed = true);
          Boolean fast; // <-
        equation
          fast = x > 0.5;
          der(x) = -x;
        end M;
    """),
    "Integer variable": ("Integer variable", """
        model M
          Real x(start = 1, fixed = true);
          Integer count; // <-
        equation
          count = 3;
          der(x) = -x;
        end M;
    """),
    "discrete": ("discrete", """
        model M
          Real x(start = 1, fixed = true);
          discrete Real level; // <-
        equation
          level = 1;
          der(x) = -x * level;
        end M;
    """),
    "der(expression)": ("der(expression)", """
        model M
          Real x(start = 1, fixed = true);
          Real y(start = 1, fixed = true);
        equation
          der(x * y) = -x; // <-
          der(y) = -y;
        end M;
    """),
    "if-expression in a declaration equation": ("if-expression", """
        model M
          Real x(start = 1, fixed = true);
          output Real high = if x > 0.5 then 1 else 0; // <-
        equation
          der(x) = -x;
        end M;
    """),
    "integer() index outside noEvent()": ("integer()", """
        model M
          parameter Real f[3] = {1, 2, 3};
          Real x(start = 1, fixed = true);
          output Real y;
        equation
          der(x) = 1;
          y = f[integer(x) + 1]; // <-
        end M;
    """),
    "mod() outside the noEvent() of an index": ("mod()", """
        model M
          parameter Real f[3] = {1, 2, 3};
          Real x(start = 1, fixed = true);
          output Real y;
        equation
          der(x) = 1;
          y = f[mod(noEvent(integer(x)), 3) + 1]; // <-
        end M;
    """),
    "mod() in a declaration equation": ("mod()", """
        model M
          Real x(start = 1, fixed = true);
          output Real phase(unit = "rad") = mod(x, // <- the call's line, not the statement's last
            0.3);
        equation
          der(x) = -x;
        end M;
    """),
}


@pytest.mark.parametrize("case", list(CASES))
def test_unsupported_construct_is_named_with_its_line(case, tmp_path, write_package):
    construct, body = CASES[case]
    path = write_package(tmp_path, "Sub", body)
    (line,) = _marked_lines(path)
    # through the public entry point: the check runs before rumoca and gcc
    with pytest.raises(ModelicaSubsetError) as info:
        fmu_build.build_fmu("Sub.M", tmp_path, tmp_path / "out")
    hits = [(ln, c) for f, ln, c, _ in info.value.problems if f == str(path)]
    assert (line, construct) in hits, info.value.problems
    assert f"{path}:{line}: unsupported construct '{construct}'" in str(info.value)
    assert isinstance(info.value, BuildError)
    assert not (tmp_path / "out" / "Sub.M.fmu").exists()


def test_all_problems_of_a_file_are_listed_at_once(tmp_path, write_package):
    path = write_package(tmp_path, "Sub", """
        model M "Four mistakes"
          Real x(start = 1, fixed = true);
          Boolean on; // <-
        equation
          on = x > 0;
          der(x) = -pre(x); // <-
          when x < 0.5 then // <-
          end when;
        algorithm // <-
        end M;
    """)
    with pytest.raises(ModelicaSubsetError) as info:
        check_subset(tmp_path, "Sub.M")
    found = [(ln, c) for _, ln, c, _ in info.value.problems]
    assert found == list(zip(_marked_lines(path), ["Boolean variable", "pre()", "when", "algorithm"]))
    assert {f for f, *_ in info.value.problems} == {str(path)}
    assert str(info.value).count("unsupported construct") == 4


def test_problems_in_used_classes_name_their_own_file(tmp_path, write_package):
    """Classes reached by extends/components are scanned in their files; unused ones are not."""
    base = write_package(tmp_path, "Parts", """
        partial model Base
          Real x(start = 1, fixed = true);
        equation
          der(x) = -mod(x, 2); // <-
        end Base;
        model Unused
          Real z(start = 1, fixed = true);
        equation
          when z < 0 then
          end when;
        end Unused;
    """)
    user = write_package(tmp_path, "Sub", """
        model M
          extends Parts.Base;
          Real y;
        equation
          y = if x > 1 then 1 else 0; // <-
        end M;
    """)
    with pytest.raises(ModelicaSubsetError) as info:
        check_subset(tmp_path, "Sub.M")
    found = sorted((Path(f).name, ln, c) for f, ln, c, _ in info.value.problems)
    assert found == sorted([("Parts.mo", _marked_lines(base)[0], "mod()"),
                            ("Sub.mo", _marked_lines(user)[0], "if-expression")])


def test_supported_constructs_pass(tmp_path, write_package):
    write_package(tmp_path, "Sub", """
        model M "Mentions when, algorithm and pre(x) only in strings and comments"
          parameter Integer n = 3 "Structural size; a when-clause would be rejected";
          parameter Boolean use_damping = true "Structural switch";
          parameter Real r = mod(7, 3) "mod() of parameters is evaluated at build time";
          parameter Real c[n] = {0.1 * i for i in 1:n};
          input Real u(start = 0);
          Real x(start = 1, fixed = true);
          output Real y;
        equation
          // an if-expression inside noEvent() is fine, so is der() of an array element
          der(x) = noEvent(if x > 0 then -x else 0) + sum(c) * u;
          y = noEvent(max(x, 0)) + abs(x) + atan2(x, 1.0) + c[noEvent(mod(integer(x), n)) + 1];
        end M;
        type Angle = Real(unit = "rad") "Short class definition: its '=' is no equation";
        model N "Declarations whose bindings are parameter expressions or inside noEvent()"
          parameter Integer n = 2;
          parameter Real p2 = if n > 2 then 1 else 0 "Parameter bindings are evaluated once, no events";
          Angle w(start = if n > 2 then 1 else 0, fixed = true) "Modifiers are parameter expressions";
          output Real y2 = noEvent(if w > 0 then w else -w);
        equation
          der(w) = -p2 * w;
        end N;
    """)
    check_subset(tmp_path, "Sub.M")
    check_subset(tmp_path, "Sub.N")


@pytest.mark.parametrize("model", ["GearTwin.Gearbox21", "GearTwin.Examples.TwoMassOscillator"])
def test_repository_models_are_inside_the_subset(model):
    check_subset(REPO / "modelica", model)
