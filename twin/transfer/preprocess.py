"""Preprocessing and windowing: records -> normalised 2048-sample windows.

Every record, source or target, goes through the same steps (the settings are saved with the
model, so ``assess`` windows new data exactly as training did):

1. **channel** -- one acceleration channel (default ``accel_pinion_casing``); a record without
   it is an error naming the record and the channel.  A rig that names its accelerometer
   differently gives that name as ``target_channel``: rig data (``fit``'s target, ``predict``,
   ``assess``) are read from it, the twin's data from ``channel``.
2. **resampling** -- to ``sample_rate`` (default 20 kHz) with
   :func:`twin.measurements.resample_record` (polyphase FIR, anti-aliased, flat to 80 % of the
   new Nyquist frequency).  The rule is a window of two pinion revolutions,
   ``sample_rate = 1024 x shaft speed`` (:meth:`Preprocessing.for_shaft_speed`, ``twin
   train-assessor`` sets it from the archive's test): 20.48 kHz for the lubricated test at 20 Hz, 10.24 kHz for the
   dry test at 10 Hz.  Every tooth is then in every window twice, and the spectrum holds the
   same ~26 mesh harmonics at either speed.  At 20 kHz the dry test's window would hold one
   revolution, and its wear stages were told apart 4 points worse (trials of 2026-11-22).
3. **windowing** -- windows of ``window`` samples (2048, the paper's segment length) every ``hop``
   samples from the start of the record; the tail shorter than a window is dropped.
4. **normalisation** (``normalise``), two documented choices:

   * ``"window"`` -- ``(x - mean) / std`` per window.  It cancels the sensor gain (and any gain
     error of the rig), so the network sees waveform shape only, never level.
   * ``"domain"`` (default) -- ``(x - mean) / s_domain``: the window mean is removed, and every
     window of a domain is divided by one scale, the median window standard deviation of that
     domain's training data (source: the twin's windows; target: the unlabelled rig windows
     given to ``fit``, stored with the model and reused by ``predict``/``assess``).  It cancels a
     constant sensor gain as well, but keeps the *relative* level between records, which is
     where most of the damage information sits: in the twin's archives the casing RMS grows
     about fivefold from the first to the last pitting stage and more than threefold over the
     wear stages, and per-window normalisation throws that away.  The price is an assumption,
     stated in the README: the rig's adaptation data must cover the stages in roughly the
     proportion of the source (the median then sits at a comparable stage), as the MMD
     alignment assumes anyway.
   * ``"none"`` -- raw samples (for tests).

   (This step is described for ``representation="waveform"``; for the log spectrum see step 5.)
5. **representation** (``representation``):

   * ``"log_spectrum"`` (default) -- the window's log-magnitude spectrum (``window`` bins up to
     the Nyquist frequency, :func:`log_spectrum`): a multitaper estimate (``time_bandwidth`` NW
     = 4, five Slepian tapers), whose scatter from window to window is a third of a single
     taper's.  Per domain ("domain" normalisation), the domain's mean log spectrum is removed: a
     linear transfer path (accelerometer, mount, casing, foundation) adds the same ``log|H(f)|``
     to every spectrum of a rig, so this cancels a transfer path the twin never modelled (and a
     constant sensor gain with it), the cepstral mean normalisation of speech recognition applied
     to the vibration channel (:func:`domain_normaliser`).  The scale is the source's and is
     shared.  Each window's *level* (its mean log magnitude) is kept: it carries the damage.  Once
     the wear depth is far above the teeth's elastic deflection, the transmission error follows the
     worn profile, so the vibration grows in proportion to the depth while its spectral shape
     hardly changes (wear stages 3 and 4 of the dry test differ by 0.36 in log level and little
     else).  What the level costs is robustness to a gain that changes from record to record;
     ``remove_level=True`` (or ``normalise="window"``) removes it where a stage's level step is
     within the rig's gain scatter, as for pitting: tooth-local damage shows in the spectral
     shape, and the early pitting stages differ in level by only ~19 % per stage
     (``twin.transfer.benchmark_data.TASK_REMOVE_LEVEL``).
   * ``"waveform"`` -- the paper's raw samples, normalised as in step 4.

   Why the default changed from the paper's waveform: on the benchmark's pitting task (same data),
   the source-only CNN fed waveforms reaches 38 % on the rig (6 stages), because the rig's mount
   and casing reshape the spectrum; fed centred log spectra it reaches 70 %, and the proposed
   method 94 % instead of 62 % (``BENCHMARKS.md``, Hann taper with the level removed, as saved
   by assessor format version 2).

Simulation-side augmentation (:class:`Augmentation`, source training windows only, re-drawn every
epoch from a seeded generator): a speed jitter (the record is time-stretched by a factor
``1 + speed_jitter * N(0, 1)`` by linear interpolation, moving every mesh line like a small speed
error), a random window start (so windows do not always start at the same mesh phase), a sensor
gain ``exp(gain * N(0, 1))`` (per record: the rig's gain scatters from record to record; cancelled by
``normalise="window"``), and white noise of ``U(0, noise)`` times the window's standard deviation.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from twin.errors import MeasurementError, ParameterError
from twin.transfer.errors import AssessorError

__all__ = ["Augmentation", "DomainNormaliser", "NORMALISATIONS", "Preprocessing", "Prepared", "REPRESENTATIONS",
           "apply_normalisation", "augmented_windows", "domain_normaliser", "domain_scale", "log_spectrum",
           "normalise", "prepare", "split_records", "window_signal", "windows_of"]


NORMALISATIONS = ("domain", "window", "none")
REPRESENTATIONS = ("log_spectrum", "waveform")


@dataclass(frozen=True)
class Preprocessing:
    """How records become network inputs (saved with the model).

    Attributes
    ----------
    channel : str
        Acceleration channel of the twin's (source) data.
    target_channel : str or None
        The rig's name for the same channel; ``None`` means the rig uses ``channel`` too.
    sample_rate : float
        Rate the records are resampled to [Hz].
    window : int
        Samples per window (network input length).  Must be a multiple of 32 (five max-pools).
    hop : int
        Samples between window starts.
    normalise : {"domain", "window", "none"}
        See step 4 of the module docstring.
    representation : {"log_spectrum", "waveform"}
        What the network sees (step 5): the window's log-magnitude spectrum (``window`` bins,
        0 to the Nyquist frequency) or the paper's raw samples.
    time_bandwidth : float
        Multitaper time-bandwidth product NW of the log spectrum (:func:`log_spectrum`); 0 means
        a single Hann taper.  Ignored for ``waveform``.
    remove_level : bool
        Log spectrum with ``normalise="domain"`` only: also remove each window's mean log
        magnitude (its level), as ``normalise="window"`` always does.  Off by default: the level
        between records carries deep wear (step 5).  Turn it on where a stage's level step is
        within the rig's record-to-record gain scatter, e.g. for early pitting.
    """

    channel: str = "accel_pinion_casing"
    sample_rate: float = 20_000.0
    window: int = 2048
    hop: int = 1024
    normalise: str = "domain"
    representation: str = "log_spectrum"
    time_bandwidth: float = 4.0
    remove_level: bool = False
    target_channel: str | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.channel, str) or not self.channel:
            raise ParameterError(f"channel must be a non-empty string, got {self.channel!r}")
        if self.target_channel is not None and (not isinstance(self.target_channel, str) or not self.target_channel):
            raise ParameterError(f"target_channel must be a non-empty string or None, got {self.target_channel!r}")
        if not (isinstance(self.sample_rate, (int, float)) and math.isfinite(self.sample_rate)
                and self.sample_rate > 0):
            raise ParameterError(f"sample_rate must be a finite number > 0 [Hz], got {self.sample_rate!r}")
        if not isinstance(self.window, int) or self.window < 32 or self.window % 32:
            raise ParameterError(f"window must be a positive multiple of 32 samples, got {self.window!r}")
        if not isinstance(self.hop, int) or self.hop < 1:
            raise ParameterError(f"hop must be a positive integer [samples], got {self.hop!r}")
        if self.normalise not in NORMALISATIONS:
            raise ParameterError(f"normalise must be one of {', '.join(NORMALISATIONS)}, got {self.normalise!r}")
        if self.representation not in REPRESENTATIONS:
            raise ParameterError(f"representation must be one of {', '.join(REPRESENTATIONS)}, "
                                 f"got {self.representation!r}")
        if not isinstance(self.remove_level, bool):
            raise ParameterError(f"remove_level must be True or False, got {self.remove_level!r}")
        nw = self.time_bandwidth
        if not (isinstance(nw, (int, float)) and math.isfinite(nw) and (nw == 0 or 1 <= nw < self.window / 4)):
            raise ParameterError(f"time_bandwidth must be 0 (Hann taper) or in [1, window/4 = {self.window / 4:g}), "
                                 f"got {nw!r}")

    def to_dict(self) -> dict:
        return asdict(self)

    def channel_of(self, domain: str) -> str:
        """The channel read from ``"source"`` (twin) or ``"target"`` (rig) data."""
        if domain not in ("source", "target"):
            raise ParameterError(f"domain must be 'source' or 'target', got {domain!r}")
        return self.channel if domain == "source" else (self.target_channel or self.channel)

    @classmethod
    def for_shaft_speed(cls, speed: float, revolutions: float = 2.0, **settings) -> "Preprocessing":
        """Settings whose window spans ``revolutions`` pinion revolutions at ``speed`` [Hz].

        ``sample_rate = window * speed / revolutions``: 20.48 kHz for the lubricated test (20 Hz)
        and 10.24 kHz for the dry test (10 Hz) with the default 2048-sample window, so every
        window holds every tooth twice and the same ~26 mesh harmonics, whatever the test speed.
        ``settings`` are the other :class:`Preprocessing` fields.
        """
        if not (isinstance(speed, (int, float)) and math.isfinite(speed) and speed > 0):
            raise ParameterError(f"shaft speed must be a finite number > 0 [Hz], got {speed!r}")
        if not (isinstance(revolutions, (int, float)) and math.isfinite(revolutions) and revolutions > 0):
            raise ParameterError(f"revolutions must be a finite number > 0, got {revolutions!r}")
        window = settings.get("window", cls.window)
        return cls(sample_rate=window * speed / revolutions, **settings)


@dataclass(frozen=True)
class Augmentation:
    """Random perturbations of the source windows during training (see the module docstring).

    Attributes
    ----------
    noise : float
        Largest added white-noise standard deviation, relative to the window's [-].
    gain : float
        Standard deviation of the log gain [-].
    speed_jitter : float
        Relative standard deviation of the time-stretch factor [-].
    """

    noise: float = 0.1
    gain: float = 0.1
    speed_jitter: float = 0.02

    def __post_init__(self) -> None:
        for name, v in asdict(self).items():
            if not (isinstance(v, (int, float)) and math.isfinite(v) and 0 <= v < 1):
                raise ParameterError(f"Augmentation.{name} must be in [0, 1), got {v!r}")

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Prepared:
    """One record after steps 1-2: ``signal`` (n,) float64 at the preprocessing rate."""

    name: str
    signal: np.ndarray
    label: int | None


def window_signal(x: np.ndarray, window: int, hop: int) -> np.ndarray:
    """Windows of a 1-D signal, shape (n_windows, window); (0, window) if it is too short."""
    x = np.asarray(x, dtype=np.float64)
    if x.size < window:
        return np.empty((0, window))
    n = (x.size - window) // hop + 1
    idx = np.arange(window)[None, :] + hop * np.arange(n)[:, None]
    return x[idx]


def apply_normalisation(w: np.ndarray, mode: str) -> np.ndarray:
    """Per-window part of step 4: z-score ("window"), mean removal ("domain"), nothing ("none")."""
    if mode == "window":
        return normalise(w)
    if mode == "domain":
        return w - w.mean(axis=-1, keepdims=True)
    return w


def log_spectrum(w: np.ndarray, time_bandwidth: float = 4.0) -> np.ndarray:
    """Log-magnitude spectrum of each window, shape (n, window) -> (n, window).

    ``time_bandwidth`` NW > 0: Thomson's multitaper estimate -- the power spectra of the window
    under unit-energy discrete prolate spheroidal (Slepian) tapers, averaged, so the estimate has
    ``K`` times the degrees of freedom of a single taper.  Of the ``2 NW - 1`` tapers of the
    textbook rule only those whose out-of-band leakage is at most 0.1 % are used (NW = 4: K = 5):
    the higher-order ones leak up to 6 %, which fills the spectrum between strong mesh lines with
    leakage that a transfer path weights differently, and the domain centring cannot cancel that
    (on a clean two-line signal through a mount resonance it leaves 31 % of the path's effect
    with seven tapers, 13 % with five, 4 % with one Hann taper).  The log of a single taper's
    periodogram scatters by ``sqrt(pi**2 / 6)`` = 1.28 (log power) from window to window even
    for a stationary signal; with K = 5 by ``sqrt(trigamma(5))`` = 0.47, at a resolution of
    ``2 NW / T`` (80 Hz for a 0.1 s window, below the 380 Hz mesh-line spacing at 20 Hz shaft
    speed).  ``time_bandwidth`` 0: one Hann taper (assessors saved before version 3).

    Zero-padded to twice the window, so there are ``window`` bins from 0 Hz up to (not including)
    the Nyquist frequency, spaced ``sample_rate / (2 window)``; the value is half the log power,
    i.e. the log magnitude.  The small absolute floor only keeps an all-zero window finite.
    """
    w = np.asarray(w, dtype=np.float64)
    n = w.shape[-1]
    if time_bandwidth == 0:
        mag = np.abs(np.fft.rfft(w * np.hanning(n), n=2 * n, axis=-1))[..., :n]
        return np.log(mag + 1e-12)
    tapers = _slepian_tapers(n, float(time_bandwidth))                 # (K, n)
    power = np.zeros(w.shape[:-1] + (n,))
    for taper in tapers:                                               # K FFTs; keeps memory at one copy
        power += np.abs(np.fft.rfft(w * taper, n=2 * n, axis=-1)[..., :n]) ** 2
    return 0.5 * np.log(power / len(tapers) + 1e-24)


@functools.lru_cache(maxsize=8)
def _slepian_tapers(n: int, time_bandwidth: float) -> np.ndarray:
    from scipy.signal.windows import dpss

    tapers, concentration = dpss(n, time_bandwidth, Kmax=max(int(2 * time_bandwidth) - 1, 1), norm=2,
                                 return_ratios=True)
    keep = max(int(np.sum(1.0 - concentration <= 1e-3)), 1)     # concentrations are descending
    return tapers[:keep]


def represent(w: np.ndarray, pre: "Preprocessing") -> np.ndarray:
    """Steps 4-5 per window: the representation and its per-window part of the normalisation.

    ``waveform``: :func:`apply_normalisation`.  ``log_spectrum``: :func:`log_spectrum`; with
    ``normalise`` "window" (or "domain" with ``remove_level``) the window's mean log magnitude
    (its level, where a sensor gain shows) is removed, so the network sees spectral *shape* only;
    with "domain" the level stays, and the domain centring removes the rig's constant gain.
    """
    if pre.representation == "waveform":
        return apply_normalisation(w, pre.normalise)
    spec = log_spectrum(w, pre.time_bandwidth)
    if pre.normalise == "window" or (pre.normalise == "domain" and pre.remove_level):
        return spec - spec.mean(axis=-1, keepdims=True)
    return spec


@dataclass(frozen=True)
class DomainNormaliser:
    """The per-domain part of the normalisation: ``(x - centre) / scale``.

    ``centre`` is 0.0 or an array of shape (window,); ``scale`` > 0.
    """

    centre: np.ndarray | float
    scale: float

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return ((x - self.centre) / self.scale).astype(np.float32)

    def to_dict(self) -> dict:
        c = self.centre
        return {"centre": c.tolist() if isinstance(c, np.ndarray) else float(c), "scale": float(self.scale)}

    @classmethod
    def from_dict(cls, d: dict) -> "DomainNormaliser":
        c = d["centre"]
        return cls(np.asarray(c, dtype=np.float32) if isinstance(c, list) else float(c), float(d["scale"]))


IDENTITY = DomainNormaliser(0.0, 1.0)


def domain_normaliser(x: np.ndarray, pre: "Preprocessing", reference: DomainNormaliser | None = None
                      ) -> DomainNormaliser:
    """The normaliser of one domain, learned from its unlabelled represented windows ``x`` (n, window).

    * ``waveform`` + "domain": centre 0, scale = :func:`domain_scale` of the domain's own windows.
    * ``log_spectrum`` + "domain": centre = the domain's mean log spectrum (per bin), scale = the
      standard deviation of the centred *reference* (source) values, shared by both domains.
      A linear transfer path ``H(f)`` (sensor, mount, casing) multiplies every spectrum of a
      domain by ``|H(f)|``, i.e. adds ``log|H(f)|`` to every log spectrum; subtracting the
      domain's mean log spectrum removes it -- the cepstral mean normalisation of speech
      recognition, applied to the vibration channel.  It assumes the stages are represented in
      roughly the same proportions in both domains (as the MMD alignment does too).
      ``reference`` None means ``x`` is the reference.
    * any other normalisation: the identity.
    """
    if pre.normalise != "domain":
        return IDENTITY
    if pre.representation == "waveform":
        return DomainNormaliser(0.0, domain_scale(x))
    centre = np.asarray(x, dtype=np.float64).mean(axis=0)
    if reference is None:
        sd = float(np.std(np.asarray(x, dtype=np.float64) - centre))
        scale = sd if sd > 0 else 1.0
    else:
        scale = reference.scale
    return DomainNormaliser(centre.astype(np.float32), scale)


def domain_scale(w: np.ndarray) -> float:
    """The "domain" scale: median standard deviation of the windows (n, window); 1 if that is 0."""
    s = float(np.median(np.asarray(w).std(axis=-1)))
    return s if s > 0 else 1.0


def normalise(w: np.ndarray) -> np.ndarray:
    """Per-row zero mean and unit standard deviation, shape kept; a constant row becomes zeros."""
    w = np.asarray(w, dtype=np.float64)
    mu = w.mean(axis=-1, keepdims=True)
    sd = w.std(axis=-1, keepdims=True)
    return (w - mu) / np.where(sd > 0, sd, 1.0)


def _from_records(records: Iterable, pre: Preprocessing, what: str, channel: str) -> list[Prepared]:
    from twin.measurements import Record, resample_record

    out = []
    for rec in records:
        if not isinstance(rec, Record):
            raise AssessorError(f"{what}: expected measurement Records, got {type(rec).__name__}")
        if channel not in rec.channels:
            raise MeasurementError(rec.source or "<memory>", rec.name,
                                   f"{what}: record has no channel '{channel}' "
                                   f"(channels: {', '.join(rec.channels)})")
        if not math.isclose(rec.sample_rate, pre.sample_rate, rel_tol=1e-9):
            only = Record(rec.name, {channel: rec[channel]}, {channel: rec.units[channel]},
                          rec.sample_rate, label=rec.label, source=rec.source)
            rec, _ = resample_record(only, pre.sample_rate)
        out.append(Prepared(rec.name, np.asarray(rec[channel], dtype=np.float64), rec.label))
    return out


def prepare(data, pre: Preprocessing, what: str = "data", domain: str = "source") -> list[Prepared]:
    """Steps 1-2 for a path, a :class:`~twin.measurements.MeasurementSet`, Records or an Archive.

    ``domain`` ("source" or "target") picks the channel (:meth:`Preprocessing.channel_of`).

    Raises
    ------
    MeasurementError
        Unreadable file, missing channel (naming record and channel).
    AssessorError
        An input of another type, or no records.
    """
    from twin.archive import Archive
    from twin.measurements import MeasurementSet, load_measurements

    channel = pre.channel_of(domain)
    if isinstance(data, (str, Path)):
        data = load_measurements(data, channels=[channel], resample_to=pre.sample_rate)
    if isinstance(data, Archive):
        if channel not in data.signals:
            raise MeasurementError(str(data.path or "<archive>"), None,
                                   f"{what}: archive has no channel '{channel}' "
                                   f"(channels: {', '.join(data.signals)})")
        from twin.measurements import Record
        data = [Record(f"{i:06d}", {channel: data.signals[channel][i]}, {channel: "m/s2"},
                       data.sample_rate, label=int(data.labels[i]))
                for i in range(data.labels.size)]
    if isinstance(data, MeasurementSet):
        data = data.records
    if isinstance(data, np.ndarray) or not isinstance(data, (list, tuple)):
        raise AssessorError(f"{what}: expected a measurement file path, MeasurementSet, list of Records or "
                            f"Archive, got {type(data).__name__}")
    out = _from_records(data, pre, what, channel)
    if not out:
        raise AssessorError(f"{what}: no records")
    return out


def windows_of(prepared: Sequence[Prepared], pre: Preprocessing, what: str = "data"
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steps 3-4: (windows (n, window) float32, record index (n,), label (n,) with -1 = unknown).

    Raises
    ------
    AssessorError
        A record shorter than one window (naming it and its length).
    """
    ws, rec, lab = [], [], []
    for i, p in enumerate(prepared):
        w = window_signal(p.signal, pre.window, pre.hop)
        if w.shape[0] == 0:
            raise AssessorError(f"{what}: record '{p.name}' has {p.signal.size} samples at "
                                f"{pre.sample_rate:g} Hz, shorter than one window of {pre.window}")
        ws.append(represent(w, pre))
        rec.append(np.full(w.shape[0], i))
        lab.append(np.full(w.shape[0], -1 if p.label is None else p.label))
    return (np.concatenate(ws).astype(np.float32), np.concatenate(rec), np.concatenate(lab))


