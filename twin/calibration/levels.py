"""The level of the twin's spectrum: sensor gain, roughness and process-force levels fitted to a record.

With ``GearTwin.Gearbox21Measured`` the spectrum at a casing sensor is, in power, the sum of
three uncorrelated parts seen through the sensor's gain ``g``:

    P(f) = g^2 * (M(f) + a * R(f) + b * F(f)),

``M`` from the mesh (stiffness variation under load: physics, no free level), ``R`` from the flank
roughness and ``F`` from the process force, ``a`` and ``b`` the squared ratios of their RMS levels
to the values simulated. So three simulations (nothing; roughness alone added; process force
alone added) give every level at once. The gain comes from the gear-mesh harmonics (measured over
simulated amplitude: band levels alone cannot tell a louder mesh from more roughness, whose
orders include the mesh orders; the roughness in the measured lines biases it by up to about
20 %), held to the range the sensor declares (a gain the lines push beyond it says the twin's mesh
excitation or its path is off, not the sensor: a warning); ``a`` and ``b`` are then fitted to the
measured spectrum's band levels (1/12 octave) by least squares in dB, with a third term for the
measurement's own noise (white, so at most the level of the quietest measured band; it is
reported, not put in the model).
"""
from __future__ import annotations

import math
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
    gain: float                  # sensor gain g [-], within the sensor's declared range
    roughness_scale: float       # factor on the simulated roughness RMS [-]
    process_scale: float         # factor on the simulated process-force RMS [-]
    noise_psd: float             # white measurement noise [unit^2/Hz], at most the quietest band's level
    distance_db: float           # RMS dB difference of the band levels after the fit
    parameters: Mapping[str, float]   # FMU parameter values to set
    band_hz: np.ndarray | None = None       # (m,) band centres [Hz]
    measured_db: np.ndarray | None = None   # (m,) measured band levels [dB]
    model_db: np.ndarray | None = None      # (m,) fitted model band levels, noise included [dB]
    gain_wanted: float | None = None        # the gain the mesh lines asked for, before the declared range [-]

    @property
    def gain_on_bound(self) -> bool:
        """Whether the mesh lines asked for a gain outside the sensor's declared range."""
        return self.gain_wanted is not None and not math.isclose(self.gain_wanted, self.gain, rel_tol=1e-9)

    def describe(self) -> str:
        return (f"sensor gain {self.gain:.3g}, roughness x{self.roughness_scale:.3g}, process force "
                f"x{self.process_scale:.3g}, measurement noise {self.noise_psd:.3g} /Hz; band levels within "
                f"{self.distance_db:.2f} dB RMS")

    def warning(self) -> str | None:
        """A one-line warning when the sensor gain is held at a bound of its declared range, else None."""
        if not self.gain_on_bound:
            return None
        return (f"sensor gain held at {self.gain:.3g}: the measured gear-mesh harmonics ask for {self.gain_wanted:.3g} "
                f"({20 * math.log10(self.gain_wanted / self.gain):+.1f} dB), more than a sensor's sensitivity error; "
                "the twin's mesh excitation or its path to the casing is off")


def has_levels(fmu_path, channel: str) -> bool:
    """Whether the FMU has the sensor gain of ``channel`` and the broadband sources."""
    from twin.fmu import FMU
    with FMU(fmu_path) as fmu:
        names = set(fmu.variables)
    sensor = SENSOR_OF_CHANNEL.get(channel)
    return sensor is not None and f"{sensor}.gain" in names and PROCESS in names and all(r in names for r in ROUGHNESS)


