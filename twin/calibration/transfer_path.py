"""The transfer path from the bearings to the casing sensors, measured by hammer tests.

A model of a casing (rigid box on pedestals, flexible walls with a few modes) never passes the
vibration of a real one: on the independent rigs the twin's own path was 20-25 dB too strong at
200-800 Hz and 15-27 dB too weak above 1.6 kHz, a shape no stiffness within physics gave. Striking
the housings of the real gearbox measures that path. In-situ transfer path analysis (ISO 20270)
then predicts a sensor's response as the sum over the force inputs of the accelerance measured
from each (hammer at the housing, the sensor recording) times the force the source puts in there:

    a(f) = sum_k H_k(f) F_k(f).

The twin supplies the forces (the bearing forces of ``GearTwin.Gearbox21Casing`` and the models
built on it); ``GearTwin.Sensors.MeasuredPath`` carries the measured accelerances into the FMU as
one rational function per force with common poles, in second-order sections, so the FMU's casing
channels read the measured path in every tool that runs it (compare, diagnose, archive, an SSP
importer). This module estimates the accelerances from hammer records (H1, with the coherence)
and fits the sections to them by vector fitting (Gustavsen and Semlyen 1999: common poles
relocated by the zeros of a weighting function, then the numerators by linear least squares).

The measured path stands for the whole casing, its walls and the sensor's mount; a force the
hammer tests did not strike in (a horizontal bearing force when the housings were struck from
above) reaches no sensor, which :func:`path_parameters` leaves at zero.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

#: The path block of each casing channel in ``GearTwin.Gearbox21Casing``.
PATH_OF_CHANNEL = {"accel_pinion_casing": "path_pinion", "accel_gear_casing": "path_gear"}
#: The force inputs of every path block, in the order of its ``force`` array (FMU outputs).
FORCES = ("bearing_force_input_x", "bearing_force_input_y", "bearing_force_output_x", "bearing_force_output_y")
#: Structural parameter that sizes both path blocks (0: the modelled casing path).
SECTIONS_PARAMETER = "n_path_sections"
#: Sections fitted per path by default: the rigs' casing channels show 10-30 modes below 5 kHz.
DEFAULT_SECTIONS = 32


@dataclass(frozen=True)
class Accelerance:
    """One measured accelerance: ``frequency`` (m,) [Hz], ``value`` (m,) complex [m/s^2/N],
    ``coherence`` (m,) [-], from ``record`` (struck) to ``channel``, averaged over ``segments``."""

    record: str
    channel: str
    frequency: np.ndarray
    value: np.ndarray
    coherence: np.ndarray
    segments: int = 1

    def coherent(self, fmin: float, fmax: float) -> bool:
        """Whether the response holds the blows at all over [fmin, fmax] Hz: a median coherence
        above twice what two unrelated signals show over this many segments (about 1 / segments)."""
        band = (self.frequency >= fmin) & (self.frequency <= fmax)
        return bool(np.median(self.coherence[band]) > 2.0 / max(self.segments, 1))


def force_channel(record) -> str:
    """The name of a hammer record's force channel (the one in N); ValueError if it has none."""
    names = [c for c in record.channel_names if record.units[c] == "N"]
    if not names:
        raise ValueError(f"record {record.name!r} is not a hammer test (it has no force channel in N)")
    return names[0]


def hammer_accelerance(record, channel: str, *, resolution: float = 4.0) -> Accelerance:
    """H1 estimate of the accelerance from the hammer's force to ``channel`` of a hammer record.

    Welch cross- and auto-spectra with Hann segments of 1/``resolution`` s (each holds at least one
    blow at the usual 2-4 blows/s); H1 = S_fx / S_ff is unbiased by noise on the response (the
    running machine at slow roll), and the coherence says where the force did not dominate it.
    """
    from scipy import signal as sps

    fs = float(record.sample_rate)
    force = np.asarray(record[force_channel(record)], float)
    response = np.asarray(record[channel], float)
    n = int(min(force.size, round(fs / resolution)))
    f, sfx = sps.csd(force, response, fs=fs, nperseg=n)
    _, sff = sps.welch(force, fs=fs, nperseg=n)
    _, sxx = sps.welch(response, fs=fs, nperseg=n)
    h = sfx / np.maximum(sff, 1e-300)
    coh = np.abs(sfx) ** 2 / np.maximum(sff * sxx, 1e-300)
    segments = 1 + max(force.size - n, 0) // (n // 2)       # Welch's default half overlap
    return Accelerance(record.name, channel, f, h, np.clip(coh, 0.0, 1.0), segments)


