"""Linearisation of an FMU about its operating point, and its natural frequencies.

The state Jacobian A = d(xdot)/dx is taken by central finite differences through the FMU's
Model Exchange interface (any FMI 2.0 FMU with ME works).  A gearbox's mesh stiffness varies
over the mesh cycle, so A is averaged over states sampled along a short co-simulated window
(default: 8 samples over 2.5 ms, about one mesh period of the rig at 20 Hz, after 50 ms of
settling).  For a time-invariant model the average equals the single-point Jacobian.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twin.errors import SimulationError
from twin.fmu import FMU


def state_jacobian(path: str | Path, *, parameters: Mapping[str, float] | None = None,
                   inputs: Mapping[str, float] | None = None, settle: float = 0.05,
                   window: float = 2.5e-3, samples: int = 8) -> tuple[np.ndarray, list[str]]:
    """Mesh-cycle-averaged state Jacobian.

    Returns
    -------
    A : (n, n) array, d(xdot)/dx in SI units.
    state_names : the n state names, in the FMU's derivative order.
    """
    with FMU(path) as fmu:
        f, x0, names = fmu.state_derivative_function(parameters, inputs)
        try:
            if samples <= 1 or window <= 0:
                points = [x0]
            else:
                points = _trajectory_states(fmu, names, parameters, inputs, settle, window, samples)
            jac = np.mean([_fd_jacobian(f, x) for x in points], axis=0)
        finally:
            f.close()
    return jac, names


def _trajectory_states(fmu: FMU, names, parameters, inputs, settle, window, samples):
    missing = [n for n in names if n not in fmu.variables]
    if missing:
        raise SimulationError(f"{fmu.model_name} does not expose its states {missing[:3]}... "
                              "as variables; use samples=1")
    fmu.setup(0.0, parameters=parameters, inputs=inputs)
    dt = window / samples
    if settle > 0:
        fmu.step(settle)
    out = []
    for _ in range(samples):
        fmu.step(dt)
        out.append(fmu.get(names))
    return out


def _fd_jacobian(f, x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    n = x.size
    jac = np.empty((n, n))
    for i in range(n):
        h = 1e-8 * max(1.0, abs(x[i]))
        xp = x.copy()
        xm = x.copy()
        xp[i] += h
        xm[i] -= h
        jac[:, i] = (f(xp) - f(xm)) / (2 * h)
    return jac


def modes(jac: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Oscillatory modes of x' = A x.

    Returns natural frequencies [Hz] (undamped, |lambda|/2pi), shape (m,), ascending, and the
    matching damping ratios (-Re(lambda)/|lambda|), shape (m,).
    Real eigenvalues (rigid-body rotation, the speed regulator) are not modes and are skipped.
    """
    lam = np.linalg.eigvals(jac)
    osc = lam[lam.imag > 1e-6 * np.maximum(1.0, np.abs(lam))]
    wn = np.abs(osc)
    order = np.argsort(wn)
    return wn[order] / (2 * np.pi), (-osc.real / wn)[order]


def natural_frequencies(path: str | Path, n: int = 8, **kwargs) -> np.ndarray:
    """The first ``n`` natural frequencies [Hz] of the FMU about its operating point, shape (n,)."""
    jac, _ = state_jacobian(path, **kwargs)
    freqs, _ = modes(jac)
    return freqs[:n]