def fit_levels(fmu_path, parameters: Mapping[str, float], measured, fs: float, *, speed_hz: float, load_nm: float,
               channel: str, fmin: float, fmax: float, settle: float = 0.1, duration: float = 0.5) -> LevelFit:
    """Fit the sensor gain and the broadband levels to a measured steady record (see the docstring).

    ``measured`` (n,) samples at ``fs`` [Hz] of ``channel``; ``speed_hz`` [Hz] and ``load_nm``
    [N.m] the operating point of the three simulations. Every fitted value stays within the range
    the FMU declares for it; a gain the mesh lines push beyond it is held at the bound before the
    broadband levels are fitted, and reported (:meth:`LevelFit.warning`).
    """
    from scipy.optimize import least_squares

    from twin.fmu import FMU
    from twin.operating import simulate_operating_point

    sensor = SENSOR_OF_CHANNEL[channel]
    with FMU(fmu_path) as fmu:
        start = {n: float(parameters.get(n, fmu.variable(n).start)) for n in (*ROUGHNESS, PROCESS)}
        limits = {sv.name: (sv.min, sv.max) for sv in fmu.model_description.modelVariables}
    r0 = max(start[ROUGHNESS[0]], 1e-9)
    p0 = max(start[PROCESS], 1e-3)
    base = {**parameters, f"{sensor}.gain": 1.0}
    runs = {"mesh": {**base, ROUGHNESS[0]: 0.0, ROUGHNESS[1]: 0.0, PROCESS: 0.0},
            "roughness": {**base, ROUGHNESS[0]: r0, ROUGHNESS[1]: r0, PROCESS: 0.0},
            "process": {**base, ROUGHNESS[0]: 0.0, ROUGHNESS[1]: 0.0, PROCESS: p0}}
    measured = np.asarray(measured, float)
    resolution = max(2.0, 8.0 / min(duration, measured.size / fs))
    levels, signals = {}, {}
    for name, values in runs.items():
        signals[name] = simulate_operating_point(fmu_path, speed_hz, load_nm, parameters=values, settle=settle,
                                                 duration=duration, channels=[channel], output_interval=1.0 / fs)[:, 0]
        fc, levels[name] = band_levels(signals[name], fs, fmin, fmax, resolution=resolution)
    fm, lm = band_levels(measured, fs, fmin, fmax, resolution=resolution)
    n = fc.size
    M = levels["mesh"][:n]
    R = np.maximum(levels["roughness"][:n] - M, 1e-6 * levels["roughness"][:n])
    F = np.maximum(levels["process"][:n] - M, 1e-6 * levels["process"][:n])
    target = 10 * np.log10(lm[:n])
    # White measurement noise cannot stand above the quietest band of what was measured: left
    # free, it took the place of the broadband content the spectrum needs from the model.
    noise0 = float(np.min(lm[:n]))
    # The gain from the mesh lines: band levels alone cannot tell a louder mesh from more
    # roughness, whose orders include the mesh orders. The measured lines hold some roughness too
    # (added with a random phase), which biases the gain by up to about 20 %.
    line_meas, ring_meas = mesh_lines(measured, fs, speed_hz, fmax=fmax)
    line_mesh, _ = mesh_lines(signals["mesh"], fs, speed_hz, fmax=fmax)
    usable = np.isfinite(line_meas) & (line_meas >= 4.0 * ring_meas) & (line_mesh > 0)
    if not usable.any():
        raise ValueError("no gear-mesh harmonic stands out of the measured spectrum: the sensor gain cannot be set")
    gain_wanted = float(np.sqrt(np.median(line_meas[usable] / line_mesh[usable])))
    # held to the sensor's declared range before the broadband is fitted, so the levels fit the
    # gain the FMU will read with
    gain = _within(gain_wanted, limits.get(f"{sensor}.gain"))

    def model(q):
        a, b, w = np.exp(q)
        return 10 * np.log10(gain ** 2 * (M + a * R + b * F) + w * noise0)

    # the broadband levels within a factor 100 of the simulated ones (power 1e4), the noise at most
    # the quietest band; a level the spectrum does not need goes to the low end, not to zero
    lo = np.array([np.log(1e-4), np.log(1e-4), np.log(1e-6)])
    hi = np.array([np.log(1e4), np.log(1e4), 0.0])
    sol = least_squares(lambda q: model(q) - target, np.log([1.0, 1.0, 0.1]), bounds=(lo, hi))
    a, b, w = np.exp(sol.x)
    rs, ps = float(np.sqrt(a)), float(np.sqrt(b))
    values = {f"{sensor}.gain": gain, **{name: _within(v, limits.get(name)) for name, v in
                                         ((ROUGHNESS[0], r0 * rs), (ROUGHNESS[1], r0 * rs), (PROCESS, p0 * ps))}}
    return LevelFit(gain, rs, ps, float(w * noise0), float(np.sqrt(np.mean(sol.fun ** 2))), values, fc[:n],
                    target, model(sol.x), gain_wanted=gain_wanted)


