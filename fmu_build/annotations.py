"""Class annotations read from Modelica source: the model's ``experiment`` and its library's metadata.

rumoca's flat model drops annotations, so they are read from the source file of the class:

- ``annotation(experiment(StartTime=..., StopTime=..., Interval=..., Tolerance=...))`` of the
  model (Modelica Language Specification 3.5, section 18.4) becomes the FMU's DefaultExperiment;
- ``annotation(version="...", __GearTwin(author="...", license="...", copyright="..."))`` of the
  top-level package (``version`` is the standard annotation of section 18.8; ``__GearTwin`` is a
  vendor annotation of this exporter) gives the FMU's version, author, license and copyright.

Only literal values (strings, numbers) are read; an annotation that cannot be read is a
:class:`~twin.errors.BuildError` naming the file.
"""
from __future__ import annotations

import re
from pathlib import Path

from twin.errors import BuildError

from .flat import Token, tokenize

#: The vendor annotation of the top-level package that carries the FMU metadata.
VENDOR = "__GearTwin"


def strip_comments(text: str) -> str:
    """Modelica source without ``//`` and ``/* */`` comments (strings are kept intact)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            out.append(" ")
            i = n if j < 0 else j + 2
        else:
            out.append(c)
            i += 1
    return "".join(out)


def _class_body(text: str, name: str) -> str | None:
    start = re.search(rf"\b(?:model|block|class|package|record|connector)\s+{re.escape(name)}\b", text)
    if not start:
        return None
    end = re.search(rf"\bend\s+{re.escape(name)}\s*;", text[start.end():])
    return text[start.end(): start.end() + end.start()] if end else None


def _parse_args(tokens: list[Token], i: int, where: str) -> tuple[dict, int]:
    """Parse ``( name = value | name(...) , ... )`` starting at the '(' at ``tokens[i]``."""
    out: dict = {}
    i += 1
    while i < len(tokens) and tokens[i].text != ")":
        if tokens[i].kind != "name":
            raise BuildError(f"{where}: cannot read the annotation near {tokens[i].text!r}")
        key = tokens[i].text
        i += 1
        if i < len(tokens) and tokens[i].text == "(":
            out[key], i = _parse_args(tokens, i, where)
        elif i < len(tokens) and tokens[i].text == "=":
            i += 1
            j, depth = i, 0
            while j < len(tokens) and not (depth == 0 and tokens[j].text in (",", ")")):
                depth += {"(": 1, "{": 1, "[": 1, ")": -1, "}": -1, "]": -1}.get(tokens[j].text, 0)
                j += 1
            out[key] = _literal(tokens[i:j])
            i = j
        else:
            out[key] = True
        if i < len(tokens) and tokens[i].text == ",":
            i += 1
    if i >= len(tokens):
        raise BuildError(f"{where}: unbalanced parentheses in an annotation")
    return out, i + 1


def _literal(tokens: list[Token]):
    """A string or a (signed) number; anything else is kept as its source text."""
    if len(tokens) == 1 and tokens[0].kind == "str":
        return tokens[0].text[1:-1].replace('\\"', '"')
    sign = 1.0
    body = tokens
    if body and body[0].text in ("-", "+"):
        sign = -1.0 if body[0].text == "-" else 1.0
        body = body[1:]
    if len(body) == 1 and body[0].kind == "num":
        return sign * float(body[0].text)
    return " ".join(t.text for t in tokens)


def class_annotation(source: Path, name: str) -> dict:
    """The annotation of class ``name`` (its last component, e.g. ``Gearbox21``) in ``source``.

    Annotations of nested classes and of declarations are not included. Returns ``{}`` when the
    class has none.
    """
    text = strip_comments(source.read_text(encoding="utf-8"))
    body = _class_body(text, name)
    if body is None:
        return {}
    # drop nested classes, so that their annotations are not taken for this one's
    for nested in re.finditer(r"\b(?:model|block|class|package|record|connector|function)\s+(\w+)\b", body):
        inner = _class_body(body, nested.group(1))
        if inner is not None:
            body = body.replace(inner, " ")
    try:
        tokens = tokenize(body)
    except BuildError as exc:
        raise BuildError(f"{source}: {exc}") from None
    found: dict = {}
    prev = ";"
    for k, tok in enumerate(tokens):
        # a class annotation is a statement of its own: after ';' or a section keyword
        if tok.text == "annotation" and prev in (";", "equation", "algorithm", "public", "protected") \
                and k + 1 < len(tokens) and tokens[k + 1].text == "(":
            args, _ = _parse_args(tokens, k + 1, str(source))
            found.update(args)
        prev = tok.text
    return found


def default_experiment(source: Path, name: str) -> dict[str, float]:
    """``{startTime, stopTime, stepSize, tolerance}`` from the class's ``experiment`` annotation
    (only the entries it gives), each a finite float; stop after start, step and tolerance > 0."""
    exp = class_annotation(source, name).get("experiment", {})
    if not isinstance(exp, dict):
        return {}
    names = {"StartTime": "startTime", "StopTime": "stopTime", "Interval": "stepSize", "Tolerance": "tolerance"}
    out: dict[str, float] = {}
    for key, value in exp.items():
        if key not in names:
            continue
        if not isinstance(value, float):
            raise BuildError(f"{source}: experiment({key} = {value}) of {name} must be a number")
        out[names[key]] = value
    if out.get("stopTime", float("inf")) <= out.get("startTime", 0.0):
        raise BuildError(f"{source}: experiment StopTime of {name} must be after its StartTime")
    for key in ("stepSize", "tolerance"):
        if key in out and not out[key] > 0:
            raise BuildError(f"{source}: experiment {key} of {name} must be > 0, got {out[key]}")
    return out


def library_metadata(modelica_dir: Path, model: str) -> dict[str, str]:
    """``version``, ``author``, ``license``, ``copyright`` from the top-level package's annotation."""
    top = model.split(".")[0]
    for cand in (modelica_dir / top / "package.mo", modelica_dir / f"{top}.mo"):
        if cand.exists():
            ann = class_annotation(cand, top)
            out = {}
            if isinstance(ann.get("version"), str):
                out["version"] = ann["version"]
            vendor = ann.get(VENDOR, {})
            if isinstance(vendor, dict):
                for key in ("author", "license", "copyright"):
                    if isinstance(vendor.get(key), str):
                        out[key] = vendor[key]
            return out
    return {}
