"""The only module of ``twin`` that talks to FMUs (through fmpy).

It runs FMI 2.0 and FMI 3.0 Co-Simulation FMUs: it turns names into value references,
values into the variable's FMI type (every scalar type, see :mod:`twin.variables`), FMI status
codes into :class:`SimulationError`, and an FMU that ends the run itself (FMI 2.0
``fmi2Discard`` with ``fmi2Terminated``, FMI 3.0 ``terminateSimulation``) into a result that
stops at the FMU's last valid time, marked ``ended_by_fmu``.

High-rate outputs are captured without a Python call per sample where the FMU allows it: FMUs
built by ``fmu_build`` buffer their outputs inside each ``doStep`` (parameter
``solver.output_interval``) and the buffer is read with one C call per communication step.
Any other FMU works at one ``doStep`` and one get per type per output sample, on the grid
``start + k * output_interval`` that ``fmpy.simulate_fmu`` uses, so both give the same samples.

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
import warnings
import weakref
import zipfile
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from twin.errors import FMUError, ParameterError, SimulationError, TwinWarning
from twin.fmu_capture import Block, FMUCapture, RunEnd
from twin.fmu_description import OUTPUT_INTERVAL, STEP_SIZE, DefaultExperiment, FMUDescription, float_or_none
from twin.fmu_values import FMUValues
from twin.results import SimulationResult
from twin.variables import Variable, variables_from_description

__all__ = ["FMU", "Variable", "DefaultExperiment", "RunEnd", "Block", "simulate_fmu", "describe",
           "is_gearbox_model", "STEP_SIZE", "OUTPUT_INTERVAL"]

_STATUS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]

# fmpy getter/setter per FMI type (an enumeration is an Integer in FMI 2.0, an Int64 in FMI 3.0)
_ACCESS = {
    2: {"Real": "Real", "Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean", "String": "String"},
    3: {t: t for t in ("Float32", "Float64", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32",
                       "Int64", "UInt64", "Boolean", "String")} | {"Enumeration": "Int64"},
}
_FMI2_TERMINATED = 3          # fmi2StatusKind fmi2Terminated
_FMI2_LAST_SUCCESSFUL_TIME = 2  # fmi2StatusKind fmi2LastSuccessfulTime


# fmpy's logger proxy (which formats the printf arguments of FMI 2.0 messages) keeps ONE target
# logger per process. Registering a proxy per instance would redirect every other FMU's messages,
# fmpy's own included, to that instance's callback, and to freed memory once it is closed. So one
# proxy is registered, once, for a dispatcher that forwards by componentEnvironment to the live
# instance, and prints like fmpy for anything else.  (FMI 3.0 messages arrive formatted, through
# a callback per instance.)
_LOG_KEYS = itertools.count(1)
_LOG_TARGETS: dict[int, "weakref.WeakMethod"] = {}
_SHARED: dict[str, object] = {}


def _dispatch_log(env, instance, status, category, message):
    target = _LOG_TARGETS.get(int(env)) if env else None
    method = target() if target is not None else None
    if method is not None:
        method(status, message)
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


def file_sha256(path: Path) -> str:
    """The SHA-256 of a file (hex), which results record to name the FMU that made them."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


