"""The only module of ``twin`` that talks to FMUs (through fmpy).

It turns value references into names, FMI status codes into :class:`SimulationError`, and
captures high-rate outputs without a Python call per sample: FMUs built by ``fmu_build``
buffer their outputs inside each ``doStep`` (parameter ``solver.output_interval``) and the
buffer is read with one C call per communication step.  Any other FMI 2.0 Co-Simulation
FMU works too, at one ``doStep`` + ``getReal`` per output sample.

Typical use::

    with FMU("build/GearTwin.Gearbox21.fmu") as fmu:
        fmu.setup(parameters={"c_mesh": 900.0})
        result = fmu.run(stop_time=1.0, output_interval=1e-5)
"""
from __future__ import annotations

import ctypes
import hashlib
import itertools
import shutil
import tempfile
import weakref
import zipfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twin._progress import progress_bar
from twin.errors import FMUError, ParameterError, SimulationError
from twin.results import SimulationResult

_STATUS = ["fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending"]
STEP_SIZE = "solver.step_size"
OUTPUT_INTERVAL = "solver.output_interval"


# fmpy's logger proxy (which formats the printf arguments of FMU messages) keeps ONE target
# logger per process. Registering a proxy per instance would redirect every other FMU's messages,
# fmpy's own included, to that instance's callback, and to freed memory once it is closed. So one
# proxy is registered, once, for a dispatcher that forwards by componentEnvironment to the live
# instance, and prints like fmpy for anything else.
_LOG_KEYS = itertools.count(1)
_LOG_TARGETS: dict[int, "weakref.WeakMethod"] = {}
_SHARED: dict[str, object] = {}


def _dispatch_log(env, instance, status, category, message):
    target = _LOG_TARGETS.get(int(env)) if env else None
    method = target() if target is not None else None
    if method is not None:
        method(env, instance, status, category, message)
    else:
        from fmpy.fmi1 import printLogMessage
        printLogMessage(env, instance, status, category, message)


def _shared_logger():
    """The proxied logger function pointer shared by every instance (registered on first use)."""
    if "logger" not in _SHARED:
        from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(_dispatch_log)
        _SHARED["python_logger"] = cb.logger          # kept alive for the life of the process
        try:
            from fmpy.logging import addLoggerProxy
            addLoggerProxy(ctypes.byref(cb))           # replaces cb.logger by the C proxy
        except Exception:  # without the proxy, messages arrive unformatted but still arrive
            pass
        _SHARED["callbacks"] = cb
        _SHARED["logger"] = cb.logger
    return _SHARED["logger"]


@dataclass(frozen=True)
class Variable:
    """One scalar variable of an FMU, as declared in its modelDescription.xml."""

    name: str
    value_reference: int
    type: str               # Real, Integer, Boolean, String, Enumeration
    causality: str          # parameter, calculatedParameter, input, output, local, independent
    variability: str        # constant, fixed, tunable, discrete, continuous
    unit: str
    description: str
    start: float | None


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


