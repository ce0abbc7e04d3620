"""The pinion encoder's angular vibration compared with the model's: a second channel of a record.

A casing accelerometer sees what shakes the casing. Below the drive train's first torsional mode a
pinion run-out or a motor-torque ripple mostly turns the shafts instead: the beam rig's 80 um
pinion run-out and 0.8 N.m ripple stand 20-31 dB out in its encoder's angle and within the
healthy scatter at its casing (``bench/encoder_rigs.py``, BENCHMARKS.md). A record whose
tachometer is an angle encoder on the pinion shaft (``tachometer_kind: angle``) therefore gives a
second measured quantity, compared with the model's ``encoder_pinion_angle`` output (the
input shaft's free end, where test rigs mount their encoders).

**Angular vibration** is the encoder angle less a quadratic in time (the mean speed and a slow
drift) [rad]. Its Welch PSD over :data:`ANGLE_BAND` (the shaft orders, the drive's lines and
the first torsional modes; above it the angle of a 2048-count encoder is mostly quantisation) is
compared as the casing channel is (:func:`twin.compare.spectral_levels`: floor-aware, the gain
aligned within 1 dB), giving its own distance: the RMS dB error over the bins where the record
holds content, not over every bin of the band (:class:`AngularObjective`); a baseline record's discrepancy is
learned as missing content added to the model (:class:`AngularDiscrepancy`). The diagnosis judges the two channels together by :func:`joint_lsd`, the RMS of the two
distances, so a channel that does not change leaves the relative cut of the other unchanged, and
the findings of both are ranked by their share of the joint squared distance (:func:`joint`).

Findings (kind ``angular_line``): the encoder's line at 1-4 x each shaft's speed, and any line
locked to no shaft (10 dB above a 30 Hz running median), where measured and model differ by
``line_db`` or more. Frequencies in Hz, angles in rad.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from twin.signals.spectral import padded_spectrum

#: FMU output the encoder is compared with (GearTwin.Gearbox21: theta7, the input shaft's free end).
ANGLE_OUTPUT = "encoder_pinion_angle"
#: Band of the angular-vibration comparison [Hz].
ANGLE_BAND = (2.0, 500.0)
#: Finding kind of the encoder channel.
KIND = "angular_line"


def angular_vibration(angle: np.ndarray, fs: float) -> np.ndarray:
    """The angle (n,) [rad] less its least-squares quadratic in time: the vibration about a
    steadily accelerating rotation [rad] (a steady record's speed and drift, a run-up's ramp)."""
    angle = np.asarray(angle, float)
    t = np.arange(angle.size) / float(fs)
    t = t - t.mean()                            # conditioning of the fit
    return angle - np.polyval(np.polyfit(t, angle, 2), t)


def read_scatter(frequencies: np.ndarray, grid: np.ndarray, scatter_db: np.ndarray | None) -> np.ndarray:
    """A baseline's record-to-record scatter [dB], learned on ``grid`` (m,) [Hz], read at
    ``frequencies`` (k,) [Hz] (linear between bins); 0 without repeated baseline records (None)."""
    if scatter_db is None:
        return np.zeros(np.size(frequencies))
    return np.interp(np.asarray(frequencies, float), grid, scatter_db)


@dataclass(frozen=True)
class AngularDiscrepancy:
    """The model's discrepancy on the encoder channel, learned on a baseline record: per bin of
    ``frequencies`` (m,) [Hz], the model PSD is read as ``gain * model + added`` [rad^2/Hz].

    The encoder sees the shafts' motion directly, with no transfer path to get wrong: where the
    baseline record holds more than the model (a rig's speed control, its own shafts' run-outs,
    sources the model lacks) the difference is *added* to the model, so what an effect adds to
    the model adds to that, as it adds to the gearbox's own content; where the model holds more,
    its level is scaled down to the baseline's. On the baseline itself the read model equals the
    measurement. (The casing channel's discrepancy is a dB offset instead,
    :mod:`twin.effects.baseline`: there a path's gain error scales everything.)
    """

    record: str
    frequencies: np.ndarray = field(repr=False)
    gain: np.ndarray = field(repr=False)          # (m,) [1]
    added: np.ndarray = field(repr=False)         # (m,) [rad^2/Hz]
    # (m,) [dB] how far repeated baseline records differ (twin.effects.baseline); None with one
    scatter_db: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def learn(cls, record: str, frequencies: np.ndarray, baseline_psd: np.ndarray, model_psd: np.ndarray
              ) -> "AngularDiscrepancy":
        """From the baseline's measured and the model's PSDs (m,) on ``frequencies`` (m,)."""
        pb, pm = np.asarray(baseline_psd, float), np.asarray(model_psd, float)
        more = pb >= pm
        gain = np.where(more, 1.0, pb / np.where(pm > 0, pm, 1.0))
        return cls(record, np.asarray(frequencies, float), gain, np.where(more, pb - pm, 0.0))

    def scatter_at(self, frequencies: np.ndarray) -> np.ndarray:
        """The baseline's record-to-record scatter [dB] at ``frequencies`` (m,) [Hz] (0 without
        repeated baseline records)."""
        return read_scatter(frequencies, self.frequencies, self.scatter_db)

    def apply(self, frequencies: np.ndarray, model_psd: np.ndarray) -> np.ndarray:
        """The model PSD (m,) on ``frequencies`` read as the baseline's gearbox would show it."""
        return (np.interp(frequencies, self.frequencies, self.gain) * model_psd
                + np.interp(frequencies, self.frequencies, self.added))


