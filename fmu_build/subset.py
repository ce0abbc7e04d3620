"""Check that a Modelica model stays inside the subset this builder supports.

rumoca's flattening silently drops some constructs (``when`` clauses, for example), so the
source is scanned before flattening.  Only the classes reachable from the requested model
are scanned, and every problem is reported with its file and line.

Supported subset (documented in fmu_build/README.md):

* ``model``/``block``/``connector``/``record``/``package`` classes, ``extends`` with
  modifiers, components, ``connect`` equations (flattened by rumoca);
* ``parameter Real`` scalars and 1-D arrays (literal or expression bindings; expression
  bindings become calculated parameters), ``parameter Integer`` as structural constants;
* continuous ``Real`` variables, ``input``/``output`` Real, ``der()`` of variables;
* equations that can be sorted into assignments (no algebraic loops), each linear in the
  variable it is solved for;
* ``if``-expressions and ``div mod rem floor ceil integer`` of time-varying values only
  inside ``noEvent(...)`` (so an array may be indexed by ``noEvent(integer(...))``); ``abs``, ``min``, ``max``, ``atan2``
  and the usual elementary functions; array comprehensions and ``sum``.

Declaration equations of time-varying variables (``Real y = expr;``) are checked like
equations; parameter bindings and modifiers are not (they are evaluated once, without events).
"""
from __future__ import annotations

import re
from pathlib import Path

from twin.errors import ModelicaSubsetError

_CLASS_RE = re.compile(
    r"\b(?:(?:partial|encapsulated|final|replaceable|expandable)\s+)*"
    r"(model|block|connector|record|package|function|type|class|operator)\s+([A-Za-z_]\w*)\b(?!\s*=)",
)
_TOKEN_RE = re.compile(r'"(?:[^"\\]|\\.)*"|//[^\n]*|/\*.*?\*/|[A-Za-z_]\w*|\S', re.S)

# name -> reason
_FORBIDDEN_KEYWORDS = {
    "when": "when-clauses create discrete events, which the fixed-step co-simulation wrapper cannot handle",
    "elsewhen": "when-clauses create discrete events",
    "algorithm": "algorithm sections are not supported; write equations",
    "discrete": "discrete variables are not supported",
    "external": "external functions are not supported",
    "inner": "inner/outer lookup is not supported",
    "outer": "inner/outer lookup is not supported",
    "stream": "stream connectors are not supported",
}
_FORBIDDEN_CALLS = {
    "pre": "pre() needs discrete events", "edge": "edge() needs discrete events",
    "change": "change() needs discrete events", "sample": "sample() needs discrete events",
    "reinit": "reinit() needs discrete events", "initial": "initial() needs event handling",
    "terminal": "terminal() needs event handling", "delay": "delay() needs a history buffer",
    "mod": "mod() of a time-varying expression generates events; inside noEvent(...) it does not",
    "rem": "rem() of a time-varying expression generates events; inside noEvent(...) it does not",
    "floor": "floor() of a time-varying expression generates events; inside noEvent(...) it does not",
    "ceil": "ceil() of a time-varying expression generates events; inside noEvent(...) it does not",
    "integer": "integer() of a time-varying expression generates events; inside noEvent(...) it does not",
    "div": "div() of a time-varying expression generates events; inside noEvent(...) it does not",
    "spatialDistribution": "spatialDistribution() is not supported",
    "homotopy": "homotopy() is not supported",
    "semiLinear": "semiLinear() is not supported",
}

# Allowed on time-varying arguments inside noEvent(...): evaluated as written, without events
# (e.g. an array index tooth_pit_field[noEvent(integer(...))]).
_NOEVENT_CALLS = {"mod", "rem", "floor", "ceil", "integer", "div"}

_DISCRETE_TYPES = ("Boolean", "Integer", "String")
# `type X = Real(...)`, `model A = B(...)`, `import X = A.B`: a `=` that is no declaration equation
_SHORT_DEFINITION = {"model", "block", "connector", "record", "package", "function", "type", "class",
                     "operator", "import"}
_DECL_BOUNDARY = {";", "public", "protected", "equation", "algorithm",
                  "model", "block", "connector", "record", "package", "class"}


