"""Parser for the flat Modelica that rumoca renders (``render("flat-modelica")``).

The flat form is regular: one ``class``, one declaration per line, one ``equation``
section of fully parenthesised equations.  This module turns it into a small AST
(:class:`Decl`, :class:`Equation`, expression tuples) that :mod:`fmu_build.symbolic`
evaluates, numerically for parameters and symbolically (CasADi) for equations.

Expression nodes are tuples: ``("num", v)``, ``("ref", name, [index_expr...])``,
``("call", fname, [args], named)``, ``("bin", op, a, b)``, ``("neg", a)``,
``("not", a)``, ``("if", [(cond, value)...], else_value)``, ``("array", [items])``,
``("comp", expr, [(iter, range_expr)...])``, ``("range", start, stop)``,
``("str", s)``, ``("bool", b)``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from twin.errors import BuildError

_TOKEN = re.compile(
    r"""
    (?P<ws>\s+)
  | (?P<str>"(?:[^"\\]|\\.)*")
  | (?P<num>(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)
  | (?P<op>\.\^|\.\*|\./|\.\+|\.-|==|<>|<=|>=|[-+*/^()\[\]{},;=<>:])
    """,
    re.VERBOSE,
)

KEYWORDS = {"and", "or", "not", "if", "then", "elseif", "else", "for", "in", "end", "true", "false"}


@dataclass
class Token:
    kind: str
    text: str
    pos: int


def tokenize(text: str) -> list[Token]:
    out: list[Token] = []
    i = 0
    while i < len(text):
        m = _TOKEN.match(text, i)
        if not m:
            raise BuildError(f"flat Modelica: cannot tokenize near {text[i:i + 40]!r}")
        kind = m.lastgroup
        if kind != "ws":
            out.append(Token(kind, m.group(kind), i))
        i = m.end()
    return out


@dataclass
class Decl:
    """One declared variable of the flat model."""

    name: str
    type: str                       # Real, Integer, Boolean
    prefix: str                     # parameter, constant, input, output, or ""
    dims: list                      # list of dimension expressions
    attrs: dict = field(default_factory=dict)   # start, unit, fixed, min, max, ...: expr
    binding: tuple | None = None
    description: str = ""


@dataclass
class Equation:
    lhs: tuple
    rhs: tuple
    text: str


@dataclass
class FlatModel:
    name: str
    description: str
    decls: list[Decl]
    equations: list[Equation]


class _Parser:
    def __init__(self, tokens: list[Token], src: str):
        self.t = tokens
        self.i = 0
        self.src = src

    # -- token helpers ---------------------------------------------------------------------
    def peek(self, k: int = 0) -> Token | None:
        j = self.i + k
        return self.t[j] if j < len(self.t) else None

    def at(self, text: str) -> bool:
        tok = self.peek()
        return tok is not None and tok.text == text and tok.kind in ("op", "name")

    def take(self, text: str | None = None) -> Token:
        tok = self.peek()
        if tok is None:
            raise BuildError("flat Modelica: unexpected end of input")
        if text is not None and tok.text != text:
            raise BuildError(f"flat Modelica: expected {text!r} but found {tok.text!r} near "
                             f"{self.src[max(0, tok.pos - 30):tok.pos + 30]!r}")
        self.i += 1
        return tok

    # -- expressions ---------------------------------------------------------------------------
    def expr(self):
        if self.at("if"):
            self.take("if")
            branches = [(self.expr(), None)]
            self.take("then")
            branches[0] = (branches[0][0], self.expr())
            while self.at("elseif"):
                self.take("elseif")
                c = self.expr()
                self.take("then")
                branches.append((c, self.expr()))
            self.take("else")
            return ("if", branches, self.expr())
        return self.range_expr()

    def range_expr(self):
        a = self.or_expr()
        if self.at(":"):
            self.take(":")
            b = self.or_expr()
            return ("range", a, b)
        return a

    def or_expr(self):
        a = self.and_expr()
        while self.at("or"):
            self.take()
            a = ("bin", "or", a, self.and_expr())
        return a

    def and_expr(self):
        a = self.not_expr()
        while self.at("and"):
            self.take()
            a = ("bin", "and", a, self.not_expr())
        return a

    def not_expr(self):
        if self.at("not"):
            self.take()
            return ("not", self.not_expr())
        return self.rel()

    def rel(self):
        a = self.arith()
        tok = self.peek()
        if tok is not None and tok.kind == "op" and tok.text in ("<", "<=", ">", ">=", "==", "<>"):
            self.take()
            return ("bin", tok.text, a, self.arith())
        return a

    def arith(self):
        if self.at("-") or self.at("+"):
            sign = self.take().text
            a = self.term()
            if sign == "-":
                a = ("neg", a)
        else:
            a = self.term()
        while self.at("+") or self.at("-") or self.at(".+") or self.at(".-"):
            op = self.take().text.lstrip(".")
            a = ("bin", op, a, self.term())
        return a

    def term(self):
        a = self.factor()
        while self.at("*") or self.at("/") or self.at(".*") or self.at("./"):
            op = self.take().text
            a = ("bin", op, a, self.factor())
        return a

    def factor(self):
        a = self.primary()
        if self.at("^") or self.at(".^"):
            op = self.take().text
            b = self.factor() if not (self.at("-") or self.at("+")) else self.arith_unary()
            return ("bin", "^" if op == "^" else ".^", a, b)
        return a

    def arith_unary(self):
        sign = self.take().text
        a = self.primary()
        return ("neg", a) if sign == "-" else a

    def primary(self):
        tok = self.peek()
        if tok is None:
            raise BuildError("flat Modelica: unexpected end of expression")
        if tok.kind == "num":
            self.take()
            return ("num", float(tok.text))
        if tok.kind == "str":
            self.take()
            return ("str", tok.text[1:-1])
        if tok.text == "(":
            self.take("(")
            e = self.expr()
            self.take(")")
            return e
        if tok.text == "{":
            self.take("{")
            if self.at("}"):
                self.take("}")
                return ("array", [])
            first = self.expr()
            if self.at("for"):
                iters = self.for_iters()
                self.take("}")
                return ("comp", first, iters)
            items = [first]
            while self.at(","):
                self.take(",")
                items.append(self.expr())
            self.take("}")
            return ("array", items)
        if tok.kind == "name":
            if tok.text in ("true", "false"):
                self.take()
                return ("bool", tok.text == "true")
            if tok.text in KEYWORDS:
                raise BuildError(f"flat Modelica: unexpected keyword {tok.text!r} near "
                                 f"{self.src[max(0, tok.pos - 40):tok.pos + 40]!r}")
            self.take()
            name = tok.text
            if self.at("("):
                self.take("(")
                args, named = [], {}
                if not self.at(")"):
                    while True:
                        if self.peek().kind == "name" and self.peek(1) is not None and self.peek(1).text == "=":
                            key = self.take().text
                            self.take("=")
                            named[key] = self.expr()
                        else:
                            a = self.expr()
                            if self.at("for"):
                                a = ("comp", a, self.for_iters())
                            args.append(a)
                        if self.at(","):
                            self.take(",")
                            continue
                        break
                self.take(")")
                return ("call", name, args, named)
            subs = []
            if self.at("["):
                self.take("[")
                subs.append(self.expr())
                while self.at(","):
                    self.take(",")
                    subs.append(self.expr())
                self.take("]")
            # rumoca renders record/array element access like a[1].b; keep it as one name
            return ("ref", name, subs)
        raise BuildError(f"flat Modelica: unexpected token {tok.text!r} near "
                         f"{self.src[max(0, tok.pos - 40):tok.pos + 40]!r}")

    def for_iters(self):
        self.take("for")
        iters = []
        while True:
            it = self.take().text
            self.take("in")
            iters.append((it, self.range_expr()))
            if self.at(","):
                self.take(",")
                continue
            break
        return iters

    # -- declarations ------------------------------------------------------------------------
    def modification(self) -> dict:
        attrs = {}
        self.take("(")
        while not self.at(")"):
            if self.at("each") or self.at("final"):
                self.take()
            key = self.take().text
            self.take("=")
            attrs[key] = self.expr()
            if self.at(","):
                self.take(",")
        self.take(")")
        return attrs


_DECL_START = re.compile(r"^\s*(?:(parameter|constant|input|output|discrete)\s+)?(Real|Integer|Boolean|String)\b")


def parse_flat(text: str) -> FlatModel:
    """Parse rumoca's flat Modelica into a :class:`FlatModel`."""
    lines = text.splitlines()
    if not lines or not lines[0].startswith("class "):
        raise BuildError("flat Modelica: expected the rendering to start with 'class'")
    head = tokenize(lines[0])
    name = head[1].text
    description = head[2].text[1:-1] if len(head) > 2 and head[2].kind == "str" else ""
    try:
        eq_line = next(i for i, ln in enumerate(lines) if ln.strip() == "equation")
    except StopIteration:
        eq_line = len(lines) - 1
    decl_text = "\n".join(lines[1:eq_line])
    eq_text = "\n".join(lines[eq_line + 1:-1]) if eq_line < len(lines) - 1 else ""

    decls = []
    for stmt in _split_statements(decl_text):
        m = _DECL_START.match(stmt)
        if not m:
            raise BuildError(f"flat Modelica: unsupported declaration {stmt.strip()[:120]!r}")
        prefix, typ = m.group(1) or "", m.group(2)
        p = _Parser(tokenize(stmt[m.end():]), stmt)
        dims = []
        if p.at("["):
            p.take("[")
            dims.append(p.expr())
            while p.at(","):
                p.take(",")
                dims.append(p.expr())
            p.take("]")
        vname = p.take().text
        attrs = p.modification() if p.at("(") else {}
        binding = None
        if p.at("="):
            p.take("=")
            binding = p.expr()
        desc = ""
        if p.peek() is not None and p.peek().kind == "str":
            desc = p.take().text[1:-1]
        if p.peek() is not None:
            raise BuildError(f"flat Modelica: trailing text in declaration of {vname}: {stmt.strip()[:120]!r}")
        decls.append(Decl(vname, typ, prefix, dims, attrs, binding, desc))

    equations = []
    for stmt in _split_statements(eq_text):
        p = _Parser(tokenize(stmt), stmt)
        lhs = p.expr()
        p.take("=")
        rhs = p.expr()
        if p.peek() is not None:
            raise BuildError(f"flat Modelica: cannot read equation {stmt.strip()[:160]!r}")
        equations.append(Equation(lhs, rhs, stmt.strip()))
    return FlatModel(name, description, decls, equations)


def _split_statements(text: str) -> list[str]:
    """Split on top-level ';' (not inside strings)."""
    out, cur, in_str, esc = [], [], False, False
    for ch in text:
        if in_str:
            cur.append(ch)
            if esc:
                esc = False
            elif ch == "\\":
                esc = True
            elif ch == '"':
                in_str = False
            continue
        if ch == '"':
            in_str = True
            cur.append(ch)
        elif ch == ";":
            s = "".join(cur).strip()
            if s:
                out.append(s)
            cur = []
        else:
            cur.append(ch)
    tail = "".join(cur).strip()
    if tail:
        raise BuildError(f"flat Modelica: statement without ';': {tail[:120]!r}")
    return out