@dataclass(frozen=True)
class AngularComparison:
    """The encoder channel's comparison: distance [dB] (RMS over the record's content bins,
    :class:`AngularObjective`), findings and levels (m,) over :data:`ANGLE_BAND`."""

    lsd_db: float
    findings: tuple = ()
    freqs: np.ndarray = field(default=None, repr=False)           # (m,) Hz
    level_measured: np.ndarray = field(default=None, repr=False)  # (m,) dB
    level_model: np.ndarray = field(default=None, repr=False)     # (m,) dB


#: A bin of the encoder's spectrum holds content (a line, a torsional hump, the speed control's
#: wander) where it stands this much above the spectrum's median, the encoder's noise [dB]:
#: 7 averaged Welch segments of noise reach it with probability below 1e-6.
CONTENT_DB = 10.0


def content_threshold(psd: np.ndarray) -> float:
    """The level [dB] above which a bin of the measured angular PSD (m,) holds content:
    :data:`CONTENT_DB` over its median."""
    return 10 * math.log10(max(float(np.median(np.asarray(psd, float))), 1e-30)) + CONTENT_DB


class AngularObjective:
    """Distance [dB] of a simulated angle's vibration from the measured one's, the measured PSD
    computed once (the encoder's part of the diagnosis's objective).

    The encoder's spectrum is lines (shaft orders, drive lines) and torsional humps over its
    noise. The distance is the RMS dB error of what it holds: the squared differences are summed
    over the bins where the record or the model stands :data:`CONTENT_DB` over the measured
    median, and divided by the number of the record's own such bins (its content), not by every
    bin of :data:`ANGLE_BAND`, so it does not shrink when the band is widened; a line the model
    adds where the record has none adds its squared error to the sum."""

    def __init__(self, angle: np.ndarray, fs: float, resolution: float, discrepancy=None):
        from twin.signals import welch_psd
        self.fs, self.n, self.resolution = float(fs), int(np.asarray(angle).size), float(resolution)
        self.frequencies, self.psd = welch_psd(angular_vibration(angle, fs), fs, resolution=self.resolution)
        self.band = (self.frequencies >= ANGLE_BAND[0]) & (self.frequencies <= min(ANGLE_BAND[1], fs / 2))
        self.pp = self.psd[self.band]
        self.threshold = content_threshold(self.pp)
        self.content = max(1, int(np.count_nonzero(self.pp >= 10 ** (self.threshold / 10))))
        self.discrepancy = discrepancy

    def model_psd(self, simulated_angle: np.ndarray) -> np.ndarray:
        """The model's angular-vibration PSD over the band [rad^2/Hz] (the discrepancy not applied)."""
        from twin.signals import welch_psd
        _, pm = welch_psd(angular_vibration(simulated_angle[: self.n], self.fs), self.fs, resolution=self.resolution)
        return pm[self.band]

    def levels(self, simulated_angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(measured, model) levels [dB] over the band, the model read through the discrepancy."""
        from twin.compare import spectral_levels
        pm = self.model_psd(simulated_angle)
        if self.discrepancy is not None:
            pm = self.discrepancy.apply(self.frequencies[self.band], pm)
        lp, lm, _ = spectral_levels(pm, self.pp)
        return lp, lm

    def __call__(self, simulated_angle: np.ndarray) -> float:
        if not np.all(np.isfinite(simulated_angle)):
            return 1e3
        return self.distance(*self.levels(simulated_angle))

    def distance(self, lp: np.ndarray, lm: np.ndarray) -> float:
        """The RMS dB error [dB] over the content bins, from the measured and model levels (m,)."""
        sel = (lp >= self.threshold) | (lm >= self.threshold)
        return float(np.sqrt(np.sum((lp[sel] - lm[sel]) ** 2) / self.content))


def joint_lsd(casing_db: float, angular_db: float | None) -> float:
    """The two channels' distance [dB]: the RMS of the casing's and the encoder's LSD (the
    casing's alone without an encoder)."""
    if angular_db is None:
        return float(casing_db)
    return float(math.sqrt(0.5 * (casing_db ** 2 + angular_db ** 2)))


def compare_angles(model_angle: np.ndarray, measured_angle: np.ndarray, fs: float, shaft_hz: float, *,
                   z1: int, z2: int, resolution: float = 2.0, discrepancy=None, line_db: float = 6.0,
                   max_shaft_order: int = 4) -> AngularComparison:
    """Compare the model's and the measured pinion angle (both (n,) [rad], same ``fs`` [Hz]) at
    the pinion speed ``shaft_hz`` [Hz]; ``resolution`` [Hz] as the casing comparison's."""
    from scipy.ndimage import median_filter
    from scipy.signal import find_peaks

    from twin.compare import Finding

    n = min(np.asarray(model_angle).size, np.asarray(measured_angle).size)
    obj = AngularObjective(np.asarray(measured_angle, float)[-n:], fs, max(resolution, 4.0 * fs / n), discrepancy)
    lp, lm = obj.levels(np.asarray(model_angle, float)[-n:])
    f = obj.frequencies[obj.band]
    d = lp - lm
    d2 = d ** 2
    total = float(np.sum(d2)) or 1.0
    df = float(f[1] - f[0])
    tol = 1.5 * df
    gear_hz = shaft_hz * z1 / z2
    used = np.zeros(f.size, bool)
    findings = []
    # a line counts when it differs by line_db beyond what repeated baseline records differ there
    need = line_db + (discrepancy.scatter_at(f) if discrepancy is not None else np.zeros(f.size))

    def line(fc: float, text, order=None, exact: bool = False):
        idx = np.flatnonzero(np.abs(f - fc) <= tol)
        idx = idx[~used[idx]]
        if idx.size == 0:
            return
        j = idx[np.argmax(np.abs(d[idx]))]
        if abs(d[j]) < need[j]:
            return
        used[idx] = True
        findings.append(Finding(KIND, text(float(d[j])), fc if exact else float(f[j]), (float(f[idx[0]]), float(f[idx[-1]])),
                                float(d[j]), float(np.sum(d2[idx]) / total), order))

    for name, fo in (("pinion", shaft_hz), ("gear", gear_hz)):
        for m in range(1, max_shaft_order + 1):
            line(m * fo, lambda sz, m=m, name=name, fo=fo: f"{sz:+.1f} dB at {m}x {name} speed ({m * fo:.1f} Hz) "
                 "in the encoder's angular vibration", order=m * fo / shaft_hz)
    # a line's frequency is read on a zero-padded FFT of the whole stretch, as twin.compare does:
    # the gear's orders are 7 Hz apart at 20 Hz, so a Welch bin would make every line look locked
    ffine, fine = padded_spectrum(angular_vibration(np.asarray(measured_angle, float)[-n:], fs), fs)
    prom = lp - median_filter(lp, size=max(5, int(round(30.0 / df))) | 1, mode="nearest")
    lock_tol = max(0.1, 0.3 * fs / n)
    for j in find_peaks(prom, height=10.0)[0]:
        if used[j] or abs(d[j]) < need[j]:
            continue
        win = (ffine >= f[j] - df) & (ffine <= f[j] + df)
        fl = float(ffine[win][np.argmax(fine[win])]) if win.any() else float(f[j])
        if any(abs(fl / s - round(fl / s)) * s <= lock_tol for s in (shaft_hz, gear_hz)):
            continue
        line(fl, lambda sz, fl=fl: f"a line at {fl:.1f} Hz locked to no shaft in the encoder's angular vibration "
                                   f"({sz:+.1f} dB above the model)", exact=True)
    findings.sort(key=lambda x: -x.share)
    return AngularComparison(obj.distance(lp, lm), tuple(findings), f, lp, lm)


def joint(casing, angular: AngularComparison | None):
    """The casing's :class:`twin.compare.Comparison` with the encoder's folded in: the joint
    LSD (:func:`joint_lsd`), both channels' findings with their shares of the joint squared
    distance, and ``angular`` kept for the findings' band errors. Unchanged without an encoder."""
    if angular is None:
        return casing
    a2, b2 = casing.lsd_db ** 2, angular.lsd_db ** 2
    wa, wb = (a2 / (a2 + b2), b2 / (a2 + b2)) if a2 + b2 > 0 else (0.5, 0.5)
    findings = [replace(fd, share=fd.share * wa) for fd in casing.findings]
    findings += [replace(fd, share=fd.share * wb) for fd in angular.findings]
    findings.sort(key=lambda x: -x.share)
    return replace(casing, lsd_db=joint_lsd(casing.lsd_db, angular.lsd_db), findings=tuple(findings),
                   angular=angular)


def band_error(angular: AngularComparison, band: tuple[float, float]) -> float:
    """Sum of the squared dB differences of the encoder channel within ``band`` [Hz]."""
    sel = (angular.freqs >= band[0] - 1e-9) & (angular.freqs <= band[1] + 1e-9)
    return float(np.sum((angular.level_measured[sel] - angular.level_model[sel]) ** 2))