class FMU:
    """An FMI 2.0 Co-Simulation FMU opened for simulation.

    Parameters
    ----------
    path : path of the ``.fmu`` file.
    instance_name : name passed to ``fmi2Instantiate``.
    """

    def __init__(self, path: str | Path, *, instance_name: str = "twin"):
        import fmpy
        from fmpy.model_description import read_model_description

        self.path = Path(path)
        if not self.path.exists():
            raise FMUError(f"FMU file {self.path} does not exist")
        if not zipfile.is_zipfile(self.path):
            raise FMUError(f"{self.path} is not an FMU (not a zip archive)")
        try:
            self.model_description = read_model_description(str(self.path))
        except Exception as exc:
            raise FMUError(f"{self.path}: invalid modelDescription.xml: {exc}") from exc
        md = self.model_description
        if md.fmiVersion != "2.0":
            raise FMUError(f"{self.path}: FMI version {md.fmiVersion} is not supported (need 2.0)")
        if md.coSimulation is None:
            raise FMUError(f"{self.path}: the FMU does not support Co-Simulation")
        self.sha256 = _sha256(self.path)
        self.variables: dict[str, Variable] = {}
        for v in md.modelVariables:
            start = v.start
            try:
                start = float(start) if start is not None else None
            except (TypeError, ValueError):
                start = None
            self.variables[v.name] = Variable(v.name, int(v.valueReference), v.type, v.causality,
                                              v.variability, v.unit or "", v.description or "", start)
        self._unzip = tempfile.mkdtemp(prefix="twin_fmu_")
        try:
            fmpy.extract(str(self.path), self._unzip)
        except Exception as exc:
            shutil.rmtree(self._unzip, ignore_errors=True)
            raise FMUError(f"{self.path}: cannot extract: {exc}") from exc
        self._instance_name = instance_name
        self._slave = None
        self._messages: list[str] = []
        self._callbacks = None
        self.time = 0.0
        self._buffer_fn = None
        self._buffer_interval = None
        self._scratch = None
        self._initialized = False
        self._fatal = False
        self._t_start = 0.0

    # -- description -----------------------------------------------------------------------
    @property
    def model_name(self) -> str:
        return self.model_description.modelName

    @property
    def guid(self) -> str:
        return self.model_description.guid

    def _by(self, causality: str) -> list[Variable]:
        return sorted((v for v in self.variables.values() if v.causality == causality),
                      key=lambda v: v.value_reference)

    @property
    def parameters(self) -> list[Variable]:
        return self._by("parameter")

    def structural_values(self) -> dict[str, int]:
        """The model's Integer constants (``z1``, ``z2``, ``n_profile``, ...): fixed when the FMU
        was built, so read from its model description."""
        return {v.name: int(v.start) for v in self.variables.values()
                if v.type == "Integer" and v.variability == "constant" and v.start is not None}

    @property
    def inputs(self) -> list[Variable]:
        return self._by("input")

    @property
    def outputs(self) -> list[Variable]:
        return self._by("output")

    @property
    def unit_definitions(self) -> dict:
        """The FMU's ``UnitDefinitions`` with a ``BaseUnit``, as :class:`twin.units.Unit` by name."""
        from twin.units import BASE, Unit
        out = {}
        for u in self.model_description.unitDefinitions or ():
            b = getattr(u, "baseUnit", None)
            if b is not None:
                out[u.name] = Unit(u.name, tuple(int(getattr(b, k, 0) or 0) for k in BASE),
                                   float(b.factor if b.factor is not None else 1.0),
                                   float(b.offset if b.offset is not None else 0.0))
        return out

    @property
    def supports_output_buffer(self) -> bool:
        return OUTPUT_INTERVAL in self.variables

    def variable(self, name: str) -> Variable:
        try:
            return self.variables[name]
        except KeyError:
            close = [n for n in self.variables if name.lower() in n.lower()][:5]
            hint = f"; similar: {', '.join(close)}" if close else ""
            raise ParameterError(f"{self.model_name} has no variable {name!r}{hint}") from None

    # -- lifecycle -------------------------------------------------------------------------
    def _logger(self, component, instance, status, category, message):
        text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
        if status >= 2:
            self._messages.append(text)

    def _make_callbacks(self):
        from fmpy import calloc, free
        from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions
        for dead in [k for k, ref in _LOG_TARGETS.items() if ref() is None]:
            del _LOG_TARGETS[dead]          # instances collected since the last registration
        key = next(_LOG_KEYS)
        _LOG_TARGETS[key] = weakref.WeakMethod(self._logger)
        cb = fmi2CallbackFunctions()
        cb.logger = _shared_logger()
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        # the logger finds this instance again through componentEnvironment
        cb.componentEnvironment = ctypes.c_void_p(key)
        return cb

    def _call(self, what: str, fn, *args):
        try:
            return fn(*args)
        except Exception as exc:
            status = getattr(exc, "status", None)
            name = _STATUS[status] if isinstance(status, int) and 0 <= status < len(_STATUS) else None
            self._fatal = self._fatal or name == "fmi2Fatal"
            detail = "; ".join(self._messages[-3:]) or str(exc)
            self._messages.clear()
            raise SimulationError(f"{self.model_name}: {what} failed: {detail}", time=self.time,
                                  status=name) from exc

    def instantiate(self) -> None:
        """Load the binary and instantiate (idempotent)."""
        if self._slave is not None:
            return
        from fmpy.fmi2 import FMU2Slave
        md = self.model_description
        try:
            self._slave = FMU2Slave(guid=md.guid, unzipDirectory=self._unzip,
                                    modelIdentifier=md.coSimulation.modelIdentifier,
                                    instanceName=self._instance_name)
        except Exception as exc:
            raise FMUError(f"{self.path}: cannot load the binary for this platform: {exc}") from exc
        self._callbacks = self._make_callbacks()
        try:
            self._slave.instantiate(callbacks=self._callbacks)
        except Exception as exc:
            detail = "; ".join(self._messages) or str(exc)
            # fmi2Instantiate returned NULL: there is no instance to terminate or free (an FMU
            # given a NULL component may crash), only the library to unload
            slave, self._slave = self._slave, None
            try:
                slave.freeLibrary()
            except Exception:  # the error below is the one the user needs
                pass
            raise FMUError(f"{self.path}: fmi2Instantiate failed: {detail}") from exc
        fn = getattr(self._slave.dll, "twin_fmi2GetOutputBuffer", None)
        if fn is not None:
            fn.restype = ctypes.c_size_t
            fn.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.c_size_t]
        self._buffer_fn = fn

    def setup(self, start_time: float = 0.0, *, parameters: Mapping[str, float] | None = None,
              inputs: Mapping[str, float] | None = None) -> None:
        """Instantiate, set parameters/inputs, and run the initialization mode."""
        self.instantiate()
        self.time = float(start_time)
        self._t_start = float(start_time)
        self._call("fmi2SetupExperiment", self._slave.setupExperiment, None, float(start_time))
        self._call("fmi2EnterInitializationMode", self._slave.enterInitializationMode)
        if parameters:
            self.set(parameters)
        if inputs:
            self.set(inputs)
        self._call("fmi2ExitInitializationMode", self._slave.exitInitializationMode)
        self._initialized = True

    def reset(self) -> None:
        """Return to the state right after instantiation (parameters back to defaults)."""
        if self._slave is not None:
            self._call("fmi2Reset", self._slave.reset)
        self.time = 0.0
        self._buffer_interval = None
        self._initialized = False

    def close(self) -> None:
        if self._slave is not None:
            # fmi2Terminate only for an initialised instance, and nothing after fmi2Fatal
            # (FMI 2.0, section 4.2.4); fmi2FreeInstance for any instance that exists
            if self._initialized and not self._fatal:
                try:
                    self._slave.terminate()
                except Exception:  # terminating a failed instance may fail again; it is freed anyway
                    pass
            if not self._fatal and getattr(self._slave, "component", None):
                self._slave.freeInstance()
            try:
                self._slave.freeLibrary() if hasattr(self._slave, "freeLibrary") else None
            except Exception:
                pass
            self._slave = None
        shutil.rmtree(self._unzip, ignore_errors=True)

    def __enter__(self) -> "FMU":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):
        try:
            shutil.rmtree(self._unzip, ignore_errors=True)
        except Exception:
            pass

    # -- values ----------------------------------------------------------------------------
    def set(self, values: Mapping[str, float]) -> None:
        """Set Real parameters or inputs by name. Non-finite values and read-only names are refused."""
        self.instantiate()
        vrs, vals = [], []
        for name, value in values.items():
            v = self.variable(name)
            if v.variability == "constant" and v.type in ("Integer", "Boolean"):
                from twin.variants import rebuild_hint
                raise ParameterError(rebuild_hint(self.model_name, name, value))
            if v.type != "Real":
                raise ParameterError(f"{name!r} is a {v.type} variable; only Real variables can be set here")
            if v.causality not in ("parameter", "input"):
                raise ParameterError(f"{name!r} has causality {v.causality!r} and cannot be set "
                                     "(only parameters and inputs)")
            if v.causality == "parameter" and v.variability != "tunable" and self._initialized:
                raise ParameterError(f"{name!r} is a {v.variability} parameter and cannot change during a run")
            try:
                f = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"value of {name!r} must be a number, got {value!r}") from None
            if not np.isfinite(f):
                raise ParameterError(f"value of {name!r} must be finite, got {value!r}")
            vrs.append(v.value_reference)
            vals.append(f)
        if vrs:
            self._call("fmi2SetReal", self._slave.setReal, vrs, vals)

    def get(self, names: str | Sequence[str]) -> float | np.ndarray:
        """Current values of Real variables by name (a float for one name, else an array).

        A structural Integer or Boolean (``z1``, ``z2``, ``n_profile``) has no Real value: read it
        with :meth:`structural_values`.  Value references are unique per type only, so reading
        one as a Real would return another variable's value; it is a ParameterError instead."""
        self.instantiate()
        single = isinstance(names, str)
        names = [names] if single else list(names)
        variables = [self.variable(n) for n in names]
        not_real = [v.name for v in variables if v.type != "Real"]
        if not_real:
            raise ParameterError(f"{', '.join(repr(n) for n in not_real)} of {self.model_name} "
                                 f"{'is not a Real' if len(not_real) == 1 else 'are not Reals'}; "
                                 "read structural Integers with structural_values()")
        vrs = [v.value_reference for v in variables]
        vals = np.array(self._call("fmi2GetReal", self._slave.getReal, vrs))
        return float(vals[0]) if single else vals

    def step(self, dt: float) -> None:
        """Advance one communication step of ``dt`` seconds."""
        if not dt > 0:
            raise SimulationError(f"communication step must be > 0 s, got {dt!r}", time=self.time)
        self._call("fmi2DoStep", self._slave.doStep, self.time, dt)
        self.time += dt

    def get_state(self):
        """Opaque snapshot of the FMU (fmi2GetFMUstate); restore it with :meth:`set_state`."""
        return self._call("fmi2GetFMUstate", self._slave.getFMUstate), self.time

    def set_state(self, state) -> None:
        handle, t = state
        self._call("fmi2SetFMUstate", self._slave.setFMUstate, handle)
        self.time = t
        self._buffer_interval = self.get(OUTPUT_INTERVAL) if self.supports_output_buffer else None

    def free_state(self, state) -> None:
        self._call("fmi2FreeFMUstate", self._slave.freeFMUstate, state[0])

    # -- capture ---------------------------------------------------------------------------
    def run(self, stop_time: float, output_interval: float, *, outputs: Iterable[str] | None = None,
            communication_step: float | None = None, progress: bool = False, callback=None) -> SimulationResult:
        """Simulate from the current time to ``stop_time`` and return the sampled outputs.

        Parameters
        ----------
        stop_time : end time [s].
        output_interval : output sample period [s] (1e-5 for 100 kHz).
        outputs : names to record (default: every output).
        communication_step : doStep size [s]; default 0.1 s (one Python call per 10,000 samples at 100 kHz).
        callback : ``callback(fmu, t)`` called after every communication step (events, hooks).

        Returns a :class:`SimulationResult` whose ``time`` has shape (n,) with
        n = round((stop_time - start) / output_interval) + 1.
        """
        if self._slave is None:
            self.setup(self.time)
        if not output_interval > 0:
            raise SimulationError(f"output_interval must be > 0 s, got {output_interval!r}", time=self.time)
        t0 = self.time
        n_samples = int(round((stop_time - t0) / output_interval))
        if n_samples < 1:
            raise SimulationError(f"stop_time {stop_time} s leaves no output sample after t={t0} s", time=t0)
        names = [v.name for v in self.outputs] if outputs is None else list(outputs)
        for n in names:
            self.variable(n)
        per_step = max(1, int(round((communication_step or 0.1) / output_interval)))
        out = np.empty((n_samples + 1, len(names)))
        out[0] = self.get(names) if names else []
        bar = progress_bar(n_samples, progress, self.model_name, "samples")
        k = 0
        try:
            while k < n_samples:
                m = min(per_step, n_samples - k)
                out[k + 1:k + 1 + m] = self.capture(t0 + (k + m) * output_interval, output_interval, names)
                k += m
                if callback is not None:
                    callback(self, self.time)
                bar.update(m)
        finally:
            bar.close()
        time = t0 + output_interval * np.arange(n_samples + 1)
        bad = ~np.isfinite(out)
        if bad.any():
            i = int(np.argmax(bad.any(axis=1)))
            raise SimulationError(f"output {names[int(np.argmax(bad[i]))]} is not finite", time=float(time[i]))
        params = self.parameter_values()
        return SimulationResult(
            time=time, signals={n: out[:, j].copy() for j, n in enumerate(names)},
            units={n: self.variables[n].unit for n in names}, sample_rate=1.0 / output_interval,
            parameters=params, model_name=self.model_name, guid=self.guid, fmu_sha256=self.sha256)

    def capture(self, t_end: float, output_interval: float, names: Sequence[str]) -> np.ndarray:
        """Advance to ``t_end`` and return the outputs sampled every ``output_interval``.

        Returns shape (m, len(names)): the samples at t + output_interval, ..., t_end, where
        m = round((t_end - t) / output_interval). FMUs built by fmu_build fill an internal
        buffer during one doStep; other FMUs get one doStep + getReal per sample.
        """
        # snap to the sample grid t_start + k*interval, which is where the FMU samples, so float
        # drift over many captures cannot drop or add a sample
        k_now = round((self.time - self._t_start) / output_interval)
        k_end = round((t_end - self._t_start) / output_interval)
        t_end = self._t_start + k_end * output_interval
        m = int(k_end - k_now)
        if m < 1:
            raise SimulationError(f"capture to t={t_end} s leaves no sample after t={self.time} s", time=self.time)
        block = np.empty((m, len(names)))
        if self._buffer_fn is not None:
            all_outputs = [v.name for v in self.outputs]
            try:
                cols = [all_outputs.index(n) for n in names]
            except ValueError:
                extra = [n for n in names if n not in all_outputs]
                raise ParameterError(f"only outputs can be recorded from the buffer; not outputs: {extra}") from None
            if self._buffer_interval != output_interval:
                self.set({OUTPUT_INTERVAL: output_interval})
                self._buffer_interval = output_interval
            if self._scratch is None or self._scratch.shape[0] < m + 2:
                self._scratch = np.empty((m + 2, max(len(all_outputs), 1)))
            self._call("fmi2DoStep", self._slave.doStep, self.time, t_end - self.time)
            self.time = t_end
            got = self._buffer_fn(self._slave.component,
                                  self._scratch.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
                                  self._scratch.shape[0])
            if got != m:
                raise SimulationError(f"output buffer held {got} samples, expected {m}", time=self.time)
            block[:] = self._scratch[:m, cols]
        else:
            start = self.time
            for j in range(m):
                t_next = t_end if j == m - 1 else start + (j + 1) * output_interval
                self._call("fmi2DoStep", self._slave.doStep, self.time, t_next - self.time)
                self.time = t_next
                block[j] = self.get(names) if names else []
        return block

    def parameter_values(self) -> dict[str, float]:
        """Current values of every Real parameter."""
        reals = [v.name for v in self.parameters if v.type == "Real"]
        if not reals:
            return {}
        return dict(zip(reals, (float(x) for x in self.get(reals))))

    # -- Model Exchange view for linearisation -------------------------------------------------
    def state_derivative_function(self, parameters: Mapping[str, float] | None = None,
                                  inputs: Mapping[str, float] | None = None):
        """Return ``(f, x0, state_names)`` where ``f(x) -> xdot`` uses the FMU's Model Exchange interface.

        ``x0`` (n,) holds the initial states; the caller must call ``f.close()`` when done.
        ``f.outputs(x, names)`` gives variables (outputs) at state ``x``; ``f.set({name: value})``
        changes parameters or inputs for the following evaluations (calculated parameters follow).
        """
        md = self.model_description
        if md.modelExchange is None:
            raise FMUError(f"{self.path}: no Model Exchange interface, cannot linearise")
        from fmpy.fmi2 import FMU2Model
        model = FMU2Model(guid=md.guid, unzipDirectory=self._unzip,
                          modelIdentifier=md.modelExchange.modelIdentifier, instanceName="linearize")
        callbacks = self._make_callbacks()
        try:
            model.instantiate(callbacks=callbacks)
        except Exception as exc:  # NULL instance: nothing to terminate, see instantiate()
            detail = "; ".join(self._messages) or str(exc)
            raise FMUError(f"{self.path}: fmi2Instantiate (Model Exchange) failed: {detail}") from exc
        model.setupExperiment(startTime=0.0)
        model.enterInitializationMode()
        values = {**(parameters or {}), **(inputs or {})}
        if values:
            vrs = [self.variable(n).value_reference for n in values]
            model.setReal(vrs, [float(x) for x in values.values()])
        model.exitInitializationMode()
        model.enterContinuousTimeMode()
        nx = md.numberOfContinuousStates
        x0 = np.zeros(nx)
        dx = np.zeros(nx)
        model.getContinuousStates(x0.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)
        state_names = [self._derivative_of(d) for d in md.derivatives]

        class _F:
            def __call__(self_inner, x):
                x = np.ascontiguousarray(x, dtype=float)
                model.setContinuousStates(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)
                model.getDerivatives(dx.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)
                return dx.copy()

            def outputs(self_inner, x, names: Sequence[str]) -> np.ndarray:
                """Values of the variables ``names`` (outputs) at state ``x``."""
                x = np.ascontiguousarray(x, dtype=float)
                model.setContinuousStates(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)
                return np.array(model.getReal([self.variable(n).value_reference for n in names]), dtype=float)

            def set(self_inner, values: Mapping[str, float]) -> None:
                """Set parameters or inputs (by name) for the following evaluations."""
                if values:
                    model.setReal([self.variable(n).value_reference for n in values],
                                  [float(v) for v in values.values()])

            def close(self_inner):
                model.terminate()
                model.freeInstance()

        f = _F()
        f._callbacks = callbacks  # keep the ctypes callbacks alive as long as f
        return f, x0, state_names

    @staticmethod
    def _derivative_of(unknown) -> str:
        var = unknown.variable
        return var.derivative.name if getattr(var, "derivative", None) is not None else var.name


