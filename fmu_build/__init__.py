"""Modelica -> FMI 2.0 FMU builder (rumoca + CasADi + gcc). See fmu_build/README.md."""
from .build import DEFAULT_STEP_SIZE, build_fmu, flatten

__all__ = ["build_fmu", "flatten", "DEFAULT_STEP_SIZE"]
