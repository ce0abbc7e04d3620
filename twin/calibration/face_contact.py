"""How the mesh softens at light load, fitted to how the spectrum changes between two loads.

Two mechanisms make a real mesh softer at light load, and the twin has one parameter for each:

* **The flanks' rough layer** (``flank_layer_share`` q, :data:`SHARES`): asperity heights
  exponentially distributed (Greenwood & Williamson, 1966) carry a load that grows exponentially as
  the surfaces close, so the layer's compliance is h / F at force F, in series with the teeth.
  ``GearTwin.Gearbox21`` linearises it at the static mesh force: the pair stiffnesses hold at
  ``layer_reference_torque`` (set here to the steady record's load, where the modes were fitted,
  so the fitted modes stay where they are), and at brake torque T the mesh is
  ``T / ((1 - q) T + q T_ref)`` times as stiff.  q is the layer's share of the mesh compliance at
  the reference: with the default mesh (about 4e8 N/m) and 273 N of mesh force at 20 N.m,
  q = 0.1-0.6 is a height scale h = q F / k of 0.07-0.4 um, the composite roughness of ground to
  finely hobbed flanks.  Every real pair has some; ISO 6336-1 reduces its single stiffness
  below 100 N/mm of line load for the same reason.
* **The flanks' lead mismatch** (``lead_mismatch`` D, :data:`GRID`): a spur pair whose leads differ
  by D across the face (helix slope deviations of both gears, shaft and housing misalignment:
  ISO 6336-1's equivalent misalignment F_beta_x) touches first at one face end.  Up to the load
  that closes the gap the pair carries ``k a^2 / (2 D)`` at approach a (the thin-slice law of
  ``GearTwin.Gearbox21``): its tangent stiffness grows as the square root of the load, and the
  contact pattern, hence the mesh excitation, changes with it.  Bounds: 0 to 45 um, two to four
  times the 10-20 um of helix deviation and misalignment an ISO 1328-1 grade 7-8 pair of this
  face width has.

The layer is fitted first (every pair has one; a misalignment is particular to a gearbox), then
the mismatch with the layer fixed, so a mismatch is taken only for what the layer cannot explain.
The defaults (q = 0, D = 0) are a linear, aligned mesh, whose modes do not move with load at all.

At one speed and two loads the ratio of the two spectra at a sensor does not hold the transfer
path or the sensor gain (they divide out), so it is the mesh's own load dependence that the ratio
shows.  Each value is simulated at both records' loads and speed; both spectra are Welch PSDs
smoothed by a running median over :data:`SMOOTH_HZ` (wider than the mesh-harmonic spacing, so the
broadband shape is compared, not the lines), the ratio in dB is compared with the records' over
[:data:`FMIN`, min(:data:`FMAX`, 0.4 fs)] with its median removed (gain-free), and the distance is
the RMS.  A flat ratio says little: in each stage the smallest value whose distance is within
:data:`TOLERANCE_DB` of the stage's best is taken, so a gearbox whose spectrum does not change its
shape with load keeps a linear, aligned mesh.  A fit at a grid's top is reported as a warning.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

PARAMETER = "lead_mismatch"
#: Lead mismatches tried [m].
GRID = (0.0, 2.5e-6, 5e-6, 7.5e-6, 10e-6, 15e-6, 20e-6, 30e-6, 45e-6)
LAYER, REFERENCE = "flank_layer_share", "layer_reference_torque"
#: Rough-layer shares of the mesh compliance at the steady record's load tried [-].
SHARES = (0.0, 0.05, 0.1, 0.15, 0.2, 0.3, 0.45, 0.6)
#: Smallest D within this distance of the best is taken [dB].
TOLERANCE_DB = 0.25
#: Band of the compared ratio [Hz] (the top also at most 0.4 times the sample rate).
FMIN, FMAX = 1000.0, 8000.0
#: Width of the running median that removes the mesh lines [Hz].
SMOOTH_HZ = 380.0
#: Welch segment [s].
SEGMENT_S = 0.08


@dataclass(frozen=True)
class FaceContactFit:
    """The light-load law chosen from the load pair.

    ``flank_layer_share`` [-] from ``shares`` with ``share_distances_db`` (len(shares),) the ratio
    distance [dB] at each (lead mismatch 0); ``reference_torque`` [N.m] the steady record's load,
    where the layer leaves the mesh as the modes fitted it; ``lead_mismatch`` [m] from ``grid`` [m]
    with ``distances_db`` (len(grid),) at each (with the chosen share); ``loads`` [N.m] (steady
    first) and ``speed_hz`` of the pair."""
    lead_mismatch: float
    grid: tuple[float, ...]
    distances_db: tuple[float, ...]
    loads: tuple[float, float]
    speed_hz: float
    flank_layer_share: float = 0.0
    shares: tuple[float, ...] = (0.0,)
    share_distances_db: tuple[float, ...] = ()

    @property
    def reference_torque(self) -> float:
        return self.loads[0]

    @property
    def parameters(self) -> dict[str, float]:
        out = {PARAMETER: self.lead_mismatch}
        if len(self.shares) > 1 or self.flank_layer_share > 0:     # the layer was fitted: 0 replaces an earlier one
            out.update({LAYER: self.flank_layer_share, REFERENCE: self.reference_torque})
        return out

    def on_bound(self) -> bool:
        return self.lead_mismatch >= max(self.grid)

    def layer_on_bound(self) -> bool:
        return len(self.shares) > 1 and self.flank_layer_share >= max(self.shares)

    def describe(self) -> str:
        best = float(min(self.distances_db))
        at0 = (self.share_distances_db[self.shares.index(0.0)] if 0.0 in self.shares and self.share_distances_db
               else self.distances_db[self.grid.index(0.0)] if 0.0 in self.grid else float("nan"))
        light = layer_factor(self.flank_layer_share, self.loads[1], self.loads[0])
        layer = ("" if len(self.shares) < 2 else "no rough layer, " if not self.flank_layer_share else
                 f"rough layer {self.flank_layer_share:g} of the mesh compliance at {self.loads[0]:g} N.m (the mesh "
                 f"{light:.2f} times as stiff at {self.loads[1]:g} N.m), ")
        return (f"{layer}lead mismatch {1e6 * self.lead_mismatch:g} um from the spectra at {self.loads[0]:g} and "
                f"{self.loads[1]:g} N.m ({self.speed_hz:g} Hz): their ratio {at0:.2f} dB from a linear aligned "
                f"mesh's, {best:.2f} dB at best")


def layer_factor(share: float, torque: float, reference: float) -> float:
    """Tangent mesh stiffness at brake torque ``torque`` relative to that at ``reference`` [N.m] with a
    rough layer of ``share`` [-] (``GearTwin.Gearbox21.flank_layer_factor``)."""
    t = max(abs(torque), 1e-3)
    return t / ((1 - share) * t + share * reference)


def has_layer(fmu_path) -> bool:
    """Whether the FMU has the rough-layer parameters (an FMU built before them, or another tool's, has not)."""
    from twin.fmu import FMU
    with FMU(fmu_path) as fmu:
        names = set(fmu.variables)
    return LAYER in names and REFERENCE in names


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


def smoothed_db(x: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [Hz] (n,) and the Welch PSD of ``x`` in dB with a running median over
    :data:`SMOOTH_HZ` (n,)."""
    from scipy.ndimage import median_filter
    from scipy.signal import welch
    nper = int(2 ** round(np.log2(SEGMENT_S * fs)))
    f, p = welch(np.asarray(x, float), fs, nperseg=nper, noverlap=nper // 2)
    size = max(3, int(round(SMOOTH_HZ / (f[1] - f[0]))) | 1)
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
                     *, settle: float = 0.3, duration: float = 2.0, grid=GRID, shares=SHARES, executor=None,
                     progress: bool = False) -> FaceContactFit:
    """Fit ``flank_layer_share``, then ``lead_mismatch``, to two steady records at one speed and two loads.

    records : two (signal (n,), load [N.m]) pairs of ``channel`` sampled at ``fs`` [Hz], the steady
    record (whose load the modes were fitted at) first.  ``speed_hz`` is the drive speed both were
    taken at; ``duration`` [s] is simulated per run after ``settle`` (at most each record's length);
    ``shares`` the rough-layer shares tried [-] (``(0.0,)``: no layer), ``grid`` the lead
    mismatches tried [m].
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
    own = executor is None
    ex = executor or LocalExecutor(1)

    def distances(values: list[dict[str, float]], desc: str) -> list[float]:
        tasks = [(str(fmu_path), float(speed_hz), float(load), {**parameters, **v}, settle, duration, channel, fs)
                 for v in values for load in (la, lb)]
        runs = ex.map(_simulate, tasks, progress=progress, desc=desc)
        out = []
        for i in range(len(values)):
            _, sa = smoothed_db(runs[2 * i], fs)
            _, sb = smoothed_db(runs[2 * i + 1], fs)
            out.append(ratio_distance(measured, (sa - sb)[band]))
        return out

    try:
        # with the layer fitted every run sets it (a share in ``parameters`` from an earlier calibration
        # must not stay under the runs of share 0); without, an FMU may not have it at all
        layer = lambda q: {LAYER: q, REFERENCE: float(la)} if len(shares) > 1 or q > 0 else {}
        share_dist = (distances([{PARAMETER: 0.0, **layer(q)} for q in shares], "rough layer")
                      if len(shares) > 1 else [])
        share = choose(share_dist, shares) if share_dist else float(shares[0])
        # the mismatch with the layer fixed; with no mismatch it is the layer's own run
        known = dict(zip(shares, share_dist)) if share_dist else {}
        rest = [d for d in grid if not (d == 0.0 and share in known)]
        got = dict(zip(rest, distances([{PARAMETER: d, **layer(share)} for d in rest], "lead mismatch")))
        dist = [known[share] if (d == 0.0 and share in known) else got[d] for d in grid]
    finally:
        if own:
            ex.close()
    return FaceContactFit(choose(dist, grid), tuple(grid), tuple(dist), (float(la), float(lb)), float(speed_hz),
                          float(share), tuple(shares), tuple(share_dist))
