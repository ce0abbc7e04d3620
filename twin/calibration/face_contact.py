"""The flanks' lead mismatch, fitted to how the spectrum changes between two loads.

A spur pair whose leads differ by D across the face (helix slope deviations of both gears, shaft
and housing misalignment: ISO 6336-1's equivalent misalignment F_beta_x) touches first at one
face end.  Up to the load that closes the gap the pair carries ``k a^2 / (2 D)`` at approach a
(the thin-slice law of ``GearTwin.Gearbox21``, ``lead_mismatch``): its tangent stiffness grows
as the square root of the load, so the mesh-controlled mode climbs with load, and above it the
mesh is the full-face line contact.  The twin's default D = 0 is a perfectly aligned pair, whose
mesh mode does not move with load at all.

At one speed and two loads the ratio of the two spectra at a sensor does not hold the transfer
path or the sensor gain (they divide out), so it is the mesh's own load dependence that the ratio
shows.  Each D of :data:`GRID` is simulated at both records' loads and speed; both spectra are
Welch PSDs smoothed by a running median over :data:`SMOOTH_HZ` (wider than the mesh-harmonic
spacing, so the broadband shape is compared, not the lines), the ratio in dB is compared with the
records' over [:data:`FMIN`, min(:data:`FMAX`, 0.4 fs)] with its median removed (gain-free), and
the distance is the RMS. A flat ratio says little about D: the smallest D whose distance is within
:data:`TOLERANCE_DB` of the best is taken, so a gearbox whose spectrum does not change its shape
with load keeps an aligned pair.  Bounds: 0 to 45 um, two to four times the 10-20 um of helix
deviation and misalignment an ISO 1328-1 grade 7-8 pair of this face width has; a fit at the bound
is reported as a warning.

The note also reports where the ratio rises and falls most (:func:`load_lobes`), for the records and
for the twin at the fitted D: a mode that moves down as the load falls (the mesh-controlled mode of
a mesh that softens at light load) reads as a rise near its frequency at the heavier load and a fall
near its frequency at the lighter one, so the user sees whether the twin's moving mode sits where the
rig's does.  Nothing is fitted on it.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

PARAMETER = "lead_mismatch"
#: Lead mismatches tried [m].
GRID = (0.0, 2.5e-6, 5e-6, 7.5e-6, 10e-6, 15e-6, 20e-6, 30e-6, 45e-6)
#: Smallest D within this distance of the best is taken [dB].
TOLERANCE_DB = 0.25
#: Band of the compared ratio [Hz] (the top also at most 0.4 times the sample rate).
FMIN, FMAX = 1000.0, 8000.0
#: Width of the running median that removes the mesh lines [Hz].
SMOOTH_HZ = 380.0
#: Welch segment [s].
SEGMENT_S = 0.08
#: Narrower smoothing for the ratio's lobes (a mode that moves with load) [Hz], and their band's start.
LOBE_SMOOTH_HZ, LOBE_FMIN = 150.0, 1500.0


@dataclass(frozen=True)
class LoadLobes:
    """Where the ratio of a load pair's spectra (heavier load over lighter, dB, median removed)
    rises and falls most in :data:`LOBE_FMIN`-:data:`FMAX`: a mode that moves down as the load falls (the
    mesh-controlled mode of a mesh that softens at light load) shows as a rise near its frequency
    at the heavier load and a fall near its frequency at the lighter one, each read a little
    outward of the mode (the extremes of a ratio of two overlapping humps). ``rise_hz``,
    ``fall_hz`` [Hz]; ``rise_db``, ``fall_db`` [dB]."""
    rise_hz: float
    rise_db: float
    fall_hz: float
    fall_db: float

    def describe(self) -> str:
        return f"{self.rise_db:+.1f} dB at {self.rise_hz:.0f} Hz, {self.fall_db:+.1f} dB at {self.fall_hz:.0f} Hz"


def load_lobes(heavy, light, fs: float) -> LoadLobes:
    """The :class:`LoadLobes` of two records (n,) of one channel sampled at ``fs`` [Hz], ``heavy``
    at the heavier load, from :data:`LOBE_FMIN` to the fit's band top (:data:`FMAX`, at most 0.4 ``fs``)."""
    f, a = smoothed_db(heavy, fs, LOBE_SMOOTH_HZ)
    _, b = smoothed_db(light, fs, LOBE_SMOOTH_HZ)
    band = (f >= LOBE_FMIN) & (f <= min(FMAX, 0.4 * fs))
    r, fb = (a - b)[band], f[band]
    r = r - np.median(r)
    i, j = int(np.argmax(r)), int(np.argmin(r))
    return LoadLobes(float(fb[i]), float(r[i]), float(fb[j]), float(r[j]))


