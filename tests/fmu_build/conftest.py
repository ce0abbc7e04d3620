"""Helpers shared by the fmu_build tests: throw-away Modelica packages and fmpy instances.

The session FMUs (``gearbox_fmu``, ``two_mass_fmu``) come from ``tests/conftest.py``.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import pytest


@pytest.fixture
def write_package():
    """Return ``write(root, package, body) -> Path`` that writes ``<root>/<package>.mo``.

    ``body`` is the text between ``package <package>`` and ``end <package>;`` (dedented), so
    line numbers in the file are ``2 + line number in body`` (line 1 is ``within ;``).
    """
    def write(root: Path, package: str, body: str) -> Path:
        root.mkdir(parents=True, exist_ok=True)
        path = root / f"{package}.mo"
        path.write_text(f'within ;\npackage {package} "Written by a test"\n'
                        f"{textwrap.dedent(body).strip(chr(10))}\nend {package};\n", encoding="utf-8")
        return path
    return write


@pytest.fixture(scope="session")
def unzip_fmu(tmp_path_factory):
    """Return ``unzip(fmu) -> (model_description, unzip_dir)``, extracting each FMU once."""
    from fmpy import extract, read_model_description

    cache: dict[Path, tuple] = {}

    def unzip(fmu: Path):
        fmu = Path(fmu)
        if fmu not in cache:
            target = tmp_path_factory.mktemp(fmu.stem.replace(".", "_"))
            cache[fmu] = (read_model_description(str(fmu)), Path(extract(str(fmu), unzipdir=str(target))))
        return cache[fmu]
    return unzip


@pytest.fixture
def open_slave(unzip_fmu):
    """Return ``open(fmu, step_size=None, **start_values) -> (slave, vr)``: an initialised FMU2Slave.

    ``start_values`` are set before initialisation (parameters, inputs); ``vr`` maps every Real
    variable name to its value reference.  All instances are terminated and freed at teardown.
    """
    from fmpy.fmi2 import FMU2Slave

    opened = []

    def open_(fmu: Path, step_size: float | None = None, **start_values):
        md, unzipped = unzip_fmu(fmu)
        vr = {v.name: v.valueReference for v in md.modelVariables if v.type == "Real"}
        slave = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped),
                          modelIdentifier=md.coSimulation.modelIdentifier, instanceName=f"test{len(opened)}")
        slave.instantiate()
        opened.append(slave)
        slave.setupExperiment(startTime=0.0)
        if step_size is not None:
            slave.setReal([vr["solver.step_size"]], [step_size])
        for name, value in start_values.items():
            slave.setReal([vr[name]], [value])
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        return slave, vr

    yield open_
    for slave in reversed(opened):
        slave.terminate()
        slave.freeInstance()


class TwoMassODE:
    """TwoMassOscillator's equations written out by hand from its .mo file.

    The state is augmented with the constant input force [N] as a fifth component, so that
    ``z(t) = expm(A t) z(0)`` with ``z = (x1 [m], v1 [m/s], x2 [m], v2 [m/s], force [N])``
    solves the forced response exactly.
    """

    defaults = {"m1": 1.0, "m2": 0.5, "k1": 100.0, "k12": 50.0, "d1": 0.2}
    x0 = (0.01, 0.0, 0.0, 0.0)
    states = ("x1", "v1", "x2", "v2")

    def matrix(self, **params):
        """(5, 5) system matrix of the augmented state for the given parameter overrides."""
        import numpy as np

        p = {**self.defaults, **params}
        m1, m2, k1, k12, d1 = (p[k] for k in ("m1", "m2", "k1", "k12", "d1"))
        return np.array([
            [0.0, 1.0, 0.0, 0.0, 0.0],
            [-(k1 + k12) / m1, -d1 / m1, k12 / m1, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0, 0.0],
            [k12 / m2, 0.0, -k12 / m2, 0.0, 1.0 / m2],
            [0.0, 0.0, 0.0, 0.0, 0.0],
        ])

    def solution(self, times, z0, **params):
        """(len(times), 5) exact augmented states at ``times`` [s] (measured from z0's time)."""
        import numpy as np
        from scipy.linalg import expm

        a = self.matrix(**params)
        return np.array([expm(a * t) @ np.asarray(z0, dtype=float) for t in times])


@pytest.fixture(scope="session")
def two_mass() -> TwoMassODE:
    """Closed-form reference of GearTwin.Examples.TwoMassOscillator (see :class:`TwoMassODE`)."""
    return TwoMassODE()
