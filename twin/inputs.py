"""Time-varying inputs from a CSV file in fmpy's format (``twin simulate --input-file``).

The file has a header row of variable names (quoted or not) whose first column is the time [s],
then one row per time point, ascending (a repeated time is a step). As fmpy applies an input
file, each column drives the FMU variable of its name:

- a continuous ``Real`` input is interpolated linearly in time (held at the first and last
  value outside the table);
- any other input, and a tunable parameter, holds the value of the last row at or before the
  time (after a step, the value right of it).

Values are set at every communication point and held over the step, so the communication step
is the output interval. A column that names no input or tunable parameter is an error naming it.
"""
from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twin.errors import ParameterError


@dataclass(frozen=True)
class InputTable:
    """Columns of an input file: ``time`` (n,) ascending and ``values[name]`` (n,) each."""

    time: np.ndarray
    values: Mapping[str, np.ndarray]
    source: str = "<input>"

    @classmethod
    def read(cls, path: str | Path) -> "InputTable":
        """Read an fmpy-style input CSV; every problem is a :class:`~twin.errors.ParameterError` naming it."""
        path = Path(path)
        if not path.is_file():
            raise ParameterError(f"input file {path} does not exist")
        with path.open(newline="", encoding="utf-8-sig") as fh:
            rows = [r for r in csv.reader(fh) if r]
        if len(rows) < 2:
            raise ParameterError(f"input file {path}: needs a header row and at least one row of values")
        header = [h.strip() for h in rows[0]]
        if len(header) < 2:
            raise ParameterError(f"input file {path}: needs a time column and at least one input column")
        if len(set(header)) != len(header):
            raise ParameterError(f"input file {path}: duplicate column names in {header}")
        try:
            table = np.array([[float(x) for x in r] for r in rows[1:]])
        except ValueError as exc:
            raise ParameterError(f"input file {path}: {exc}") from None
        if table.shape[1] != len(header):
            raise ParameterError(f"input file {path}: rows have {table.shape[1]} values for {len(header)} columns")
        if not np.isfinite(table).all():
            raise ParameterError(f"input file {path}: values must be finite")
        t = table[:, 0]
        if np.any(np.diff(t) < 0):
            raise ParameterError(f"input file {path}: the time column ({header[0]!r}) must be ascending")
        return cls(t, {name: table[:, j] for j, name in enumerate(header[1:], start=1)}, str(path))

    def check(self, variables: Mapping[str, object]) -> tuple[list[str], list[str]]:
        """Split the columns into (interpolated, held) by the FMU variables they drive."""
        linear, held, bad = [], [], []
        for name in self.values:
            v = variables.get(name)
            if v is not None and v.causality == "input":
                continuous = v.type in ("Real", "Float64", "Float32") and v.variability == "continuous"
                (linear if continuous else held).append(name)
            elif v is not None and v.causality == "parameter" and v.variability == "tunable":
                held.append(name)
            else:
                bad.append(name)
        if bad:
            raise ParameterError(f"input file {self.source}: column(s) {', '.join(map(repr, bad))} name no input "
                                 "or tunable parameter of the FMU")
        return linear, held

    def at(self, t: float, linear: Sequence[str], held: Sequence[str]) -> dict[str, float]:
        """Values of the columns at time ``t`` [s]."""
        out = {n: float(np.interp(t, self.time, self.values[n])) for n in linear}
        k = max(int(np.searchsorted(self.time, t, side="right")) - 1, 0)
        out.update({n: self.values[n][k].item() for n in held})
        return out


def simulate_with_inputs(path: str | Path, table: InputTable, *, stop_time: float | None = None,
                         start_time: float | None = None, output_interval: float | None = None,
                         outputs: Sequence[str] | None = None,
                         parameters: Mapping[str, object] | None = None, inputs: Mapping[str, object] | None = None,
                         progress: bool = False):
    """Simulate an FMU driven by ``table`` (set at every output sample and held over it).

    ``inputs`` holds further inputs constant; a variable both here and in the table is an error.
    Times left out come from the model's default experiment (see :meth:`twin.fmu.FMU.experiment`).
    Returns a :class:`~twin.results.SimulationResult`.
    """
    from twin.fmu import FMU

    both = sorted(set(table.values) & set(inputs or {}))
    if both:
        raise ParameterError(f"{', '.join(map(repr, both))} given both as a constant input and in {table.source}")
    with FMU(path) as fmu:
        start_time, stop_time, output_interval = fmu.experiment(start_time, stop_time, output_interval)
        linear, held = table.check(fmu.variables)
        start = table.at(start_time, linear, held)
        fmu.setup(start_time, parameters={**dict(parameters or {}), **{n: start[n] for n in held if n not in linear
                                                                         and fmu.variables[n].causality == "parameter"}},
                  inputs={**dict(inputs or {}), **{n: v for n, v in start.items()
                                                   if fmu.variables[n].causality == "input"}},
                  stop_time=stop_time)
        return fmu.run(stop_time, output_interval, outputs=outputs, communication_step=output_interval,
                       progress=progress, callback=lambda f, t: f.set(table.at(t, linear, held)))