def simulate_fmu(path: str | Path, *, stop_time: float, start_time: float = 0.0, output_interval: float = 1e-5,
                 outputs: Sequence[str] | None = None, parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, float] | None = None, progress: bool = False,
                 step_size: float | None = None) -> SimulationResult:
    """Simulate an FMU with constant inputs and return its sampled outputs (like ``fmpy.simulate_fmu``).

    ``step_size`` [s] sets the internal solver step of FMUs built by ``fmu_build``.
    """
    if stop_time <= start_time:
        raise SimulationError(f"stop_time ({stop_time} s) must be after start_time ({start_time} s)")
    params = dict(parameters or {})
    with FMU(path) as fmu:
        if step_size is not None:
            if STEP_SIZE not in fmu.variables:
                raise ParameterError(f"{fmu.model_name} has no {STEP_SIZE} parameter (not built by fmu_build)")
            params[STEP_SIZE] = step_size
        fmu.setup(start_time, parameters=params, inputs=inputs)
        return fmu.run(stop_time, output_interval, outputs=outputs, progress=progress)


def validate(path: str | Path) -> list[str]:
    """Problems fmpy's validator finds in an FMU (``fmpy validate``): schema, names, model
    structure, start values, causality/variability, units. ``[]`` when there are none."""
    from fmpy.validation import validate_fmu

    path = Path(path)
    if not path.exists():
        raise FMUError(f"FMU file {path} does not exist")
    if not zipfile.is_zipfile(path) and not path.is_dir():
        raise FMUError(f"{path} is not an FMU (not a zip archive)")
    problems = [str(p) for p in validate_fmu(str(path))]
    if not problems and zipfile.is_zipfile(path):
        problems += _binary_problems(path)
    return problems