@dataclass(frozen=True)
class FaceContactFit:
    """``lead_mismatch`` [m] chosen from the load pair; ``distances_db`` (len(GRID),) the ratio
    distance [dB] at each D of ``grid`` [m]; ``loads`` [N.m] and ``speed_hz`` of the pair."""
    lead_mismatch: float
    grid: tuple[float, ...]
    distances_db: tuple[float, ...]
    loads: tuple[float, float]
    speed_hz: float
    lobes_measured: LoadLobes | None = None
    lobes_model: LoadLobes | None = None

    @property
    def parameters(self) -> dict[str, float]:
        return {PARAMETER: self.lead_mismatch}

    def on_bound(self) -> bool:
        return self.lead_mismatch >= max(self.grid)

    def describe(self) -> str:
        best = float(min(self.distances_db))
        at0 = self.distances_db[self.grid.index(0.0)] if 0.0 in self.grid else float("nan")
        lobes = (f"; the records' ratio {self.lobes_measured.describe()} (a mode moving down with load "
                 f"reads as such a pair), the fitted twin's {self.lobes_model.describe()}"
                 if self.lobes_measured is not None and self.lobes_model is not None else "")
        return (f"lead mismatch {1e6 * self.lead_mismatch:g} um from the spectra at {self.loads[0]:g} and "
                f"{self.loads[1]:g} N.m ({self.speed_hz:g} Hz): their ratio {at0:.2f} dB from the aligned "
                f"pair's, {best:.2f} dB at best{lobes}")


def load_pair_problem(steady, other) -> str | None:
    """Why two records (``nominal_speed`` [Hz], ``load`` [N.m], ``name``) are no load pair, or None:
    the same speed within 2 %, loads 25 % apart or more."""
    if abs(other.nominal_speed - steady.nominal_speed) > 0.02 * steady.nominal_speed:
        return (f"record {other.name!r} runs at {other.nominal_speed:g} Hz, the steady record {steady.name!r} at "
                f"{steady.nominal_speed:g} Hz: the load pair must share its speed (within 2 %)")
    if abs(other.load - steady.load) < 0.25 * max(abs(other.load), abs(steady.load)):
        return (f"record {other.name!r} is at {other.load:g} N.m, the steady record {steady.name!r} at "
                f"{steady.load:g} N.m: the loads must differ by 25 % or more for the spectrum to show its load "
                "dependence")
    return None