def fit_levels_and_panels(fmu_path, parameters: Mapping[str, float], measured, fs: float, *, channel: str,
                          **kwargs) -> tuple[LevelFit, dict[str, float]]:
    """The level fit as a calibration runs it: fit, correct the casing panels' participations from
    its band levels (:func:`panel_participations`), and, if there are panels, fit again.

    Returns the last fit and every value it set (levels, and participations when corrected);
    ``kwargs`` as :func:`fit_levels`.
    """
    values = dict(parameters)
    levels = fit_levels(fmu_path, values, measured, fs, channel=channel, **kwargs)
    values.update(levels.parameters)
    updates = dict(levels.parameters)
    panels = panel_participations(levels, values, channel)
    if panels:
        values.update(panels)
        levels = fit_levels(fmu_path, values, measured, fs, channel=channel, **kwargs)
        updates.update({**panels, **levels.parameters})
    return levels, updates


def _within(value: float, limits) -> float:
    """``value`` clipped to an FMU variable's declared (min, max), either of them None or absent."""
    lo, hi = limits if limits is not None else (None, None)
    return float(np.clip(value, float(lo) if lo is not None else -np.inf, float(hi) if hi is not None else np.inf))


def mesh_lines(x, fs: float, nominal_hz: float, *, teeth: int = 19, fmax: float = 5000.0, harmonics: int = 6
               ) -> tuple[np.ndarray, np.ndarray]:
    """(power of each gear-mesh harmonic, power of the spectrum around it), both (harmonics,) [unit^2].

    The shaft speed is read off the signal's own mesh line (an induction motor slips, a rig's
    speed is off its setting); amplitudes from a Hann spectrum, the line being the largest of
    the bins within 2.5 bins of k times the mesh frequency, its surroundings the median of the
    bins up to 40 away. NaN above ``fmax``.
    """
    from twin.calibration.objectives import estimate_shaft_hz
    from twin.signals import amplitude_spectrum

    x = np.asarray(x, float)
    shaft = estimate_shaft_hz(x, fs, nominal_hz, teeth)
    f, amp = amplitude_spectrum(x - x.mean(), fs)
    df = f[1] - f[0]
    line, around = np.full(harmonics, np.nan), np.full(harmonics, np.nan)
    for k in range(1, harmonics + 1):
        fk = k * teeth * shaft
        if fk > fmax:
            break
        near = np.abs(f - fk) <= 2.5 * df
        ring = (np.abs(f - fk) <= 40 * df) & ~near
        line[k - 1] = amp[near].max() ** 2
        around[k - 1] = np.median(amp[ring]) ** 2
    return line, around


def panel_participations(fit: LevelFit, parameters: Mapping[str, float], channel: str) -> dict[str, float]:
    """One correction of the casing panel modes' participations from the band levels of a level fit.

    Near its resonance a panel mode lifts the band by its participation (amplitude), so the
    participation is scaled by the measured-minus-model band level there (in amplitude), within
    [0.1, 10]. Returns the new participations (empty without panel modes).
    """
    sensor = SENSOR_OF_CHANNEL[channel]
    out = {}
    for slot in (1, 2, 3):
        w = parameters.get(f"{sensor}.panel_participation[{slot}]", 0.0)
        f = parameters.get(f"{sensor}.panel_frequency[{slot}]")
        if not w or f is None or fit.band_hz is None:
            continue
        i = int(np.argmin(np.abs(np.log(fit.band_hz / f))))
        out[f"{sensor}.panel_participation[{slot}]"] = float(
            np.clip(w * 10 ** ((fit.measured_db[i] - fit.model_db[i]) / 20), 0.1, 10.0))
    return out