def _instantiate_only(path: str) -> None:
    import shutil
    import tempfile

    from fmpy import extract, instantiate_fmu, read_model_description

    unzipdir = extract(path, unzipdir=tempfile.mkdtemp(prefix="twin_fmu_"))
    try:
        md = read_model_description(unzipdir)
        kind = "CoSimulation" if md.coSimulation is not None else "ModelExchange"
        try:
            instance = instantiate_fmu(unzipdir, md, fmi_type=kind)
        except Exception as exc:     # fmpy raises plain exceptions for a library it cannot load
            raise FMUError(f"cannot load or instantiate: {exc}") from None
        instance.freeInstance()
    finally:
        shutil.rmtree(unzipdir, ignore_errors=True)


def _binary_problems(path: Path) -> list[str]:
    """Load and instantiate the platform binary in a child process: a truncated or foreign
    shared library passes every XML check but crashes (SIGBUS, SIGSEGV) or fails on first use."""
    from twin.isolation import run_isolated

    try:
        run_isolated(_instantiate_only, str(path), timeout=60.0, what=f"the instantiation of {path.name}")
    except (FMUError, SimulationError) as exc:      # WorkerCrashError is a SimulationError
        return [f"The binary for this platform cannot be loaded and instantiated: {exc}"]
    return []