def _is_parameter_decl(toks: list, i: int) -> bool:
    """True if the declaration whose type token is ``toks[i]`` has a parameter/constant prefix."""
    j = i - 1
    while j >= 0 and toks[j].text not in _DECL_BOUNDARY:
        if toks[j].text in ("parameter", "constant"):
            return True
        j -= 1
    return False


class _Tok:
    __slots__ = ("text", "line", "file")

    def __init__(self, text, line, file):
        self.text, self.line, self.file = text, line, file


def _tokens(text: str, file: str) -> list[_Tok]:
    out = []
    line = 1
    pos = 0
    for m in _TOKEN_RE.finditer(text):
        line += text.count("\n", pos, m.start())
        pos = m.start()
        tok = m.group(0)
        if not (tok.startswith("//") or tok.startswith("/*")):
            out.append(_Tok(tok, line, file))
    return out


def _class_spans(path: Path) -> dict[str, list[_Tok]]:
    """Map class short name -> its tokens, for every class defined in a .mo file."""
    toks = _tokens(path.read_text(encoding="utf-8"), str(path))
    spans: dict[str, list[_Tok]] = {}
    stack: list[tuple[str, int]] = []
    kinds = {"model", "block", "connector", "record", "package", "function", "type", "class", "operator"}
    i = 0
    while i < len(toks):
        t = toks[i].text
        if t in kinds and i + 1 < len(toks) and re.match(r"[A-Za-z_]\w*$", toks[i + 1].text):
            # `type X = Real(...)` and short class definitions have no `end`
            if i + 2 < len(toks) and toks[i + 2].text == "=":
                spans[toks[i + 1].text] = toks[i:i + 3]
                i += 2
                continue
            if i > 0 and toks[i - 1].text == "end":
                i += 1
                continue
            stack.append((toks[i + 1].text, i))
            i += 2
            continue
        if t == "end" and i + 1 < len(toks) and stack and toks[i + 1].text == stack[-1][0]:
            name, start = stack.pop()
            spans[name] = toks[start:i + 2]
            i += 2
            continue
        i += 1
    return spans


def _own_tokens(toks: list[_Tok], spans) -> list[_Tok]:
    """``toks`` without the tokens of complete class definitions nested inside it."""
    mine = {id(t) for t in toks}
    nested: set[int] = set()
    for other in spans:
        # full definitions end with `end Name`; short ones (`type X = ...`) stay in place
        if (other is not toks and len(other) < len(toks) and len(other) > 3 and other[-2].text == "end"
                and id(other[0]) in mine):
            nested.update(id(t) for t in other)
    return [t for t in toks if id(t) not in nested] if nested else toks


def check_subset(root: Path, model: str) -> None:
    """Raise :class:`ModelicaSubsetError` listing every unsupported construct used by ``model``."""
    classes: dict[str, list[_Tok]] = {}
    for f in sorted(Path(root).rglob("*.mo")):
        for name, toks in _class_spans(f).items():
            classes.setdefault(name, toks)
    short = model.split(".")[-1]
    if short not in classes:
        return  # rumoca reports unknown models itself
    seen: set[str] = set()
    todo = [short]
    problems: list[tuple[str, int, str, str]] = []
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        toks = classes[name]
        if toks and toks[0].text == "function":
            problems.append((toks[0].file, toks[0].line, "function",
                             f"user-defined function {name} is not supported; inline it as equations"))
            continue
        # Classes nested in this one (e.g. the models of a one-file package) are scanned only if
        # something refers to them, so an unused sibling cannot fail the build.
        toks = _own_tokens(toks, classes.values())
        problems += _scan(toks, nested={n for n in classes if n != name})
        for t in toks:
            for part in t.text.split("."):
                if part in classes and part not in seen and part != name:
                    todo.append(part)
    if problems:
        # de-duplicate while keeping order
        uniq = list(dict.fromkeys(problems))
        raise ModelicaSubsetError(uniq)