class PathFit:
    """Common-pole rational fit of K accelerances in second-order sections (vector fitting).

    Parameters
    ----------
    n_sections : sections (pole pairs) of the fit.
    fmin, fmax : band fitted [Hz].
    iterations : pole relocations.

    After :meth:`fit`: ``section_frequency_`` (n,) [Hz], ``section_damping_`` (n,) [-],
    ``residue_rate_`` (n, K) [1/kg], ``residue_`` (n, K) [rad/(kg s)], ``feedthrough_`` (K,)
    [1/kg], ``error_db_`` (K,) RMS dB of the fit against the data over the band (coherence-weighted).
    Each accelerance is sum_r (c1 s + c0) / (s^2 + 2 zeta omega s + omega^2) + d.
    """

    def __init__(self, n_sections: int = DEFAULT_SECTIONS, *, fmin: float = 20.0, fmax: float = 5000.0,
                 iterations: int = 12):
        self.n_sections = n_sections
        self.fmin = fmin
        self.fmax = fmax
        self.iterations = iterations

    def fit(self, frequency: np.ndarray, accelerances: np.ndarray, weights: np.ndarray | None = None) -> "PathFit":
        """Fit (K, m) complex ``accelerances`` at ``frequency`` (m,) [Hz]; ``weights`` (K, m) >= 0
        (e.g. the coherence) multiply the relative weighting. Returns self."""
        f = np.asarray(frequency, float)
        h = np.atleast_2d(np.asarray(accelerances, complex))
        if h.shape[1] != f.size:
            raise ValueError(f"accelerances have {h.shape[1]} bins, frequency has {f.size}")
        if self.n_sections < 1:
            raise ValueError(f"n_sections must be at least 1, got {self.n_sections}")
        band = (f >= self.fmin) & (f <= self.fmax) & np.all(np.isfinite(h), axis=0)
        if band.sum() < 4 * self.n_sections:
            raise ValueError(f"{band.sum()} frequency bins in {self.fmin:g}-{self.fmax:g} Hz cannot fit "
                             f"{self.n_sections} sections")
        f, h = f[band], h[:, band]
        w = np.ones_like(h.real) if weights is None else np.atleast_2d(np.asarray(weights, float))[:, band]
        # relative weighting (the spectra are judged in dB), against a smoothed magnitude so a
        # noisy anti-resonance does not take the fit
        w = w / np.maximum(_smoothed(np.abs(h)), 1e-300)
        scale = self.fmax * 2 * np.pi           # s / scale is at most j on the band
        s = 2j * np.pi * f / scale
        poles = _initial_poles(self.n_sections, 2 * np.pi * self.fmin / scale, 1.0)
        for _ in range(self.iterations):
            poles = _relocate(s, h, w, poles)
        omega, zeta = _sections(poles)
        c1, c0, d = _numerators(s, h, w, omega, zeta)
        fit = _evaluate(s, omega, zeta, c1, c0, d)
        err = 20 * np.log10(np.abs(fit) / np.maximum(np.abs(h), 1e-300))
        ww = w * np.abs(h)                      # the caller's weights alone
        self.section_frequency_ = omega * scale / (2 * np.pi)
        self.section_damping_ = zeta
        # back to physical s: (c1 s~ + c0) / (s~^2 + ...) with s~ = s / scale
        self.residue_rate_ = (c1 * scale).T
        self.residue_ = (c0 * scale ** 2).T
        self.feedthrough_ = d
        self.error_db_ = np.sqrt(np.sum(ww * err ** 2, axis=1) / np.maximum(np.sum(ww, axis=1), 1e-300))
        if not all(np.all(np.isfinite(v)) for v in (self.section_frequency_, self.residue_rate_, self.residue_,
                                                     self.feedthrough_, self.error_db_)):
            raise ValueError("the rational fit did not converge (non-finite sections)")
        return self

    def predict(self, frequency: np.ndarray) -> np.ndarray:
        """(K, m) fitted accelerances at ``frequency`` (m,) [Hz]."""
        s = 2j * np.pi * np.asarray(frequency, float)
        omega = 2 * np.pi * self.section_frequency_
        den = s[None, :] ** 2 + (2 * self.section_damping_ * omega)[:, None] * s[None, :] + (omega ** 2)[:, None]
        return (np.einsum("rk,rm->km", self.residue_rate_, s[None, :] / den)
                + np.einsum("rk,rm->km", self.residue_, 1.0 / den) + self.feedthrough_[:, None])


