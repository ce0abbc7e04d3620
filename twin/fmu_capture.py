"""Sampling a run: outputs captured on the grid ``start + k * output_interval`` into a result.

:class:`FMUCapture` is the part of :class:`twin.fmu.FMU` that lays the sample grid, collects
:class:`Block` s and assembles the :class:`~twin.results.SimulationResult`, including a run the
FMU ended itself (:class:`RunEnd`).  The FMU class supplies the FMI calls ``setup()``,
``_do_step(h)``, ``_read(variables)`` and ``_capture_buffered(...)`` (one C call per
communication step for FMUs built by ``fmu_build``).
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from twin._progress import progress_bar
from twin.errors import ParameterError, SimulationError
from twin.fmu_description import float_or_none
from twin.results import SimulationResult
from twin.variables import Variable

__all__ = ["RunEnd", "Block", "FMUCapture"]


@dataclass(frozen=True)
class RunEnd:
    """The FMU ended the run itself at ``time`` [s]; ``reason`` says how (and its message)."""

    time: float
    reason: str


@dataclass(frozen=True)
class Block:
    """Samples from one capture: ``time`` shape (m,), one column per name, each (m,) of its dtype."""

    time: np.ndarray
    columns: tuple[np.ndarray, ...]



class FMUCapture:
    """Run to a stop time, or capture blocks of samples, from the current time (see :class:`twin.fmu.FMU`)."""

    def _end(self, t: float, h: float, last, how: str) -> bool:
        """Record that the FMU ended the run within the step [t, t + h]."""
        last = float_or_none(last)
        tol = 1e-9 * max(1.0, abs(t + h))
        if last is None or not t - tol <= last <= t + h + tol:
            last = t                 # not reported (or nonsense): the step start is the last valid time
        message = "; ".join(self._messages[-3:])
        self._messages.clear()
        self.ended = RunEnd(min(max(last, t), t + h), f"{how} at t={last:.9g} s" + (f": {message}" if message else ""))
        self.time = self.ended.time
        return False

    def _recorded(self, names: Iterable[str] | None) -> list[Variable]:
        """The variables to record: ``names`` (checked: they exist and have a supported type),
        or every output of a supported type."""
        if names is None:
            return self.recordable_outputs
        variables, problems = [], []
        for n in names:
            try:
                v = self.variable(n)
                if v.unsupported_reason:
                    raise ParameterError(v.unsupported_reason + "; it cannot be recorded")
                if v.causality == "independent":
                    raise ParameterError(f"'{n}' is the independent variable; it is the result's time axis")
                variables.append(v)
            except ParameterError as exc:
                problems.append(str(exc))
        if problems:
            raise ParameterError(problems[0] if len(problems) == 1 else "\n  ".join(problems))
        return variables

    def run(self, stop_time: float, output_interval: float, *, outputs: Iterable[str] | None = None,
            communication_step: float | None = None, progress: bool = False, callback=None) -> SimulationResult:
        """Simulate from the current time to ``stop_time`` and return the sampled outputs.

        Parameters
        ----------
        stop_time : end time [s].
        output_interval : output sample period [s] (1e-5 for 100 kHz).
        outputs : names to record (default: every output of a supported type).
        communication_step : how often ``callback`` runs [s]; default 0.1 s (one Python call per
            10,000 samples at 100 kHz for buffered FMUs).
        callback : ``callback(fmu, t)`` called after every communication step (events, hooks).

        Returns a :class:`SimulationResult` whose ``time`` has shape (n,) with
        n = round((stop_time - start) / output_interval) + 1, or fewer samples when the FMU ends
        the run itself (``ended_by_fmu``; the last sample is at the FMU's last valid time).  Its
        parameters are :attr:`initial_parameters`.
        """
        if not self._initialized:
            self.setup(self.time, stop_time=stop_time)
        if not output_interval > 0:
            raise SimulationError(f"output_interval must be > 0 s, got {output_interval!r}", time=self.time)
        variables = self._recorded(outputs)
        k0 = round((self.time - self._t_start) / output_interval)
        n_samples = int(round((stop_time - self._t_start) / output_interval)) - k0
        if n_samples < 1:
            raise SimulationError(f"stop_time {stop_time} s leaves no output sample after t={self.time} s",
                                  time=self.time)
        per_step = max(1, int(round((communication_step or 0.1) / output_interval)))
        names = [v.name for v in variables]
        blocks = [Block(np.array([self.time]), tuple(np.array([x], dtype=v.dtype)
                                                     for v, x in zip(variables, self._read(variables))))]
        bar = progress_bar(n_samples, progress, self.model_name, "samples")
        k = 0
        try:
            while k < n_samples and self.ended is None:
                m = min(per_step, n_samples - k)
                block = self.capture_block(self._t_start + (k0 + k + m) * output_interval, output_interval, names)
                blocks.append(block)
                k += m
                if callback is not None and self.ended is None:
                    callback(self, self.time)
                bar.update(m)
        finally:
            bar.close()
        return self._result(variables, blocks, output_interval)

    def _result(self, variables: Sequence[Variable], blocks: Sequence[Block], output_interval: float) -> SimulationResult:
        time = np.concatenate([b.time for b in blocks])
        columns = [np.concatenate([b.columns[j] for b in blocks]) for j in range(len(variables))]
        for v, col in zip(variables, columns):
            if v.kind == "float":
                bad = ~np.isfinite(col)
                if bad.any():
                    i = int(np.argmax(bad))
                    raise SimulationError(f"output {v.name} is not finite", time=float(time[i]))
        return SimulationResult(
            time=time, signals={v.name: c for v, c in zip(variables, columns)},
            units={v.name: v.unit for v in variables}, sample_rate=1.0 / output_interval,
            parameters=dict(self.initial_parameters), model_name=self.model_name, guid=self.guid,
            fmu_sha256=self.sha256, types={v.name: v.type for v in variables},
            enumerations={v.name: dict(v.items) for v in variables if v.items},
            ended_by_fmu=self.ended is not None, end_reason=self.ended.reason if self.ended else "")

    def capture(self, t_end: float, output_interval: float, names: Sequence[str]) -> np.ndarray:
        """Advance to ``t_end`` and return float outputs sampled every ``output_interval``.

        Returns shape (m, len(names)): the samples at t + output_interval, ..., t_end, where
        m = round((t_end - t) / output_interval).  For variables of other types, or FMUs that may
        end the run themselves, use :meth:`capture_block`; here such an end is a SimulationError.
        """
        variables = [self.variable(n) for n in names]
        not_float = [v.name for v in variables if v.kind != "float"]
        if not_float:
            raise ParameterError(f"capture() returns floats; {', '.join(not_float)} "
                                 f"{'is not a float variable' if len(not_float) == 1 else 'are not float variables'} "
                                 "(capture_block returns every type)")
        block = self.capture_block(t_end, output_interval, names)
        if self.ended is not None:
            raise SimulationError(f"{self.model_name} ended the run itself before t={t_end:.6g} s: "
                                  f"{self.ended.reason}", time=self.time)
        out = np.empty((block.time.size, len(names)))
        for j, c in enumerate(block.columns):
            out[:, j] = c
        return out

    def capture_block(self, t_end: float, output_interval: float, names: Sequence[str]) -> Block:
        """Advance to ``t_end`` and return the samples of ``names`` every ``output_interval``.

        Samples are at the grid points start + k * output_interval after the current time up to
        ``t_end``; FMUs built by fmu_build fill an internal buffer during one doStep, other FMUs
        get one doStep and one get per type per sample.  If the FMU ends the run itself, the block
        stops there: its last sample is at the FMU's last valid time (on the grid when within
        1e-9 of a grid point) and :attr:`ended` is set.
        """
        # snap to the sample grid t_start + k*interval, which is where the FMU samples, so float
        # drift over many captures cannot drop or add a sample
        k_now = round((self.time - self._t_start) / output_interval)
        k_end = round((t_end - self._t_start) / output_interval)
        m = int(k_end - k_now)
        if m < 1:
            raise SimulationError(f"capture to t={t_end} s leaves no sample after t={self.time} s", time=self.time)
        variables = self._recorded(names)
        if self._buffer_fn is not None and all(v.type in ("Real", "Float64") for v in variables):
            return self._capture_buffered(k_now, m, output_interval, variables)
        times = np.empty(m)
        columns = [np.empty(m, dtype=v.dtype) for v in variables]
        n = 0
        for j in range(m):
            t_next = self._t_start + (k_now + j + 1) * output_interval
            if not self._do_step(t_next - self.time):
                t_last = self.ended.time
                if abs(t_last - t_next) <= 1e-9 * output_interval:
                    t_last = t_next
                previous = self._t_start + (k_now + j) * output_interval
                if t_last > previous + 1e-9 * output_interval:     # a sample the grid does not have yet
                    times[n] = t_last
                    for c, x in zip(columns, self._read(variables)):
                        c[n] = x
                    n += 1
                break
            self.time = t_next
            times[n] = t_next
            for c, x in zip(columns, self._read(variables)):
                c[n] = x
            n += 1
        return Block(times[:n], tuple(c[:n] for c in columns))