@dataclass(frozen=True)
class LinearModel:
    """x' = A x + B u, y = C x about the operating point (mesh-cycle averaged).

    A (n, n) [SI]; B (n, m): response of x' to each excitation (a unit change of an input, or of
    a group of parameters moved together, e.g. every node of a profile deviation = a transmission
    error [m]); C (k, n): outputs per state.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    state_names: tuple[str, ...]
    excitations: tuple[str, ...]
    outputs: tuple[str, ...]


def linear_model(path: str | Path, *, parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, float] | None = None, outputs: Sequence[str] = (),
                 excitations: Mapping[str, Sequence[str]] | None = None, settle: float = 0.05,
                 window: float = 2.5e-3, samples: int = 8, step: float = 1e-9) -> LinearModel:
    """A, B and C by central differences, averaged over the same states as :func:`state_jacobian`.

    ``excitations`` maps a name to the parameters or inputs moved together by ``step`` (in their
    own units) to form one column of B; ``name[*]`` stands for every element of array ``name``.
    """
    excitations = dict(excitations or {})
    with FMU(path) as fmu:
        for key, group in list(excitations.items()):
            expanded = []
            for n in group:
                if n.endswith("[*]"):
                    expanded += [v for v in fmu.variables if v.startswith(n[:-2])]
                else:
                    expanded.append(n)
            if not expanded:
                raise SimulationError(f"{fmu.model_name} has no variable for the excitation {key!r} ({group})")
            excitations[key] = expanded
        f, x0, names = fmu.state_derivative_function(parameters, inputs)
        try:
            if samples <= 1 or window <= 0:
                points = [x0]
            else:
                points = _trajectory_states(fmu, names, parameters, inputs, settle, window, samples)
            base = {**(parameters or {}), **(inputs or {})}
            A = np.mean([_fd_jacobian(f, x) for x in points], axis=0)
            C = (np.mean([_fd_output(f, x, outputs) for x in points], axis=0) if outputs
                 else np.zeros((0, len(names))))
            cols = []
            for group in excitations.values():
                start = {n: float(base[n]) if n in base else float(fmu.variable(n).start or 0.0) for n in group}
                col = np.zeros(len(names))
                for x in points:
                    f.set({n: v + step for n, v in start.items()})
                    plus = f(x)
                    f.set({n: v - step for n, v in start.items()})
                    minus = f(x)
                    col += (plus - minus) / (2 * step)
                f.set(start)
                cols.append(col / len(points))
            B = np.array(cols).T if cols else np.zeros((len(names), 0))
        finally:
            f.close()
    return LinearModel(A, B, C, tuple(names), tuple(excitations), tuple(outputs))


def _fd_output(f, x: np.ndarray, outputs: Sequence[str]) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    out = np.empty((len(outputs), x.size))
    for i in range(x.size):
        h = 1e-8 * max(1.0, abs(x[i]))
        xp = x.copy()
        xm = x.copy()
        xp[i] += h
        xm[i] -= h
        out[:, i] = (f.outputs(xp, outputs) - f.outputs(xm, outputs)) / (2 * h)
    return out


@dataclass(frozen=True)
class ModalModel:
    """Oscillatory modes of a :class:`LinearModel` and how each one shows at the outputs.

    frequency (m,) [Hz] (undamped, ascending), damping (m,) [-], shapes (n, m) complex right
    eigenvectors, gain (k, e, m): peak |FRF| of each mode alone from excitation e to output k
    (|residue| / |Re lambda|, in output units per excitation unit).
    """

    frequency: np.ndarray
    damping: np.ndarray
    shapes: np.ndarray
    gain: np.ndarray
    eigenvalues: np.ndarray
    residues: np.ndarray          # (k, e, m) complex


def modal_model(lm: LinearModel) -> ModalModel:
    """Eigen-decomposition of A, with the residues of every mode from B to C."""
    lam, V = np.linalg.eig(lm.A)
    W = np.linalg.inv(V)
    osc = np.flatnonzero(lam.imag > 1e-6 * np.maximum(1.0, np.abs(lam)))
    osc = osc[np.argsort(np.abs(lam[osc]))]
    cv = lm.C @ V[:, osc]                                   # (k, m)
    wb = W[osc] @ lm.B                                      # (m, e)
    res = cv[:, None, :] * wb.T[None, :, :]                 # (k, e, m)
    wn = np.abs(lam[osc])
    gain = np.abs(res) / np.maximum(np.abs(lam[osc].real), 1e-12)
    return ModalModel(wn / (2 * np.pi), -lam[osc].real / wn, V[:, osc], gain, lam[osc], res)


def frequency_response(mm: ModalModel, freqs: np.ndarray) -> np.ndarray:
    """FRF (k, e, nf) from the oscillatory modes (each with its conjugate) at ``freqs`` [Hz]."""
    s = 2j * np.pi * np.asarray(freqs, float)
    lam = mm.eigenvalues
    terms = (mm.residues[..., None] / (s[None, None, None, :] - lam[None, None, :, None])
             + np.conj(mm.residues)[..., None] / (s[None, None, None, :] - np.conj(lam)[None, None, :, None]))
    return terms.sum(axis=2)
