"""What the ``twin`` sub-commands share: NAME=VALUE options, argument types, a local executor,
the library's warnings from a child process, and library modules imported when a handler runs
(so ``twin --help`` does not pay for numpy, fmpy or torch)."""
from __future__ import annotations

import argparse
import importlib
import math
import sys
import warnings
from collections.abc import Sequence
from types import ModuleType

from twin.errors import ParameterError, TwinWarning


def lib(name: str) -> ModuleType:
    """The library module ``name``, resolved through sys.modules at call time, so tests can substitute a module."""
    return importlib.import_module(name)


def parse_assignments(tokens: Sequence[str] | None, option: str) -> dict[str, str]:
    """Parse ``NAME=VALUE`` tokens into ``{name: text}``.

    The text is converted to the variable's type by the FMU (a number, ``true``/``false``, a
    string, an enumeration item by name), which refuses values that do not fit, by name.

    Raises
    ------
    ParameterError
        Missing ``=``, empty or blank-containing name, an empty value, or a name given twice;
        the message names the token.
    """
    out: dict[str, str] = {}
    for token in tokens or ():
        name, sep, text = token.partition("=")
        name = name.strip()
        if not sep or not name or any(c.isspace() for c in name):
            raise ParameterError(f"bad {option} '{token}': expected NAME=VALUE")
        if not text:
            raise ParameterError(f"bad {option} '{token}': no value after '='")
        if name in out:
            raise ParameterError(f"bad {option} '{token}': '{name}' given more than once")
        out[name] = text
    return out


def numbers(assignments: dict[str, str], option: str) -> dict[str, float]:
    """``NAME=VALUE`` texts that must be finite numbers (build options), as floats."""
    out = {}
    for name, text in assignments.items():
        try:
            value = float(text)
        except ValueError:
            raise ParameterError(f"bad {option} '{name}={text}': '{text}' is not a number") from None
        if not math.isfinite(value):
            raise ParameterError(f"bad {option} '{name}={text}': value must be finite")
        out[name] = value
    return out


def positive_seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of seconds") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive finite number of seconds, got '{text}'")
    return value


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got '{text}'")
    return value


def path_pair(text: str) -> tuple[str, str]:
    """``--path-from``: ``RECORD=FORCE``, a hammer record and the model's bearing force its blow stands for."""
    record, sep, force = text.partition("=")
    if not sep or not record.strip() or not force.strip():
        raise argparse.ArgumentTypeError(f"expected RECORD=FORCE (e.g. hammer_pinion=bearing_force_input_y), got {text!r}")
    return record.strip(), force.strip()


def local_executor(workers):
    if workers is None:
        return None
    return lib("twin.executor").make_executor({"type": "local", "workers": workers})


def recording_warnings(fn, *args):
    """``fn(*args)`` with the library's warnings recorded: (its value, their messages).  Used in
    the child process that runs an FMU, whose own stderr the caller may not see."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", TwinWarning)
        value = fn(*args)
    return value, [str(w.message) for w in caught if issubclass(w.category, TwinWarning)]


def print_warnings(notes) -> None:
    for note in notes:
        print(f"twin: warning: {note}", file=sys.stderr)