class FMU(FMUDescription, FMUValues, FMUCapture):
    """An FMI 2.0 or FMI 3.0 Co-Simulation FMU opened for simulation.

    This class makes the FMI calls; what it declares (:class:`~twin.fmu_description.FMUDescription`),
    values by name (:class:`~twin.fmu_values.FMUValues`) and the sampling of a run
    (:class:`~twin.fmu_capture.FMUCapture`) are its bases.

    Parameters
    ----------
    path : path of the ``.fmu`` file.
    instance_name : name passed to ``fmi2Instantiate`` / ``fmi3InstantiateCoSimulation``.

    Attributes
    ----------
    fmi_version : 2 or 3.
    variables : name -> :class:`~twin.variables.Variable`.
    default_experiment : the model's :class:`DefaultExperiment`.
    initial_parameters : every parameter's value right after initialisation (set by :meth:`setup`);
        this is what results record as their parameters.
    ended : a :class:`RunEnd` once the FMU has ended the run itself, else None.
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
        if md.fmiVersion == "2.0":
            self.fmi_version = 2
        elif str(md.fmiVersion).startswith("3."):
            self.fmi_version = 3
        else:
            raise FMUError(f"{self.path}: FMI version {md.fmiVersion} is not supported (2.0 and 3.0 are)")
        if md.coSimulation is None:
            raise FMUError(f"{self.path}: the FMU does not support Co-Simulation (it is Model Exchange only)")
        self.sha256 = file_sha256(self.path)
        self.variables: dict[str, Variable] = variables_from_description(md)
        de = md.defaultExperiment
        self.default_experiment = DefaultExperiment(
            *(float_or_none(getattr(de, a, None)) if de is not None else None
              for a in ("startTime", "stopTime", "stepSize", "tolerance")))
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
        self.initial_parameters: dict[str, Any] = {}
        self.ended: RunEnd | None = None

    def _auto_interval(self, span: float) -> float:
        """fmpy's automatic output interval [s] for a run of ``span`` s (500 to 1000 samples)."""
        from fmpy.util import auto_interval
        return float(auto_interval(span))

    # -- lifecycle -------------------------------------------------------------------------
    def _logger(self, status, message):
        text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
        if status >= 2:
            self._messages.append(text)
            del self._messages[:-20]        # the last few explain a failure; an FMU may log many

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

    def _log3(self):
        """An FMI 3.0 logMessage callback that reaches this instance without keeping it alive."""
        target = weakref.WeakMethod(self._logger)

        def log_message(env, status, category, message):
            method = target()
            if method is not None:
                method(status, message)
        return log_message

    def _status_name(self, status) -> str | None:
        if isinstance(status, int) and 0 <= status < len(_STATUS):
            return f"fmi{self.fmi_version}{_STATUS[status]}"
        return None

    def _call(self, what: str, fn, *args):
        try:
            return fn(*args)
        except Exception as exc:
            name = self._status_name(getattr(exc, "status", None))
            self._fatal = self._fatal or getattr(exc, "status", None) == 4   # fmiFatal
            detail = "; ".join(self._messages[-3:]) or str(exc)
            self._messages.clear()
            raise SimulationError(f"{self.model_name}: {what} failed: {detail}", time=self.time,
                                  status=name) from exc

    def _fn(self, name: str) -> str:
        """An FMI function name for this FMU's version (``Reset`` -> ``fmi2Reset``)."""
        if self.fmi_version == 2:
            name = name.replace("FMUState", "FMUstate")
        return f"fmi{self.fmi_version}{name}"

    def instantiate(self) -> None:
        """Load the binary and instantiate (idempotent)."""
        if self._slave is not None:
            return
        md = self.model_description
        kwargs = dict(guid=md.guid, unzipDirectory=self._unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=self._instance_name)
        try:
            if self.fmi_version == 2:
                from fmpy.fmi2 import FMU2Slave
                self._slave = FMU2Slave(**kwargs)
            else:
                from fmpy.fmi3 import FMU3Slave
                self._slave = FMU3Slave(**kwargs)
        except Exception as exc:
            raise FMUError(f"{self.path}: cannot load the binary for this platform: {exc}") from exc
        try:
            if self.fmi_version == 2:
                self._callbacks = self._make_callbacks()
                self._slave.instantiate(callbacks=self._callbacks)
            else:
                self._slave.instantiate(logMessage=self._log3())
        except Exception as exc:
            detail = "; ".join(self._messages) or str(exc)
            # the instance was not created: there is nothing to terminate or free (an FMU given a
            # NULL instance may crash), only the library to unload
            slave, self._slave = self._slave, None
            try:
                slave.freeLibrary()
            except Exception:  # the error below is the one the user needs
                pass
            raise FMUError(f"{self.path}: {self._fn('Instantiate')} failed: {detail}") from exc
        fn = getattr(self._slave.dll, f"twin_fmi{self.fmi_version}GetOutputBuffer", None)
        if fn is not None:
            fn.restype = ctypes.c_size_t
            fn.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.c_size_t]
        self._buffer_fn = fn

    def setup(self, start_time: float = 0.0, *, parameters: Mapping[str, Any] | None = None,
              inputs: Mapping[str, Any] | None = None, stop_time: float | None = None,
              tolerance: float | None = None) -> None:
        """Instantiate, set parameters, inputs and start values, and run the initialisation mode.

        Values are converted to each variable's type (text is parsed; an enumeration takes an
        item name); every bad name or value is refused before the FMU is touched.  As fmpy does,
        values that may be set while instantiated are set before initialisation, the others
        during it.  ``stop_time`` [s], if given, is passed on to the FMU.  Afterwards
        :attr:`initial_parameters` holds every parameter's value.
        """
        values = {**(parameters or {}), **(inputs or {})}
        typed = self._typed(values, initialised=False)
        self.instantiate()
        self.time = float(start_time)
        self._t_start = float(start_time)
        self.ended = None
        early = {n: x for n, x in typed.items()
                 if self.variables[n].causality == "input"
                 or (self.variables[n].variability != "constant" and self.variables[n].initial in ("exact", "approx"))}
        late = {n: x for n, x in typed.items() if n not in early}
        if self.fmi_version == 2:
            self._call("fmi2SetupExperiment", self._slave.setupExperiment, tolerance, self.time, stop_time)
            self._write(early)
            self._call("fmi2EnterInitializationMode", self._slave.enterInitializationMode)
        else:
            self._write(early)
            self._call("fmi3EnterInitializationMode", self._slave.enterInitializationMode, tolerance,
                       self.time, stop_time)
        self._write(late)
        self._call(self._fn("ExitInitializationMode"), self._slave.exitInitializationMode)
        self._initialized = True
        self.initial_parameters = self.parameter_values()

    def reset(self) -> None:
        """Return to the state right after instantiation (parameters back to defaults)."""
        if self._slave is not None:
            self._call(self._fn("Reset"), self._slave.reset)
        self.time = 0.0
        self._t_start = 0.0
        self._buffer_interval = None
        self._initialized = False
        self.ended = None
        self.initial_parameters = {}
        self._messages.clear()

    def close(self) -> None:
        if self._slave is not None:
            # fmiTerminate only for an initialised instance, and nothing after fmiFatal (FMI 2.0,
            # section 4.2.4); fmiFreeInstance for any instance that exists
            if self._initialized and not self._fatal:
                try:
                    self._slave.terminate()
                except Exception:  # terminating a failed instance may fail again; it is freed anyway
                    pass
            unloaded = False
            if not self._fatal and getattr(self._slave, "component", None):
                self._slave.freeInstance()
                unloaded = self.fmi_version == 3       # fmpy's FMI 3.0 freeInstance unloads the library too
            if not unloaded:
                try:
                    self._slave.freeLibrary()
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
    def _groups(self, variables: Iterable[Variable]) -> dict[str, list[int]]:
        """fmpy accessor suffix -> positions in ``variables``."""
        access = _ACCESS[self.fmi_version]
        groups: dict[str, list[int]] = {}
        for i, v in enumerate(variables):
            reason = v.unsupported_reason
            if reason:
                raise ParameterError(reason)
            kind = access.get(v.type)
            if kind is None:
                raise ParameterError(f"'{v.name}' has type {v.type}, which FMI {self.fmi_version}.0 does not define")
            groups.setdefault(kind, []).append(i)
        return groups

    def _write(self, values: Mapping[str, Any]) -> None:
        """Set already typed values, one FMI call per type."""
        if not values:
            return
        names = list(values)
        variables = [self.variables[n] for n in names]
        for kind, idx in self._groups(variables).items():
            vrs = [variables[i].value_reference for i in idx]
            vals = [values[names[i]] for i in idx]
            self._call(self._fn(f"Set{kind}"), getattr(self._slave, f"set{kind}"), vrs, vals)

    def _read(self, variables: Sequence[Variable]) -> list:
        """Current values of ``variables`` as Python values of their types, one FMI call per type."""
        self.instantiate()
        out: list = [None] * len(variables)
        for kind, idx in self._groups(variables).items():
            vrs = [variables[i].value_reference for i in idx]
            vals = self._call(self._fn(f"Get{kind}"), getattr(self._slave, f"get{kind}"), vrs)
            for i, x in zip(idx, vals):
                if kind == "String":
                    x = x.decode("utf-8", "replace") if isinstance(x, bytes) else ("" if x is None else str(x))
                elif kind == "Boolean":
                    x = bool(x)
                out[i] = x
        return out

    # -- stepping --------------------------------------------------------------------------
    def _do_step(self, h: float) -> bool:
        """One doStep of ``h`` s from :attr:`time`. True when completed; False when the FMU ended
        the run (then :attr:`ended` says where and why and :attr:`time` is that time)."""
        t = self.time
        if self.ended is not None:
            raise SimulationError(f"{self.model_name} ended the run at t={self.ended.time:.6g} s; "
                                  "it cannot step further", time=self.time)
        if self.fmi_version == 2:
            try:
                self._slave.doStep(t, h)
                return True
            except Exception as exc:
                if getattr(exc, "status", None) != 2:
                    return self._call("fmi2DoStep", self._raise, exc)
            terminated = self._status(self._slave.getBooleanStatus, _FMI2_TERMINATED)
            last = self._status(self._slave.getRealStatus, _FMI2_LAST_SUCCESSFUL_TIME)
            how = "fmi2DoStep returned fmi2Discard" + (" with fmi2Terminated" if terminated else "")
            return self._end(t, h, last, how)
        from fmpy.fmi3 import fmi3Boolean, fmi3Float64
        event, terminate, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
        try:
            self._slave.fmi3DoStep(self._slave.component, t, h, fmi3Boolean(True), ctypes.byref(event),
                                   ctypes.byref(terminate), ctypes.byref(early), ctypes.byref(last))
        except Exception as exc:
            if getattr(exc, "status", None) != 2:
                return self._call("fmi3DoStep", self._raise, exc)
            return self._end(t, h, last.value, "fmi3DoStep returned fmi3Discard")
        if terminate.value:
            return self._end(t, h, last.value, "fmi3DoStep set terminateSimulation")
        if early.value:
            raise SimulationError(f"{self.model_name}: fmi3DoStep returned early although early return "
                                  "was not allowed", time=t, status="fmi3OK")
        return True

    @staticmethod
    def _raise(exc):
        raise exc

    def _status(self, fn, kind):
        try:
            return fn(kind)
        except Exception:       # an FMU may not provide the status; the step start is used then
            return None

    def step(self, dt: float) -> None:
        """Advance one communication step of ``dt`` seconds (or less, if the FMU ends the run:
        then :attr:`ended` is set)."""
        if not dt > 0:
            raise SimulationError(f"communication step must be > 0 s, got {dt!r}", time=self.time)
        if self._do_step(dt):
            self.time += dt

    def get_state(self):
        """Opaque snapshot of the FMU (fmiGetFMUstate); restore it with :meth:`set_state`."""
        return self._call(self._fn("GetFMUState"), self._slave.getFMUState), self.time

    def set_state(self, state) -> None:
        handle, t = state
        self._call(self._fn("SetFMUState"), self._slave.setFMUState, handle)
        self.time = t
        self.ended = None
        self._buffer_interval = self.get(OUTPUT_INTERVAL) if self.supports_output_buffer else None

    def free_state(self, state) -> None:
        self._call(self._fn("FreeFMUState"), self._slave.freeFMUState, state[0])

    # -- capture from the output buffer of FMUs built by fmu_build ------------------------------
    def _capture_buffered(self, k_now: int, m: int, output_interval: float, variables: Sequence[Variable]) -> Block:
        all_outputs = [v.name for v in self.outputs]
        try:
            cols = [all_outputs.index(v.name) for v in variables]
        except ValueError:
            extra = [v.name for v in variables if v.name not in all_outputs]
            raise ParameterError(f"only outputs can be recorded from the buffer; not outputs: {extra}") from None
        if self._buffer_interval != output_interval:
            self.set({OUTPUT_INTERVAL: output_interval})
            self._buffer_interval = output_interval
        if self._scratch is None or self._scratch.shape[0] < m + 2:
            self._scratch = np.empty((m + 2, max(len(all_outputs), 1)))
        t_end = self._t_start + (k_now + m) * output_interval
        completed = self._do_step(t_end - self.time)
        got = self._buffer_fn(self._slave.component,
                              self._scratch.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
                              self._scratch.shape[0])
        if completed:
            self.time = t_end
            if got != m:
                raise SimulationError(f"output buffer held {got} samples, expected {m}", time=self.time)
        got = min(int(got), m)
        times = self._t_start + (k_now + 1 + np.arange(got)) * output_interval
        return Block(times, tuple(self._scratch[:got, c].copy() for c in cols))

    # -- Model Exchange view for linearisation -------------------------------------------------
    def state_derivative_function(self, parameters: Mapping[str, float] | None = None,
                                  inputs: Mapping[str, float] | None = None):
        """Return ``(f, x0, state_names)`` where ``f(x) -> xdot`` uses the FMU's Model Exchange interface.

        ``x0`` (n,) holds the initial states; the caller must call ``f.close()`` when done.
        ``f.outputs(x, names)`` gives variables (outputs) at state ``x``; ``f.set({name: value})``
        changes parameters or inputs for the following evaluations (calculated parameters follow).
        Linearisation uses FMI 2.0 Model Exchange.
        """
        md = self.model_description
        if md.modelExchange is None:
            raise FMUError(f"{self.path}: no Model Exchange interface, cannot linearise")
        if self.fmi_version != 2:
            raise FMUError(f"{self.path}: linearisation uses FMI 2.0 Model Exchange; this FMU is FMI 3.0")
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


