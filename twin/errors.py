"""Typed exceptions, one per boundary of the twin.

Every error the library raises on purpose derives from :class:`TwinError`, so a
caller can catch the whole family while still telling boundaries apart.
"""
from __future__ import annotations


def _rebuild(cls, args, state):
    err = cls.__new__(cls)
    err.args = args
    err.__dict__.update(state)
    return err


class TwinError(Exception):
    """Base class of every error raised on purpose by ``twin`` and ``fmu_build``.

    Errors cross process boundaries (a worker's error is the caller's): they pickle by their
    message and attributes, whatever their constructor takes.
    """

    def __reduce__(self):
        return (_rebuild, (type(self), self.args, dict(self.__dict__)))


class TwinWarning(UserWarning):
    """Something the user should know that does not stop the work (the CLI prints it on one line)."""


class BuildError(TwinError):
    """The Modelica -> FMU export failed (compiler, code generation or gcc)."""


class ModelicaSubsetError(BuildError):
    """A Modelica model uses a construct outside the supported subset.

    Attributes
    ----------
    problems : list of (file, line, construct, reason)
    """

    def __init__(self, problems: list[tuple[str, int, str, str]]):
        self.problems = list(problems)
        lines = [f"{f}:{ln}: unsupported construct '{c}': {r}" for f, ln, c, r in self.problems]
        super().__init__("Modelica model is outside the supported subset:\n  " + "\n  ".join(lines))


class FMUError(TwinError):
    """An FMU file is unusable: missing, not a zip, bad modelDescription, wrong platform."""


class SimulationError(TwinError):
    """An FMU call failed during simulation.

    Attributes
    ----------
    time : float or None
        Simulation time [s] at which the failing call was made.
    status : str or None
        FMI status name returned by the FMU (e.g. ``'fmi2Error'``).
    """

    def __init__(self, message: str, time: float | None = None, status: str | None = None):
        self.time = time
        self.status = status
        where = f" at t={time:.6g} s" if time is not None else ""
        what = f" (status {status})" if status else ""
        super().__init__(f"{message}{where}{what}")


class WorkerCrashError(SimulationError):
    """A process hosting FMU work died (a signal such as SIGSEGV, or ``exit()`` inside the FMU)
    or was stopped after passing its time limit.

    Attributes
    ----------
    exitcode : int or None
        Exit status of the process; negative: killed by signal ``-exitcode``.
    timeout : float or None
        The time limit [s] the task passed, when it was stopped for hanging.
    """

    def __init__(self, message: str, *, exitcode: int | None = None, timeout: float | None = None):
        self.exitcode = exitcode
        self.timeout = timeout
        super().__init__(message)


class ResumeError(TwinError):
    """A partial result or checkpoint cannot be resumed: unreadable, or made by another scenario,
    FMU or set of settings (its identity hash differs)."""


class ParameterError(TwinError):
    """A parameter name or value is not acceptable for the FMU."""


class UnitError(ParameterError):
    """A unit cannot be read, or a value cannot be converted between two units."""


class SSPError(TwinError):
    """An SSP file (.ssp, .ssd, .ssv) cannot be read or written; the message names the file and the
    element, parameter or unit at fault."""


class OutputPathError(TwinError):
    """An output path cannot be written (missing directory, unknown suffix, ...)."""


class ScenarioError(TwinError):
    """A scenario file is invalid. Lists every problem found, not only the first.

    Attributes
    ----------
    problems : list of (file, key_path, reason)
    """

    def __init__(self, problems: list[tuple[str, str, str]]):
        self.problems = list(problems)
        lines = [f"{f}: {k}: {r}" if k else f"{f}: {r}" for f, k, r in self.problems]
        n = len(self.problems)
        super().__init__(f"{n} problem{'s' if n != 1 else ''} in scenario:\n  " + "\n  ".join(lines))


class FMUCompatibilityError(TwinError):
    """An FMU does not offer what a scenario needs. Lists every mismatch."""

    def __init__(self, fmu: str, mismatches: list[str]):
        self.fmu = fmu
        self.mismatches = list(mismatches)
        super().__init__(f"FMU {fmu} does not fit the scenario ({len(mismatches)} mismatch"
                         f"{'es' if len(mismatches) != 1 else ''}):\n  " + "\n  ".join(mismatches))


class MeasurementError(TwinError):
    """A measurement file (HDF5 or CSV + sidecar) is unusable. Lists every problem found.

    Attributes
    ----------
    file : str
        The offending file.
    record : str or None
        Record the (first) problem belongs to; ``None`` for a problem of the whole file.
    problem : str
        What is wrong with it (the first problem when there are several).
    problems : list of (file, record, problem)
        Every problem found in the file, in the order they were found.
    """

    def __init__(self, file: str, record: str | None, problem: str, *,
                 problems: list[tuple[str, str | None, str]] | None = None):
        self.file = str(file)
        self.record = record
        self.problem = problem
        self.problems = list(problems) if problems else [(self.file, record, problem)]

        def where(f: str, r: str | None) -> str:
            return f"measurement file '{f}', " + (f"record '{r}'" if r is not None else "whole file")

        if len(self.problems) == 1:
            f, r, p = self.problems[0]
            super().__init__(f"{where(f, r)}: {p}")
        else:
            lines = [f"{where(f, r)}: {p}" for f, r, p in self.problems]
            super().__init__(f"{len(self.problems)} problems in measurement file '{self.file}':\n  "
                             + "\n  ".join(lines))
