"""Pure-Python reference FMU (FMI 2.0 co-simulation, pythonfmu) of the 21-DOF gearbox.

The slave wraps :mod:`twin.reference.gearbox_numpy`: every ``doStep`` integrates the
communication step with classical RK4 in equal sub-steps no longer than the parameter
``solver_step_size`` (default 5e-6 s), the same scheme as the compiled FMU's
``solver.step_size``, so both FMUs can be compared sample by sample.

Inside the FMU archive this file and ``gearbox_numpy.py`` sit side by side in ``resources/``
(pythonfmu puts that folder on ``sys.path`` and imports the slave module by its file name),
so the model module is imported flat there; inside the ``twin`` package it is imported
relatively.  pythonfmu runs the Python interpreter for every FMI call: it costs about 1.6 s
of wall time per simulated second even for a trivial model, so use it for short spans.

Variables
---------
inputs : ``motor_speed_ref`` [rad/s], ``drive_torque`` [N.m], ``load_torque`` [N.m]
outputs : the nine outputs of ``GearTwin.Gearbox21`` (``mesh_force`` [N], ``mesh_stiffness``
    [N/m], ``accel_pinion_casing`` / ``accel_gear_casing`` [m/s2], ``encoder_pinion_angle`` /
    ``encoder_gear_angle`` [rad], ``transmission_error`` [m], ``motor_speed`` [rad/s],
    ``motor_torque`` [N.m])
parameters : a subset of the Modelica parameters (:data:`PARAMETERS`, same names) plus
    ``solver_step_size`` [s]; all tunable, changes apply from the next ``doStep`` (the start
    state uses the values at the end of initialisation).
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real

if __package__:
    from . import gearbox_numpy as gn
else:  # loaded from the FMU's resources/ folder, next to gearbox_numpy.py
    import gearbox_numpy as gn

#: Modelica parameters exposed by the reference FMU (name -> description with unit).
PARAMETERS: dict[str, str] = {
    "c_mesh": "Mesh damping along the line of action [N.s/m]",
    "mesh_stiffness_scale": "Calibration multiplier of all pair stiffnesses [-]",
    "mesh_phase0": "Mesh phase at theta5 = 0 [rad]",
    "contact_smoothing": "Half-width of the entry/exit ramp of a tooth pair, fraction of the path of contact [-]",
    "I5": "Pinion and input shaft through casing [kg.m2]",
    "I10": "Gear and output shaft through casing [kg.m2]",
    "m5": "Pinion mass [kg]",
    "m10": "Gear mass [kg]",
    "c_motor": "Slope of the induction motor torque-slip line [N.m.s/rad]",
    "speed_ref_start": "Commanded motor speed assumed for the steady start [rad/s]",
    "load_start": "Brake torque used for the static pre-load at t = 0 [N.m]",
}
DEFAULT_STEP_SIZE = 5e-6

_INPUT_DESCRIPTIONS = {
    "motor_speed_ref": "Synchronous speed commanded by the drive [rad/s]",
    "drive_torque": "Extra motor torque added to the slip torque [N.m]",
    "load_torque": "Brake torque on the output shaft [N.m]",
}


class GearboxReference(Fmi2Slave):
    """21-DOF spur-gearbox reference model (numpy equations, fixed-step RK4 per doStep)."""

    author = "gear-twin"
    description = "Pure-Python reference of GearTwin.Gearbox21 (hand-written numpy equations, RK4)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        defaults = gn.GearboxParams()
        self._param_values = {name: float(getattr(defaults, name)) for name in PARAMETERS}
        self._params = defaults
        self._params_dirty = False
        self._inputs = dict(gn.DEFAULT_INPUTS)
        self._step_size = DEFAULT_STEP_SIZE
        self._x = gn.initial_state(defaults)
        self._out: dict[str, float] | None = None

        for name, desc in PARAMETERS.items():
            self.register_variable(Real(
                name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable,
                description=desc, getter=lambda n=name: self._param_values[n],
                setter=lambda v, n=name: self._set_param(n, v)))
        self.register_variable(Real(
            "solver_step_size", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable,
            description="Largest internal RK4 step [s]", getter=lambda: self._step_size,
            setter=self._set_step_size))
        for name, desc in _INPUT_DESCRIPTIONS.items():
            self.register_variable(Real(
                name, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                description=desc, getter=lambda n=name: self._inputs[n],
                setter=lambda v, n=name: self._set_input(n, v)))
        # initial="exact": pythonfmu always writes a start value, which FMI 2.0 only allows
        # for outputs whose initial attribute is exact.
        for name in gn.OUTPUT_NAMES:
            self.register_variable(Real(
                name, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                initial=Fmi2Initial.exact, getter=lambda n=name: self._output(n)))

    # ---- setters: invalidate the cached parameter set / outputs ------------------------------
    def _set_param(self, name: str, value: float):
        self._param_values[name] = float(value)
        self._params_dirty = True
        self._out = None

    def _set_step_size(self, value: float):
        if not value > 0:
            raise ValueError(f"solver_step_size must be > 0 s, got {value!r}")
        self._step_size = float(value)

    def _set_input(self, name: str, value: float):
        self._inputs[name] = float(value)
        self._out = None

    def _current_params(self) -> gn.GearboxParams:
        if self._params_dirty:
            self._params = gn.GearboxParams(**self._param_values)
            self._params_dirty = False
        return self._params

    def _output(self, name: str) -> float:
        if self._out is None:
            out = gn.outputs(0.0, self._x, self._current_params(), self._inputs)
            self._out = {k: float(v) for k, v in out.items()}
        return self._out[name]

    # ---- FMI life cycle ----------------------------------------------------------------------
    def exit_initialization_mode(self):
        # The start state depends on parameters (pre-load, start speed): build it from the
        # values set during initialisation.
        self._x = gn.initial_state(self._current_params())
        self._out = None

    def do_step(self, current_time: float, step_size: float) -> bool:
        self._x = gn.rk4_advance(self._x, step_size, self._current_params(), self._inputs, self._step_size)
        self._out = None
        return True


def build_reference_fmu(out_dir: Path | str) -> Path:
    """Build ``<out_dir>/GearboxReference.fmu`` with pythonfmu and return its path.

    The slave script and ``gearbox_numpy.py`` are staged in a temporary folder so the FMU
    carries both as flat modules; ``sys.path`` and ``sys.modules`` entries that pythonfmu's
    builder adds while importing the script are removed again, so the flat module names
    cannot shadow anything in this process later (e.g. when the FMU itself is loaded).
    """
    from pythonfmu.builder import FmuBuilder

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    here = Path(__file__).resolve().parent
    flat_names = ("gearbox_pythonfmu", "gearbox_numpy")
    saved_path = list(sys.path)
    saved_modules = {n: sys.modules[n] for n in flat_names if n in sys.modules}
    with tempfile.TemporaryDirectory(prefix="twin_reffmu_") as tmp:
        stage = Path(tmp)
        script = stage / "gearbox_pythonfmu.py"
        shutil.copy2(here / "gearbox_pythonfmu.py", script)
        shutil.copy2(here / "gearbox_numpy.py", stage / "gearbox_numpy.py")
        try:
            fmu = FmuBuilder.build_FMU(script, dest=out_dir, project_files=[stage / "gearbox_numpy.py"])
        finally:
            sys.path[:] = saved_path
            for n in flat_names:
                sys.modules.pop(n, None)
            sys.modules.update(saved_modules)
    return Path(fmu)
