"""Command-line shell ``twin``: parses arguments, dispatches to a sub-command, reports errors.

The sub-commands live in :mod:`twin.commands` (one module per group); they only parse and
print, all work lives in the library.  Library modules are imported inside each handler so
``twin --help`` does not pay for numpy, fmpy or torch.
"""
from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence

from twin.commands import calibration, effects, fmu, runs
from twin.commands.common import parse_assignments
from twin.commands.fmu import DEFAULT_MODEL, MEASURED_MODES_HZ
from twin.errors import TwinError, TwinWarning, WorkerCrashError

__all__ = ["main", "build_parser", "parse_assignments", "DEFAULT_MODEL", "MEASURED_MODES_HZ"]


def build_parser() -> argparse.ArgumentParser:
    """Return the ``twin`` argument parser (one sub-parser per command)."""
    parser = argparse.ArgumentParser(
        prog="twin", description="FMU co-simulation digital twin of a spur gearbox.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    fmu.add_subcommands(sub)
    runs.add_subcommands(sub)
    calibration.add_subcommands(sub)
    effects.add_subcommands(sub)
    fmu.add_ssp_subcommands(sub)

    from twin.transfer.cli import add_subcommands as add_transfer
    add_transfer(sub)

    from twin.rul import add_subcommands as add_rul
    add_rul(sub)

    from twin.pipeline import add_subcommands as add_pipeline
    add_pipeline(sub)

    runs.add_schema_and_demo(sub)
    return parser


def _os_error_message(exc: OSError) -> str:
    """One line for an OS error on a path: what went wrong and which path."""
    what = (exc.strerror or str(exc)).rstrip(".")
    what = what[:1].lower() + what[1:]
    if exc.filename is not None and exc.filename2 is not None:
        return f"{what}: '{exc.filename}' -> '{exc.filename2}'"
    if exc.filename is not None:
        return f"{what}: '{exc.filename}'"
    return what


def _add_debug_option(parser: argparse.ArgumentParser) -> None:
    """``--debug`` on the main parser and on every sub-command (so it may come anywhere)."""
    parser.add_argument("--debug", action="store_true",
                        help="show the Python traceback of an error instead of one line")
    for action in parser._subparsers._group_actions if parser._subparsers else ():
        for sub in getattr(action, "choices", {}).values():
            sub.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                             help="show the Python traceback of an error instead of one line")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; return the exit code.

    0 success; 2 usage error or bad input (:class:`TwinError`, an OS error on a path: one
    ``twin: error:`` line naming the value or the path); 130 interrupted by Ctrl-C (or SIGTERM);
    1 anything else, which is a bug: one line naming the exception and a hint to re-run with
    ``--debug`` (or ``TWIN_DEBUG=1``) for the traceback.
    """
    import os

    from twin import _interrupt

    parser = build_parser()
    _add_debug_option(parser)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help or a usage error; argparse already printed
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    debug = bool(getattr(args, "debug", False)) or os.environ.get("TWIN_DEBUG", "") not in ("", "0")
    _interrupt.install()
    try:
        with warnings.catch_warnings():
            _one_line_warnings()          # set before the FMU's child process forks, which inherits it
            code = args.handler(args)
    except KeyboardInterrupt:
        if debug:
            import traceback
            traceback.print_exc()
        print("twin: interrupted; results written before the interruption are unchanged", file=sys.stderr)
        return 130
    except TwinError as exc:
        if debug:
            raise
        if isinstance(exc, WorkerCrashError) and not getattr(args, "no_progress", True):
            print(file=sys.stderr)      # the dead process's progress bar may have left a line open
        print(f"twin: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        if debug:
            raise
        print(f"twin: error: {_os_error_message(exc)}", file=sys.stderr)
        return 2
    except MemoryError as exc:
        if debug:
            raise
        print(f"twin: error: out of memory{': ' + str(exc) if str(exc) else ''}", file=sys.stderr)
        return 2
    except Exception as exc:  # the last line of defence: a bug, reported in one line
        if debug:
            raise
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        print(f"twin: error: internal error {type(exc).__name__}{': ' + text if text else ''} "
              "(re-run with --debug for the traceback)", file=sys.stderr)
        return 1
    finally:
        interrupted = _interrupt.requested()
        _interrupt.uninstall()
    if interrupted:  # the request arrived where nothing checked it: still honoured
        print("twin: interrupted", file=sys.stderr)
        return 130
    return code


def _one_line_warnings() -> None:
    """Show the library's own warnings (:class:`TwinWarning`) as one line each, every time; any
    other warning as Python shows it.  Call inside ``warnings.catch_warnings()``."""
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, TwinWarning):
            print(f"twin: warning: {message}", file=sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)
    warnings.showwarning = show
    warnings.simplefilter("always", TwinWarning)


if __name__ == "__main__":
    sys.exit(main())
