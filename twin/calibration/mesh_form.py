"""The gears' as-manufactured profile deviation, fitted to the measured gear-mesh harmonics.

At light load the static transmission error of real spur gears comes mostly from their geometry,
not from the tooth stiffness varying along the mesh: ISO 1328-1 allows a profile slope deviation
f_H_alpha and a profile form deviation f_f_alpha of 5-6 um at grade 5 for a module-3 pinion of
50-125 mm (ISO 1328-1:1995 tables), doubling every two grades, while the twin's static mesh
deflection at 20 N.m is about 2.5 um.  The twin's flanks are perfect involutes by default, so its
mesh lines are what the stiffness variation alone makes, and a calibration matched the measured
lines only with a sensor gain far outside a sensor's tolerance.

Two shapes along the path of contact, common to every tooth, on the FMU's
``profile_deviation[1..n]`` (material missing from the pinion flank at equally spaced roll
positions xi in [0, 1]; a constant is backlash and changes nothing):

* **slope** s [m]: ``s * xi`` (s > 0: material missing towards the pinion's tip, s < 0: towards its
  root), the slope deviation;
* **crowning** c [m]: ``c * (2 xi - 1)^2`` (c > 0: material missing at both ends, a crowned or
  relieved profile; c < 0: in the middle, a hollow one), the form deviation's lowest shape.

The mesh's response is not linear in them (a deviation of a few um takes pairs out of contact and
brings them back), so each candidate (s, c) is simulated: the mesh alone (no broadband, gain 1),
its harmonics 1-6 against the measured ones (those standing 6 dB out of their surroundings),
scored by their RMS dB difference at the sensor's own gain (its value in ``parameters``, else the
FMU's start, 1).  The gain is not fitted here: with it free, a larger deviation read at a smaller
gain matched the lines as well (the level is then not identifiable); the level fit that follows
sets the gain from the lines the fitted profile makes.  Six line amplitudes do not fix both shapes
(a steep slope with a little crowning and a milder slope with a hollow can give the same lines), so
among profiles that match alike the smallest is taken: :data:`PENALTY` dB per um of the larger
amplitude is added to the score.  A 9 x 9 grid over +-:data:`BOUND`, then Nelder-Mead from the
best point.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from twin.calibration.levels import PROCESS, ROUGHNESS, SENSOR_OF_CHANNEL, mesh_lines

#: Largest |slope| and |crowning| [m]: about ISO 1328-1 grade 9 for a module-3 pinion.
BOUND = 20e-6
#: Score added per um of the larger of |slope| and |crowning| [dB/um]: the smallest of equal fits.
PENALTY = 0.1
PARAMETER = "profile_deviation"


def profile(slope: float, crowning: float, n_nodes: int) -> np.ndarray:
    """Material missing from the pinion flank at the ``n_nodes`` roll positions [m], (n_nodes,), >= 0."""
    from twin.degradation._nodes import node_xi
    xi = node_xi(n_nodes)
    e = slope * xi + crowning * (2.0 * xi - 1.0) ** 2
    return e - e.min()


def has_profile(fmu_path) -> bool:
    """Whether the FMU takes a profile deviation (``profile_deviation[1]``)."""
    from twin.fmu import FMU
    with FMU(fmu_path) as fmu:
        return f"{PARAMETER}[1]" in fmu.variables


@dataclass(frozen=True)
class MeshFormFit:
    """The fitted profile deviation and what it changed."""

    slope: float                   # [m]
    crowning: float                # [m]
    parameters: Mapping[str, float]   # profile_deviation[1..n] [m]
    lines_db_before: float         # RMS dB error of the mesh harmonics with perfect involutes, at the gain
    lines_db_after: float          # the same with the fitted deviation
    gain_before: float             # the gain the lines asked for with perfect involutes [-]
    gain_after: float              # ... with the fitted deviation [-]
    harmonics: tuple[int, ...]     # the mesh harmonics used
    simulations: int

    def on_bound(self) -> bool:
        return max(abs(self.slope), abs(self.crowning)) >= 0.999 * BOUND

    def describe(self) -> str:
        return (f"as-manufactured profile: slope {1e6 * self.slope:+.2f} um, crowning {1e6 * self.crowning:+.2f} um "
                f"(mesh harmonics {', '.join(map(str, self.harmonics))}: {self.lines_db_before:.1f} -> "
                f"{self.lines_db_after:.1f} dB RMS; gain asked {self.gain_before:.3g} -> {self.gain_after:.3g}; "
                f"{self.simulations} simulations)")


def fit_mesh_form(fmu_path, parameters: Mapping[str, float], measured, fs: float, *, speed_hz: float,
                  load_nm: float, channel: str, fmax: float, settle: float = 0.1, duration: float = 0.5
                  ) -> MeshFormFit:
    """Fit the slope and crowning of the pinion's profile to the measured mesh harmonics.

    ``measured`` (n,) samples at ``fs`` [Hz] of ``channel`` (a casing sensor of a model with
    ``profile_deviation`` and the broadband sources, e.g. ``GearTwin.Gearbox21Measured``);
    ``parameters`` the calibrated ones so far.  Raises ValueError when no measured mesh harmonic
    stands out of its surroundings.
    """
    from scipy.optimize import minimize

    from twin.fmu import FMU
    from twin.operating import simulate_operating_point

    sensor = SENSOR_OF_CHANNEL[channel]
    with FMU(fmu_path) as fmu:
        n_nodes = int(fmu.structural_values().get("n_profile", 11))
        gain = float(parameters.get(f"{sensor}.gain", fmu.variable(f"{sensor}.gain").start))
    measured = np.asarray(measured, float)
    line_meas, ring_meas = mesh_lines(measured, fs, speed_hz, fmax=fmax)
    usable = np.isfinite(line_meas) & (line_meas > 0) & (line_meas >= 4.0 * ring_meas)
    if not usable.any():
        raise ValueError("no gear-mesh harmonic stands out of the measured spectrum: the profile cannot be fitted")
    base = {**parameters, f"{sensor}.gain": 1.0, ROUGHNESS[0]: 0.0, ROUGHNESS[1]: 0.0, PROCESS: 0.0}
    g = 20 * math.log10(gain)
    cache: dict[tuple[int, int], tuple[float, float]] = {}

    def point(q) -> tuple[float, float, tuple[int, int]]:
        """(slope, crowning [m], cache key in nm: the simplex revisits points) of a scaled point q."""
        s, c = (float(np.clip(v, -1.0, 1.0)) * BOUND for v in q)
        return s, c, (round(s * 1e9), round(c * 1e9))

    def nodes(s: float, c: float) -> dict[str, float]:
        return {f"{PARAMETER}[{i}]": float(v) for i, v in enumerate(profile(s, c, n_nodes), 1)}

    def score(q) -> float:
        s, c, key = point(q)
        if key not in cache:
            y = simulate_operating_point(fmu_path, speed_hz, load_nm, parameters={**base, **nodes(s, c)},
                                         settle=settle, duration=duration, channels=[channel],
                                         output_interval=1.0 / fs)[:, 0]
            line, _ = mesh_lines(y, fs, speed_hz, fmax=fmax)
            ok = usable & (line > 0)
            if not ok.any():
                cache[key] = (math.inf, math.nan)
            else:
                need = 10 * np.log10(line_meas[ok] / line[ok])      # dB of gain each harmonic asks for
                cache[key] = (float(np.sqrt(np.mean((need - g) ** 2))), 10 ** (float(np.mean(need)) / 20))
        return cache[key][0] + PENALTY * 1e6 * max(abs(s), abs(c))

    grid = np.linspace(-1.0, 1.0, 9)
    points = [(a, b) for a in grid for b in grid]
    scores = [score(p) for p in points]
    before, gain_before = cache[(0, 0)]
    best = np.array(points[int(np.argmin(scores))])
    step = np.where(best > 0, -0.125, 0.125)        # into the box from a point on its edge
    res = minimize(score, best, method="Nelder-Mead",
                   options={"initial_simplex": [best, best + [step[0], 0.0], best + [0.0, step[1]]], "maxfev": 24,
                            "xatol": 0.01, "fatol": 0.05})
    s, c, key = point(res.x if res.fun <= min(scores) else best)
    after, gain_after = cache[key]
    return MeshFormFit(s, c, nodes(s, c), before, after, gain_before, gain_after,
                       tuple(int(k) + 1 for k in np.flatnonzero(usable)), len(cache))