def _smoothed(mag: np.ndarray) -> np.ndarray:
    """Running mean over +-4 bins of each row of ``mag`` (K, m)."""
    kernel = np.ones(9) / 9
    out = np.empty_like(mag)
    for k, row in enumerate(mag):
        padded = np.pad(row, 4, mode="edge")
        out[k] = np.convolve(padded, kernel, mode="valid")
    return out


def _initial_poles(n: int, lo: float, hi: float) -> np.ndarray:
    beta = np.linspace(lo, hi, n)
    return -beta / 100 + 1j * beta


def _basis(s: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """(m, 2n) real-coefficient partial fractions of the complex pole pairs ``poles`` (n,)."""
    cols = []
    for p in poles:
        a, b = 1.0 / (s - p), 1.0 / (s - np.conj(p))
        cols += [a + b, 1j * a - 1j * b]
    return np.stack(cols, axis=1)


def _relocate(s, h, w, poles):
    """One vector-fitting pole relocation with the K responses' common weighting function."""
    K, m = h.shape
    phi = _basis(s, poles)
    n = phi.shape[1]
    rows, rhs = [], []
    for k in range(K):
        block = np.zeros((m, K * (n + 1) + n), complex)
        block[:, k * (n + 1):k * (n + 1) + n] = phi
        block[:, k * (n + 1) + n] = 1.0
        block[:, K * (n + 1):] = -h[k][:, None] * phi
        rows.append(w[k][:, None] * block)
        rhs.append(w[k] * h[k])
    a = np.concatenate(rows)
    y = np.concatenate(rhs)
    a, y = np.concatenate([a.real, a.imag]), np.concatenate([y.real, y.imag])
    norm = np.linalg.norm(a, axis=0)
    norm[norm == 0] = 1.0
    x = np.linalg.lstsq(a / norm, y, rcond=None)[0] / norm
    ct = x[K * (n + 1):]
    amat = np.zeros((n, n))
    bvec = np.zeros(n)
    for i, p in enumerate(poles):
        j = 2 * i
        amat[j:j + 2, j:j + 2] = [[p.real, p.imag], [-p.imag, p.real]]
        bvec[j] = 2.0
    z = np.linalg.eigvals(amat - np.outer(bvec, ct))
    z = np.where(z.real > 0, -z.real + 1j * z.imag, z)     # unstable zeros flipped into the left half-plane
    pairs = np.sort_complex(z[z.imag > 1e-12 * np.abs(z)])
    real = np.sort(z[np.abs(z.imag) <= 1e-12 * np.abs(z)].real)
    # The sections are complex pairs: two real zeros become one pair of their geometric mean
    # magnitude at damping 0.5 (the next relocation moves it), and a pair lost that way or to an
    # odd real zero restarts inside the band, so the number of sections stays as asked.
    out = list(pairs)
    for r1, r2 in zip(real[0::2], real[1::2]):
        if r1 * r2 > 0:
            out.append(np.sqrt(r1 * r2) * complex(-0.5, np.sqrt(0.75)))
    while len(out) < poles.size:
        out.append(complex(-0.01, 0.5 + 0.01 * len(out)))
    return np.array(sorted(out[:poles.size], key=lambda p: p.imag))


#: Least damping ratio of a section: a structure dissipates at least this much, and a section
#: left undamped by the fit (a weakly seen peak) would ring for ever in the FMU.
MIN_DAMPING = 0.002


def _sections(poles):
    omega = np.abs(poles)
    zeta = np.maximum(-poles.real / omega, MIN_DAMPING)
    return omega, zeta


def _section_basis(s, omega, zeta):
    den = s[:, None] ** 2 + 2 * zeta[None, :] * omega[None, :] * s[:, None] + omega[None, :] ** 2
    return s[:, None] / den, 1.0 / den


def _numerators(s, h, w, omega, zeta):
    """Least-squares (c1 (K, n), c0 (K, n), d (K,)) for fixed sections."""
    b1, b0 = _section_basis(s, omega, zeta)
    a = np.concatenate([b1, b0, np.ones((s.size, 1))], axis=1)
    n = omega.size
    c1, c0, d = [], [], []
    for k in range(h.shape[0]):
        aw = w[k][:, None] * a
        yw = w[k] * h[k]
        ar, yr = np.concatenate([aw.real, aw.imag]), np.concatenate([yw.real, yw.imag])
        norm = np.linalg.norm(ar, axis=0)
        norm[norm == 0] = 1.0
        x = np.linalg.lstsq(ar / norm, yr, rcond=None)[0] / norm
        c1.append(x[:n])
        c0.append(x[n:2 * n])
        d.append(x[2 * n])
    return np.array(c1), np.array(c0), np.array(d)


def _evaluate(s, omega, zeta, c1, c0, d):
    b1, b0 = _section_basis(s, omega, zeta)
    return c1 @ b1.T + c0 @ b0.T + d[:, None]


def fit_paths(mset, path_from: Mapping[str, str], channels: Sequence[str], *, n_sections: int = DEFAULT_SECTIONS,
              fmin: float = 20.0, fmax: float = 5000.0) -> dict[str, PathFit]:
    """One :class:`PathFit` per channel of ``channels`` that every struck record has, fitted to the
    accelerances from the records of ``path_from`` ({hammer record: force it stands for}, a name of
    :data:`FORCES`) to that channel, weighted by their coherence. The fits' responses are in the
    order of ``path_from``."""
    records = [mset[name] for name in path_from]
    fits = {}
    for channel in channels:
        if not all(channel in r for r in records):
            continue
        acc = [hammer_accelerance(r, channel) for r in records]
        for a in acc:
            band = (a.frequency >= fmin) & (a.frequency <= fmax)
            if not (np.all(np.isfinite(a.value[band])) and np.any(np.abs(a.value[band]) > 0)):
                raise ValueError(f"record {a.record!r} gives no accelerance to {channel} (no blow in its force "
                                 "channel, or a response that is not finite)")
            if not a.coherent(fmin, fmax):
                raise ValueError(f"record {a.record!r}: the response of {channel} is not coherent with the blows "
                                 f"(median coherence {np.median(a.coherence[band]):.3f} over {fmin:g}-{fmax:g} Hz, "
                                 f"{a.segments} segments)")
        f = acc[0].frequency
        if any(a.frequency.size != f.size for a in acc):
            raise ValueError("the hammer records of the path have different sample rates")
        top = min(fmax, 0.45 * float(records[0].sample_rate))
        fits[channel] = PathFit(n_sections, fmin=fmin, fmax=top).fit(
            f, np.array([a.value for a in acc]), weights=np.array([a.coherence for a in acc]))
    return fits


def path_parameters(fits: Mapping[str, PathFit], forces: Sequence[str]) -> dict[str, float]:
    """FMU parameter values of the path blocks for ``fits`` ({channel: fit}), whose responses stand
    for ``forces`` (names of :data:`FORCES`, in the fits' response order); the other forces get no
    path. Every fit must have the same number of sections."""
    values: dict[str, float] = {}
    for channel, fit in fits.items():
        block = PATH_OF_CHANNEL[channel]
        n = fit.section_frequency_.size
        k_of = {FORCES.index(force): j for j, force in enumerate(forces)}
        for r in range(n):
            values[f"{block}.section_frequency[{r + 1}]"] = float(fit.section_frequency_[r])
            values[f"{block}.section_damping[{r + 1}]"] = float(fit.section_damping_[r])
            for k in range(len(FORCES)):
                j = k_of.get(k)
                i = r * len(FORCES) + k + 1
                values[f"{block}.residue_rate[{i}]"] = float(fit.residue_rate_[r, j]) if j is not None else 0.0
                values[f"{block}.residue[{i}]"] = float(fit.residue_[r, j]) if j is not None else 0.0
        for k in range(len(FORCES)):
            j = k_of.get(k)
            values[f"{block}.feedthrough[{k + 1}]"] = float(fit.feedthrough_[j]) if j is not None else 0.0
    return values


@dataclass(frozen=True)
class MeasuredPath:
    """The measured path a calibration attached: the FMU built with it, its parameter values, the
    fits by channel, and the struck records with the forces they stand for."""

    fmu_path: object
    parameters: Mapping[str, float]
    fits: Mapping[str, PathFit]
    path_from: Mapping[str, str]
    n_sections: int

    def describe(self) -> str:
        fits = ", ".join(f"{ch} within {', '.join(f'{e:.2f}' for e in fit.error_db_)} dB"
                         for ch, fit in self.fits.items())
        return (f"measured transfer path ({self.n_sections} sections) from "
                + ", ".join(f"{r} ({f})" for r, f in self.path_from.items()) + f": {fits}")


def check_path_from(scenario, mset, spec: Mapping, source: str, outputs: set[str]) -> list[str]:
    """Refuse a calibration block's ``path_from`` before any work: a record missing or not a hammer
    test, a model given as a file (the path is built into the model) or without bearing forces
    among its ``outputs`` (the FMU's output names). Returns the casing channels the path will be
    fitted for. Raises :class:`~twin.errors.ScenarioError` naming the bad value."""
    from twin.calibration.measured import hammer_record
    from twin.errors import ScenarioError

    where = "calibration.path_from"
    for name in spec["path_from"]:
        hammer_record(name, mset, source, where, hint="")
    model = str(scenario.fmu)
    if model.endswith((".fmu", ".ssp")):
        raise ScenarioError([(source, "fmu", f"a measured path is built into the model, so 'fmu' must name a "
                                             f"Modelica model (GearTwin.Gearbox21Shafts, ...), not the file {model!r}")])
    missing = [name for name in FORCES if name not in outputs]
    if missing:
        raise ScenarioError([(source, where, f"{model} has no bearing force outputs ({', '.join(missing)}): "
                                             "GearTwin.Gearbox21Casing and the models built on it have them")])
    channels = [c for c in PATH_OF_CHANNEL if c in outputs and all(c in mset[r] for r in spec["path_from"])]
    if not channels:
        raise ScenarioError([(source, where, f"the records {', '.join(spec['path_from'])} share none of the casing "
                                             f"channels {', '.join(PATH_OF_CHANNEL)}")])
    return channels


def attach_measured_path(scenario, mset, spec: Mapping, source: str, channels: Sequence[str], *,
                         fmin: float = 20.0, fmax: float = 5000.0) -> MeasuredPath:
    """Fit the path of the calibration block's ``path_from`` to ``channels`` (what
    :func:`check_path_from` returned for it) and build the scenario's model with it (the structural
    ``n_path_sections``). Raises :class:`~twin.errors.ScenarioError` when a fit fails."""
    from twin.errors import ScenarioError
    from twin.variants import build_variant

    path_from = dict(spec["path_from"])
    n = int(spec.get("path_sections", DEFAULT_SECTIONS))
    try:
        fits = fit_paths(mset, path_from, channels, n_sections=n, fmin=fmin, fmax=fmax)
    except ValueError as exc:
        raise ScenarioError([(source, "calibration.path_from", f"the path cannot be fitted: {exc}")]) from None
    built = build_variant(str(scenario.fmu), {**_other_options(scenario), SECTIONS_PARAMETER: n})
    return MeasuredPath(built, path_parameters(fits, list(path_from.values())), fits, path_from, n)


def without_path(parameters: Mapping[str, float]) -> dict[str, float]:
    """``parameters`` less the path blocks' values."""
    prefixes = tuple(block + "." for block in PATH_OF_CHANNEL.values())
    return {k: v for k, v in parameters.items() if not k.startswith(prefixes)}


def mechanical_model(scenario, spec: Mapping, source: str):
    """The scenario's model without its measured path, for a scenario that reads one (a calibrated
    one): its modes are the gearbox's, not the path's sections. The path must be fitted again
    (``path_from``): ScenarioError otherwise, since calibrating without it would drop the path."""
    from twin.errors import ScenarioError

    if not spec.get("path_from"):
        raise ScenarioError([(source, "structural.n_path_sections",
                              "the scenario reads a measured transfer path; calibrate it again with "
                              "calibration.path_from (the hammer records), or calibrate the scenario it came from")])
    return model_without_path(scenario)


def model_without_path(scenario):
    """The FMU of the scenario's model built without a measured path (its other build options kept)."""
    from dataclasses import replace

    return replace(scenario, structural=_other_options(scenario)).fmu_path()


def _other_options(scenario) -> dict:
    """The scenario's build options but the path's sections."""
    return {k: v for k, v in scenario.structural.items() if k != SECTIONS_PARAMETER}