def xml_schema(kind: str, name: str) -> Path:
    """A schema file that fmpy ships: ``kind`` is ``"ssp"`` (SSP 1.0), ``"fmi2"`` or ``"fmi3"``."""
    import fmpy

    base = Path(fmpy.__file__).parent
    path = base / "ssp" / "schema" / name if kind == "ssp" else base / "schema" / kind / name
    if not path.is_file():
        raise FMUError(f"schema {name} not found in {path.parent}; reinstall fmpy")
    return path


def describe(path: str | Path) -> str:
    """Human-readable summary of an FMU: identity, interfaces and variables with units."""
    with FMU(path) as fmu:
        md = fmu.model_description
        lines = [f"Model        {fmu.model_name}",
                 f"Description  {md.description or ''}",
                 f"FMI          {md.fmiVersion}  ({', '.join(k for k, v in (('Co-Simulation', md.coSimulation), ('Model Exchange', md.modelExchange)) if v is not None)})",
                 f"GUID         {fmu.guid}",
                 f"SHA-256      {fmu.sha256}",
                 f"Generated by {md.generationTool or 'unknown'}",
                 f"States       {md.numberOfContinuousStates}",
                 f"Output buffer {'yes (' + OUTPUT_INTERVAL + ')' if fmu.supports_output_buffer else 'no'}"]
        structural = {k: v for k, v in fmu.structural_values().items() if "[" not in k}
        if structural:
            lines.append(f"\nStructural ({len(structural)}, fixed when built; change with twin build --set):")
            for k, v in structural.items():
                var = fmu.variables[k]
                lines.append(f"  {k:32s} {v:>14d} {'':10s} {var.description}")
        for title, group in (("Inputs", fmu.inputs), ("Outputs", fmu.outputs), ("Parameters", fmu.parameters)):
            lines.append(f"\n{title} ({len(group)}):")
            arrays: dict[str, list[Variable]] = {}
            for v in group:
                base, bracket, _ = v.name.partition("[")
                if bracket:
                    arrays.setdefault(base, []).append(v)
            shown = set()
            for v in group:
                base, bracket, _ = v.name.partition("[")
                if bracket:
                    if base in shown:
                        continue
                    shown.add(base)
                    items = arrays[base]
                    starts = [x.start for x in items if x.start is not None]
                    rng = f"{min(starts):.4g}..{max(starts):.4g}" if starts else ""
                    lines.append(f"  {base + f'[1..{len(items)}]':32s} {rng:>14s} {v.unit:10s} {v.description}")
                    continue
                start = f"{v.start:.6g}" if v.start is not None else ""
                lines.append(f"  {v.name:32s} {start:>14s} {v.unit:10s} {v.description}")
        from twin.variants import geometry_summary
        geometry = geometry_summary(fmu)
        if geometry:
            lines += ["", *geometry]
        return "\n".join(lines)
