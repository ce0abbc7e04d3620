"""Independent reference implementations of the gearbox model, used to verify the compiled FMU.

* :mod:`twin.reference.gearbox_numpy` -- the 21-DOF equations hand-written in numpy, with
  fixed-step RK4 and ``scipy.integrate.solve_ivp`` simulators and the linearised model.
* :mod:`twin.reference.gearbox_pythonfmu` -- the same equations packaged as a pure-Python
  FMI 2.0 co-simulation FMU with pythonfmu.
"""
from .gearbox_numpy import (
    DEFAULT_INPUTS,
    DOF_NAMES,
    OUTPUT_NAMES,
    STATE_NAMES,
    GearboxParams,
    initial_state,
    mass_matrix_stiffness,
    natural_frequencies,
    outputs,
    rhs,
    rk4_advance,
    simulate_rk4,
    simulate_solve_ivp,
)

__all__ = [
    "DEFAULT_INPUTS", "DOF_NAMES", "OUTPUT_NAMES", "STATE_NAMES", "GearboxParams", "initial_state",
    "mass_matrix_stiffness", "natural_frequencies", "outputs", "rhs", "rk4_advance", "simulate_rk4",
    "simulate_solve_ivp",
]