def simulate_fmu(path: str | Path, *, stop_time: float | None = None, start_time: float | None = None,
                 output_interval: float | None = None, outputs: Sequence[str] | None = None,
                 parameters: Mapping[str, Any] | None = None, inputs: Mapping[str, Any] | None = None,
                 progress: bool = False, step_size: float | None = None) -> SimulationResult:
    """Simulate an FMU with constant inputs and return its sampled outputs (like ``fmpy.simulate_fmu``).

    Times left out come from the model's default experiment (see :meth:`FMU.experiment`).
    Values may be of any variable type, or text to be parsed.  ``step_size`` [s] sets the
    internal solver step of FMUs built by ``fmu_build``.  If the FMU ends the run before
    ``stop_time``, the result stops there and is marked ``ended_by_fmu``.
    """
    params = dict(parameters or {})
    with FMU(path) as fmu:
        start, stop, interval = fmu.experiment(start_time, stop_time, output_interval)
        step = fmu.default_experiment.step_size
        if output_interval is None and step and interval > step * (1 + 1e-9):
            warnings.warn(TwinWarning(f"output interval {interval:g} s: the model's step {step:g} s doubled to at "
                                      f"most 1000 intervals, as fmpy does; give --output-interval {step:g} "
                                      "for every step"))
        if step_size is not None:
            if STEP_SIZE not in fmu.variables:
                raise ParameterError(f"{fmu.model_name} has no {STEP_SIZE} parameter (not built by fmu_build)")
            params[STEP_SIZE] = step_size
        fmu._recorded(outputs)            # refuse bad output names before running
        if outputs is None:
            fmu.warn_unrecorded_outputs()
        fmu.setup(start, parameters=params, inputs=inputs, stop_time=stop)
        return fmu.run(stop, interval, outputs=outputs, progress=progress)


def is_gearbox_model(path: str | Path) -> bool:
    """True for the spur-gearbox models built from ``modelica/`` (``GearTwin.*`` with the casing
    accelerometers), whose natural frequencies the paper measured."""
    from fmpy.model_description import read_model_description
    try:
        md = read_model_description(str(path))
    except Exception as exc:
        raise FMUError(f"{path}: invalid modelDescription.xml: {exc}") from exc
    return (str(md.modelName).startswith("GearTwin.")
            and any(v.name == "accel_pinion_casing" for v in md.modelVariables))


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
    """Human-readable summary of an FMU: identity, description, default experiment, interfaces
    and variables with types, start values and units (see :mod:`twin.fmu_info`)."""
    from twin.fmu_info import describe_fmu
    with FMU(path) as fmu:
        return describe_fmu(fmu)