def _scan(toks: list[_Tok], nested: set[str]) -> list[tuple[str, int, str, str]]:
    problems = []
    in_equations = False
    in_binding = False              # inside `Real y = <expr>;` of a time-varying variable
    depth_noevent: list[int] = []   # paren depths at which a noEvent( was opened
    depth = 0
    brace = 0
    n = len(toks)
    for i, t in enumerate(toks):
        s = t.text
        prev = toks[i - 1].text if i else ""
        nxt = toks[i + 1].text if i + 1 < n else ""
        if s == ";" and depth == 0 and brace == 0:
            in_binding = False
            continue
        if s == "equation":
            in_equations = True
            if prev == "initial":
                problems.append((t.file, t.line, "initial equation",
                                 "initial equations are not supported; give states start values "
                                 "(parameter expressions are allowed)"))
            continue
        if s in ("public", "protected"):
            continue
        if s == "algorithm" and prev == "initial":
            problems.append((t.file, t.line, "initial algorithm", "initial algorithms are not supported"))
            continue
        if s in _FORBIDDEN_KEYWORDS and prev != "end":
            problems.append((t.file, t.line, s, _FORBIDDEN_KEYWORDS[s]))
            continue
        if (s in _DISCRETE_TYPES and not in_equations and prev != "."
                and (nxt == "[" or re.match(r"[A-Za-z_]\w*$", nxt)) and not _is_parameter_decl(toks, i)):
            # A time-varying Boolean/Integer/String only changes at events; flattening would
            # accept it and the error would surface later without a source line.
            problems.append((t.file, t.line, f"{s} variable",
                             f"{s} variables that vary in time are discrete and need events; only "
                             f"parameter/constant {s} (structural) is supported"))
            continue
        if s == "(":
            depth += 1
            if prev == "noEvent":
                depth_noevent.append(depth)
            continue
        if s == ")":
            if depth_noevent and depth_noevent[-1] == depth:
                depth_noevent.pop()
            depth -= 1
            continue
        if s == "{":
            brace += 1
            continue
        if s == "}":
            brace -= 1
            continue
        if s == "end" and nxt in ("if", "for", "when", "while"):
            continue
        if prev == "end":
            if s not in ("if", "for", "when", "while"):
                in_equations = False
            continue
        if (s == "=" and not in_equations and depth == 0 and brace == 0 and i >= 2
                and toks[i - 2].text not in _SHORT_DEFINITION and not _is_parameter_decl(toks, i)):
            # A declaration equation of a time-varying variable is an equation like any other.
            in_binding = True
            continue
        if not (in_equations or in_binding):
            continue
        if s == "if" and not depth_noevent:
            what = "if-equation" if depth == 0 and brace == 0 and prev in (";", "equation", "then", "else") else "if-expression"
            # An if-equation cannot be wrapped in noEvent(); point to the equivalent expression form.
            fix = ("write a single equation with noEvent(if ... then ... else ...)" if what == "if-equation"
                   else "wrap the expression in noEvent(...)")
            problems.append((t.file, t.line, what, f"an {what} outside noEvent() generates events; {fix}"))
        elif s == "for" and depth == 0 and brace == 0:
            problems.append((t.file, t.line, "for-loop equation",
                             "for-loop equations are not supported; use an array comprehension {... for i in 1:n}"))
        elif s == "while":
            problems.append((t.file, t.line, "while", "while loops are not supported"))
        elif s in _FORBIDDEN_CALLS and nxt == "(" and prev != "." and not (s in _NOEVENT_CALLS and depth_noevent):
            problems.append((t.file, t.line, f"{s}()", _FORBIDDEN_CALLS[s]))
        elif s == "der" and nxt == "(" and i + 3 < n and toks[i + 3].text != ")":
            # der(a.b) tokenizes as der ( a . b ) ; der(x[1]) as der ( x [ 1 ] ) -- allow both
            j = i + 2
            ok = True
            while j < n and toks[j].text != ")":
                if toks[j].text not in (".", "[", "]") and not re.match(r"[A-Za-z_0-9]\w*$", toks[j].text):
                    ok = False
                    break
                j += 1
            if not ok:
                problems.append((t.file, t.line, "der(expression)",
                                 "der() of an expression is not supported; introduce a variable"))
    return problems