def augmented_windows(prepared: Sequence[Prepared], pre: Preprocessing, aug: Augmentation,
                      rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """One epoch of augmented source windows: (windows (n, window) float32, labels (n,)).

    As many windows per record as :func:`windows_of` gives, each cut at a random start from the
    record time-stretched by its own speed-jitter factor.
    """
    ws, labels = [], []
    for p in prepared:
        n = len(window_signal(p.signal, pre.window, pre.hop))
        x = p.signal
        gain = math.exp(aug.gain * float(rng.standard_normal()))      # one sensor gain per record
        for _ in range(n):
            # Stretched signal y(t) = x(r t): the window covers (window - 1) r original samples,
            # which must fit in the record (a record of exactly one window can only be compressed).
            r = min(1.0 + aug.speed_jitter * float(rng.standard_normal()), (x.size - 1) / (pre.window - 1))
            span = (pre.window - 1) * r
            start = float(rng.uniform(0.0, max(x.size - 1 - span, 0.0)))
            t = start + r * np.arange(pre.window)
            w = gain * np.interp(t, np.arange(x.size), x)
            w = w + rng.normal(0.0, aug.noise * float(rng.uniform()) * float(w.std()), size=w.shape)
            ws.append(w)
            labels.append(p.label)
    return represent(np.asarray(ws), pre).astype(np.float32), np.asarray(labels, dtype=np.int64)


def split_records(data, fraction: float = 0.5) -> tuple[list, list]:
    """Cut every record in two disjoint stretches: ([first ``fraction``], [the rest]).

    The benchmark adapts on the first halves of the target records and tests on the second
    halves, so no test sample was ever seen (even unlabelled) during training.
    """
    from dataclasses import replace

    from twin.measurements import MeasurementSet, load_measurements

    if not 0 < fraction < 1:
        raise ParameterError(f"fraction must be in (0, 1), got {fraction!r}")
    if isinstance(data, (str, Path)):
        data = load_measurements(data)
    recs = data.records if isinstance(data, MeasurementSet) else list(data)
    first, second = [], []
    for r in recs:
        cut = int(round(r.n_samples * fraction))
        first.append(replace(r, channels={c: x[:cut] for c, x in r.channels.items()}))
        second.append(replace(r, channels={c: x[cut:] for c, x in r.channels.items()},
                              time_start=r.time_start + cut / r.sample_rate))
    return first, second