def smoothed_db(x: np.ndarray, fs: float, smooth_hz: float = SMOOTH_HZ) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [Hz] (n,) and the Welch PSD of ``x`` in dB with a running median over
    ``smooth_hz`` [Hz] (n,)."""
    from scipy.ndimage import median_filter
    from scipy.signal import welch
    nper = int(2 ** round(np.log2(SEGMENT_S * fs)))
    f, p = welch(np.asarray(x, float), fs, nperseg=nper, noverlap=nper // 2)
    size = max(3, int(round(smooth_hz / (f[1] - f[0]))) | 1)
    return f, median_filter(10.0 * np.log10(np.maximum(p, 1e-300)), size=size, mode="nearest")


def ratio_distance(ratio_measured: np.ndarray, ratio_model: np.ndarray) -> float:
    """Gain-free RMS [dB] between two dB ratios on one grid (their median difference removed)."""
    d = np.asarray(ratio_measured, float) - np.asarray(ratio_model, float)
    return float(np.sqrt(np.mean((d - np.median(d)) ** 2)))


def choose(distances_db, grid=GRID, tolerance_db: float = TOLERANCE_DB) -> float:
    """The smallest D of ``grid`` whose distance is within ``tolerance_db`` of the best."""
    d = np.asarray(distances_db, float)
    return float(min(g for g, v in zip(grid, d) if v <= d.min() + tolerance_db))


def _checked(x, fs: float, load: float) -> np.ndarray:
    """The record as a 1-D float array, refused by name (:class:`MeasurementError`) when it is not
    finite or holds fewer than four Welch segments."""
    from twin.errors import MeasurementError
    x = np.asarray(x, float)
    where = f"the load pair's record at {load:g} N.m"
    if x.ndim != 1 or not np.all(np.isfinite(x)):
        raise MeasurementError("<array>", where, f"needs a 1-D finite signal, got shape {x.shape} with NaN or Inf"
                               if x.ndim == 1 else f"needs a 1-D finite signal, got shape {x.shape}")
    if x.size < 2.5 * SEGMENT_S * fs:
        raise MeasurementError("<array>", where, f"lasts {x.size / fs:.3g} s; the spectra need {2.5 * SEGMENT_S:g} s "
                               "or more (four half-overlapping segments)")
    return x


def _simulate(task) -> np.ndarray:
    from twin.operating import simulate_operating_point
    fmu, speed, load, params, settle, duration, channel, fs = task
    return simulate_operating_point(fmu, speed, load, parameters=params, settle=settle, duration=duration,
                                    channels=[channel], output_interval=1.0 / fs)[:, 0]


def fit_face_contact(fmu_path, parameters: Mapping[str, float], records, channel: str, fs: float, speed_hz: float,
                     *, settle: float = 0.3, duration: float = 2.0, grid=GRID, executor=None,
                     progress: bool = False) -> FaceContactFit:
    """Fit ``lead_mismatch`` to two steady records at one speed and two loads.

    records : two (signal (n,), load [N.m]) pairs of ``channel`` sampled at ``fs`` [Hz].
    ``speed_hz`` is the drive speed both were taken at; ``duration`` [s] is simulated per run
    after ``settle`` (at most each record's length); ``grid`` the lead mismatches tried [m].
    """
    from twin.executor import LocalExecutor
    from twin.errors import MeasurementError
    (xa, la), (xb, lb) = records
    if not (math.isfinite(fs) and 0.4 * fs > 2 * FMIN):
        raise MeasurementError("<array>", "the load pair", f"sampled at {fs!r} Hz: the compared band from {FMIN:g} Hz "
                               f"needs {5 * FMIN:g} Hz or more")
    xa, xb = _checked(xa, fs, la), _checked(xb, fs, lb)
    band_top = min(FMAX, 0.4 * fs)
    f, a_db = smoothed_db(xa, fs)
    _, b_db = smoothed_db(xb, fs)
    band = (f >= FMIN) & (f <= band_top)
    measured = (a_db - b_db)[band]
    n = min(len(xa), len(xb))
    duration = min(float(duration), n / fs)
    tasks = [(str(fmu_path), float(speed_hz), float(load), {**parameters, PARAMETER: d}, settle, duration, channel, fs)
             for d in grid for load in (la, lb)]
    own = executor is None
    ex = executor or LocalExecutor(1)
    try:
        runs = ex.map(_simulate, tasks, progress=progress, desc="lead mismatch")
    finally:
        if own:
            ex.close()
    dist = []
    for i in range(len(grid)):
        _, sa = smoothed_db(runs[2 * i], fs)
        _, sb = smoothed_db(runs[2 * i + 1], fs)
        dist.append(ratio_distance(measured, (sa - sb)[band]))
    d = choose(dist, grid)
    k = 2 * list(grid).index(d)
    # heavier load first: a mode that moves down with load rises where it sits at the heavier one
    order = (0, 1) if abs(la) >= abs(lb) else (1, 0)
    lobes = [load_lobes(*(pair[i] for i in order), fs) for pair in ((xa, xb), (runs[k], runs[k + 1]))]
    return FaceContactFit(d, tuple(grid), tuple(dist), (float(la), float(lb)), float(speed_hz), *lobes)
