"""The architecture the layout promises: the product (twin/) never imports the independent
simulators it is validated against (rigs/) nor the benchmark scripts (bench/)."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
FORBIDDEN = ("rigs", "bench")


def imported_packages(source: str, filename: str) -> set[str]:
    """Top-level names of every module ``source`` imports, at any depth of the code
    (absolute imports; relative ones stay inside their package)."""
    found = set()
    for node in ast.walk(ast.parse(source, filename)):
        if isinstance(node, ast.Import):
            found |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module.split(".")[0])
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", None)) in (
                "import_module", "__import__") and node.args and isinstance(node.args[0], ast.Constant):
            found.add(str(node.args[0].value).split(".")[0])
    return found


def test_the_twin_never_imports_rigs_or_bench():
    modules = sorted((REPO / "twin").rglob("*.py"))
    assert len(modules) > 50
    offenders = {str(m.relative_to(REPO)): sorted(imported_packages(m.read_text(), str(m)) & set(FORBIDDEN))
                 for m in modules}
    assert {m: f for m, f in offenders.items() if f} == {}


@pytest.mark.parametrize("code, found", [
    ("import rigs.lumped", {"rigs"}),
    ("def f():\n    from bench.transfer import main\n", {"bench"}),
    ("import importlib\nimportlib.import_module('rigs.ltca')", {"importlib", "rigs"}),
    ("from . import rigs", set()),
])
def test_the_import_scan_sees_imports_anywhere_in_a_module(code, found):
    assert imported_packages(code, "<test>") == found
