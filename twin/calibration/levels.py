"""The level of the twin's spectrum: sensor gain, roughness and process-force levels fitted to a record.

With ``GearTwin.Gearbox21Measured`` the spectrum at a casing sensor is, in power, the sum of
three uncorrelated parts seen through the sensor's gain ``g``:

    P(f) = g^2 * (M(f) + a * R(f) + b * F(f)),

``M`` from the mesh (stiffness variation under load: physics, no free level), ``R`` from the flank
roughness and ``F`` from the process force, ``a`` and ``b`` the squared ratios of their RMS levels
to the values simulated. So three simulations (nothing; roughness alone added; process force
alone added) give every level at once: ``g^2``, ``a`` and ``b`` are fitted to the measured
spectrum's band levels (1/12 octave) by least squares in dB, with a fourth term for the
measurement's own noise (white; it is reported, not put in the model). The mesh lines fix the
gain, the floor between them the roughness and process levels.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

#: Sensor instance of GearTwin.Gearbox21Measured behind each casing channel.
SENSOR_OF_CHANNEL = {"accel_pinion_casing": "sensor_pinion", "accel_gear_casing": "sensor_gear"}
ROUGHNESS = ("pinion_roughness.rms", "gear_roughness.rms")
PROCESS = "process.rms"
BANDS_PER_OCTAVE = 12


def band_levels(x, fs: float, fmin: float, fmax: float, *, resolution: float,
                bands_per_octave: int = BANDS_PER_OCTAVE) -> tuple[np.ndarray, np.ndarray]:
    """(centre frequencies (m,) [Hz], mean PSD in each band (m,) [unit^2/Hz]) over [fmin, fmax].

    Welch PSD at ``resolution`` [Hz], averaged over bands of constant relative width; bands
    holding fewer than 3 bins are merged upwards, so low bands are never one bin. Two signals
    analysed at the same resolution get the same bands.
    """
    from twin.signals import welch_psd

    x = np.asarray(x, float)
    f, p = welch_psd(x, fs, resolution=resolution)
    edges = fmin * 2.0 ** (np.arange(0, np.log2(fmax / fmin) * bands_per_octave + 1) / bands_per_octave)
    centres, levels = [], []
    lo = edges[0]
    for hi in edges[1:]:
        sel = (f >= lo) & (f < hi)
        if sel.sum() < 3:
            continue
        centres.append(np.sqrt(lo * hi))
        levels.append(float(np.mean(p[sel])))
        lo = hi
    return np.array(centres), np.array(levels)


@dataclass(frozen=True)
class LevelFit:
    gain: float                  # sensor gain g [-]
    roughness_scale: float       # factor on the simulated roughness RMS [-]
    process_scale: float         # factor on the simulated process-force RMS [-]
    noise_psd: float             # white measurement noise [unit^2/Hz]
    distance_db: float           # RMS dB difference of the band levels after the fit
    parameters: Mapping[str, float]   # FMU parameter values to set

    def describe(self) -> str:
        return (f"sensor gain {self.gain:.3g}, roughness x{self.roughness_scale:.3g}, process force "
                f"x{self.process_scale:.3g}, measurement noise {self.noise_psd:.3g} /Hz; band levels within "
                f"{self.distance_db:.2f} dB RMS")


def has_levels(fmu_path, channel: str) -> bool:
    """Whether the FMU has the sensor gain of ``channel`` and the broadband sources."""
    from twin.fmu import FMU
    with FMU(fmu_path) as fmu:
        names = set(fmu.variables)
    sensor = SENSOR_OF_CHANNEL.get(channel)
    return sensor is not None and f"{sensor}.gain" in names and PROCESS in names and all(r in names for r in ROUGHNESS)


def fit_levels(fmu_path, parameters: Mapping[str, float], measured, fs: float, *, speed_hz: float, load_nm: float,
               channel: str, fmin: float, fmax: float, settle: float = 0.1, duration: float = 0.5) -> LevelFit:
    """Fit the sensor gain and the broadband levels to a measured steady record (see the docstring)."""
    from scipy.optimize import least_squares

    from twin.fmu import FMU
    from twin.operating import simulate_operating_point

    sensor = SENSOR_OF_CHANNEL[channel]
    with FMU(fmu_path) as fmu:
        start = {n: float(parameters.get(n, fmu.variable(n).start)) for n in (*ROUGHNESS, PROCESS)}
    r0 = max(start[ROUGHNESS[0]], 1e-9)
    p0 = max(start[PROCESS], 1e-3)
    base = {**parameters, f"{sensor}.gain": 1.0}
    runs = {"mesh": {**base, ROUGHNESS[0]: 0.0, ROUGHNESS[1]: 0.0, PROCESS: 0.0},
            "roughness": {**base, ROUGHNESS[0]: r0, ROUGHNESS[1]: r0, PROCESS: 0.0},
            "process": {**base, ROUGHNESS[0]: 0.0, ROUGHNESS[1]: 0.0, PROCESS: p0}}
    measured = np.asarray(measured, float)
    resolution = max(2.0, 8.0 / min(duration, measured.size / fs))
    levels = {}
    for name, values in runs.items():
        x = simulate_operating_point(fmu_path, speed_hz, load_nm, parameters=values, settle=settle, duration=duration,
                                     channels=[channel], output_interval=1.0 / fs)[:, 0]
        fc, levels[name] = band_levels(x, fs, fmin, fmax, resolution=resolution)
    fm, lm = band_levels(measured, fs, fmin, fmax, resolution=resolution)
    n = fc.size
    M = levels["mesh"][:n]
    R = np.maximum(levels["roughness"][:n] - M, 1e-6 * levels["roughness"][:n])
    F = np.maximum(levels["process"][:n] - M, 1e-6 * levels["process"][:n])
    target = 10 * np.log10(lm[:n])
    noise0 = float(np.min(lm[:n]))

    def model(q):
        g2, a, b, w = np.exp(q)
        return 10 * np.log10(g2 * (M + a * R + b * F) + w * noise0)

    q0 = np.log([np.median(lm[:n] / np.maximum(M + R + F, 1e-300)), 1.0, 1.0, 0.1])
    sol = least_squares(lambda q: model(q) - target, q0, bounds=(q0 - 25, q0 + 25))
    g2, a, b, w = np.exp(sol.x)
    gain = float(np.sqrt(g2))
    rs, ps = float(np.sqrt(a)), float(np.sqrt(b))
    values = {f"{sensor}.gain": gain, ROUGHNESS[0]: r0 * rs, ROUGHNESS[1]: r0 * rs, PROCESS: p0 * ps}
    return LevelFit(gain, rs, ps, float(w * noise0), float(np.sqrt(np.mean(sol.fun ** 2))), values)
