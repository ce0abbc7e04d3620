"""Compare the twin with a measurement and split the discrepancy into localised findings.

Headline metric: the **log-spectral distance** (LSD) in dB over the analysed band: the RMS of the
difference between the measured and simulated Welch PSDs in dB (see :func:`spectral_levels`). The
measurement is signal plus noise, so the model PSD gets the measured noise level (the median
measured level) added, and both are floored 3 dB above it: bins where the measurement only shows
its noise do not count. The model level is shifted by the median difference (at most 1 dB) so that
a sensor gain error of a few percent is not reported as a discrepancy.

The squared differences D(f)^2 are then attributed to localised findings, each with a band, a size
in dB and a share of the total sum of D^2:

* ``mesh_harmonic``: a gear-mesh harmonic k x GMF whose level differs;
* ``sideband``: lines at k x GMF +- m x shaft speed (pinion or gear), grouped per harmonic and
  shaft: modulation once per revolution (run-out, a local tooth fault);
* ``shaft_order``: lines at low multiples of a shaft speed;
* ``unlocked_line``: a measured line at no multiple of either shaft speed (motor ripple, an
  electrical or structural source the model does not have);
* ``resonance``: a broadband region where the measured level exceeds the model by more than
  ``resonance_db`` after median smoothing (an unmodelled resonance in the path to the sensor), or
  falls short of it;
* ``impulsive``: the synchronous average over the pinion revolution is far more impulsive
  (kurtosis) in the measurement than in the model, i.e. one event per revolution.

The rules use the physics of gear vibration (orders, sidebands, resonances, synchronous against
non-synchronous content, impulsiveness), not properties of our simulator, so they apply to
measurements from any rig.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.ndimage import median_filter
from scipy.signal import find_peaks
from scipy.stats import kurtosis

from twin.signals import padded_spectrum, shaft_angle_from_speed, synchronous_average, welch_psd


MAX_GAIN_DB = 1.0   # sensor sensitivity uncertainty absorbed by the level alignment (about +-12 %)


def spectral_levels(pm: np.ndarray, pp: np.ndarray, *, max_gain_db: float = MAX_GAIN_DB
                    ) -> tuple[np.ndarray, np.ndarray, float]:
    """Measured and model levels [dB] on which the log-spectral distance is taken.

    ``pm``, ``pp``: (n,) model and measured PSDs over the analysed band. The measurement is signal
    plus noise, so the model is compared with its PSD plus the measured noise level (the median
    measured level); both are floored 3 dB above that level. A sensor gain error of a few percent is not a missing
    effect: the model level is shifted by the median dB difference over the bins above the floor,
    limited to +-``max_gain_db``. Returns (measured dB, model dB, applied gain [dB]).
    """
    noise = max(float(np.median(pp)), 1e-30)
    # floored 3 dB above the noise level: a Welch estimate of pure noise rarely gets there, so
    # bins that only hold noise count as equal instead of adding their estimation scatter
    floor = 2.0 * noise
    lp = 10 * np.log10(np.maximum(pp, floor))
    above = lp > 10 * np.log10(floor)
    raw = 10 * np.log10(np.maximum(pm + noise, floor))
    gain = float(np.clip(np.median((lp - raw)[above]), -max_gain_db, max_gain_db)) if above.any() else 0.0
    lm = 10 * np.log10(np.maximum(pm * 10 ** (gain / 10) + noise, floor))
    return lp, lm, gain


@dataclass(frozen=True)
class Finding:
    kind: str                    # mesh_harmonic, sideband, shaft_order, unlocked_line, resonance, impulsive,
                                 # envelope_line (a series in the envelope), angular_line (the encoder's,
                                 # twin.angular)
    description: str
    frequency_hz: float          # centre (or the line)
    band_hz: tuple[float, float]
    size_db: float               # measured minus model [dB] (kurtosis difference for impulsive, the
                                 # series' prominence in the envelope for envelope_line)
    share: float                 # share of the total squared log-spectral difference (0..1)
    order: float | None = None   # in pinion orders, when locked


@dataclass(frozen=True)
class Comparison:
    lsd_db: float                        # headline: log-spectral distance [dB]
    f1: float                            # 1 - corr(TSA waveforms)
    f2: float                            # 1 - corr(dB spectra)
    rms_measured: float
    rms_model: float
    shaft_hz: float                      # pinion speed used for orders [Hz]
    findings: tuple[Finding, ...]
    freqs: np.ndarray = field(repr=False)           # (n,) Hz
    level_measured: np.ndarray = field(repr=False)  # (n,) dB, floored
    level_model: np.ndarray = field(repr=False)     # (n,) dB, floored
    # the encoder channel folded in (twin.angular.joint): lsd_db and the findings' shares are then
    # the two channels' together
    angular: object = field(default=None, repr=False)

    def to_dict(self) -> dict:
        return {"headline": {"log_spectral_distance_db": self.lsd_db,
                             "definition": "RMS over the band of (measured - model) Welch PSD in dB; the model PSD "
                                           "plus the measured noise level (median), both floored 3 dB above "
                                           "it, the model shifted by the median dB difference (sensor gain, "
                                           "at most 1 dB)"},
                "f1_waveform": self.f1, "f2_spectrum": self.f2,
                "rms": {"measured": self.rms_measured, "model": self.rms_model},
                "shaft_hz": self.shaft_hz,
                "findings": [asdict(f) for f in self.findings],
                **({"encoder": {"log_spectral_distance_db": self.angular.lsd_db,
                                "definition": "the same over the encoder's angular vibration (the angle less a "
                                              "quadratic in time), 2-500 Hz; the headline is then the RMS of the "
                                              "casing's and the encoder's"}} if self.angular is not None else {})}


def compare_signals(model: np.ndarray, measured: np.ndarray, fs: float, shaft_hz: float, *,
                    z1: int = 19, z2: int = 52, fmin: float = 10.0, fmax: float = 5000.0,
                    resolution: float = 2.0, line_db: float = 6.0, resonance_db: float = 6.0,
                    max_shaft_order: int = 4, n_harmonics: int | None = None, n_sidebands: int = 3,
                    discrepancy=None) -> Comparison:
    """Compare a simulated and a measured signal (both (n,), same ``fs`` [Hz]) of the same operating point.

    ``discrepancy``: a known model-form error taken out of the measured levels first (an object
    with ``at(frequencies) -> dB``, :class:`twin.effects.baseline.Discrepancy`): the distance and
    the findings are then of what differs beyond it.

    ``shaft_hz`` is the pinion (input shaft) speed [Hz]; the gear turns at shaft_hz * z1 / z2.
    ``n_harmonics`` defaults to every mesh harmonic in the band: a resonance in the transfer path
    that only lifts the lines near it shows up as findings on those harmonics and their sidebands.
    """
    from twin.calibration.objectives import spectrum_mismatch, waveform_mismatch

    model = np.asarray(model, float)
    measured = np.asarray(measured, float)
    n = min(model.size, measured.size)
    model, measured = model[:n], measured[:n]
    resolution = max(resolution, 4.0 * fs / n)
    f, pm = welch_psd(model, fs, resolution=resolution)
    _, pp = welch_psd(measured, fs, resolution=resolution)
    band = (f >= fmin) & (f <= min(fmax, fs / 2))
    f, pm, pp = f[band], pm[band], pp[band]
    lp, lm, gain_db = spectral_levels(pm, pp)
    # a line counts when it differs by line_db beyond what repeated baseline records differ there
    need = np.full(f.size, float(line_db))
    if discrepancy is not None:
        lp = lp - discrepancy.at(f)
        scatter_at = getattr(discrepancy, "scatter_at", None)
        if scatter_at is not None:
            need = need + scatter_at(f)
    d = lp - lm                                   # measured minus model [dB]
    d2 = d ** 2
    total = float(np.sum(d2)) or 1.0
    lsd = float(np.sqrt(np.mean(d2)))
    df = f[1] - f[0]
    gear_hz = shaft_hz * z1 / z2
    gmf = z1 * shaft_hz
    tol = 1.5 * df

    used = np.zeros(f.size, bool)
    findings: list[Finding] = []

    def bins_near(fc: float, width: float = tol) -> np.ndarray:
        return np.flatnonzero(np.abs(f - fc) <= width)

    def line_finding(kind, describe, fc, order=None):
        """A finding for the line near fc if its level differs by >= line_db; describe(size) -> text."""
        idx = bins_near(fc)
        if idx.size == 0:
            return
        j = idx[np.argmax(np.abs(d[idx]))]
        size = float(d[j])
        if abs(size) < need[j]:
            return
        used[idx] = True
        findings.append(Finding(kind, describe(size), float(f[j]), (float(f[idx[0]]), float(f[idx[-1]])), size,
                                float(np.sum(d2[idx]) / total), order))

    # mesh harmonics and their sidebands (grouped per harmonic and shaft)
    for k in range(1, (n_harmonics or int(f[-1] // gmf)) + 1):
        fk = k * gmf
        if fk > f[-1]:
            break
        line_finding("mesh_harmonic", lambda sz, k=k, fk=fk: f"{sz:+.1f} dB at {k}x GMF ({fk:.1f} Hz)", fk,
                     order=k * z1)
        for name, fs_hz in (("pinion", shaft_hz), ("gear", gear_hz)):
            idx = np.concatenate([bins_near(fk + s * m * fs_hz) for m in range(1, n_sidebands + 1) for s in (-1, 1)])
            idx = np.unique(idx[(idx >= 0)])
            idx = idx[~used[idx]]
            if idx.size == 0:
                continue
            big = idx[np.abs(d[idx]) >= need[idx]]
            if big.size == 0:
                continue
            size = float(np.mean(d[big]))
            used[idx] = True
            findings.append(Finding("sideband", f"{size:+.1f} dB at {k}x GMF +- 1..{n_sidebands}x {name} speed "
                                                f"({fs_hz:.2f} Hz)", float(fk), (float(f[idx[0]]), float(f[idx[-1]])),
                                    size, float(np.sum(d2[idx]) / total), k * z1))
    # low shaft orders
    for name, fs_hz in (("pinion", shaft_hz), ("gear", gear_hz)):
        for m in range(1, max_shaft_order + 1):
            line_finding("shaft_order",
                         lambda sz, m=m, name=name, fo=m * fs_hz: f"{sz:+.1f} dB at {m}x {name} speed ({fo:.1f} Hz)",
                         m * fs_hz, order=m * fs_hz / shaft_hz)
    # measured lines locked to no shaft. Locking is judged on the line frequency measured on a
    # zero-padded full-length FFT, not on the Welch bins: the gear's orders are only
    # shaft_hz * z1 / z2 apart (7 Hz at 20 Hz), so a Welch bin would make every line look locked.
    ffine, fine = padded_spectrum(measured, fs)
    # a strong line on a zero-padded FFT is located far better than 1/T: 0.3/T still separates a
    # ripple line from a shaft order 1 Hz away in a 1 s record
    lock_tol = max(0.1, 0.3 * fs / n)          # Hz
    prom = lp - median_filter(lp, size=max(5, int(round(30.0 / df))) | 1, mode="nearest")
    peaks, _ = find_peaks(prom, height=10.0)
    for j in peaks:
        if used[j] or d[j] < need[j]:
            continue
        win = (ffine >= f[j] - df) & (ffine <= f[j] + df)
        fl = float(ffine[win][np.argmax(fine[win])]) if win.any() else float(f[j])
        o1 = fl / shaft_hz
        o2 = fl / gear_hz
        locked = (abs(o1 - round(o1)) * shaft_hz <= lock_tol) or (abs(o2 - round(o2)) * gear_hz <= lock_tol)
        if locked:
            continue
        idx = bins_near(f[j])
        used[idx] = True
        findings.append(Finding("unlocked_line", f"a line at {fl:.1f} Hz not locked to any shaft "
                                                 f"({d[j]:+.1f} dB above the model)", fl,
                                (float(f[idx[0]]), float(f[idx[-1]])), float(d[j]), float(np.sum(d2[idx]) / total)))
    # broadband regions (lines removed, then median-smoothed over ~100 Hz)
    dd = np.where(used, np.nan, d)
    fill = np.interp(np.arange(f.size), np.flatnonzero(~np.isnan(dd)), dd[~np.isnan(dd)]) if np.any(~np.isnan(dd)) else d
    smooth = median_filter(fill, size=max(3, int(round(100.0 / df))) | 1, mode="nearest")
    for sign, word in ((1, "an unmodelled resonance or path gain near"), (-1, "the model too high near")):
        mask = sign * smooth > resonance_db
        start = None
        for i in range(f.size + 1):
            on = i < f.size and mask[i]
            if on and start is None:
                start = i
            elif not on and start is not None:
                seg = np.arange(start, i)
                if f[seg[-1]] - f[seg[0]] >= 2 * df:
                    c = seg[np.argmax(sign * smooth[seg])]
                    seg_free = seg[~used[seg]]
                    findings.append(Finding("resonance", f"{word} {f[c]:.0f} Hz ({smooth[c]:+.1f} dB over "
                                                         f"{f[seg[0]]:.0f}-{f[seg[-1]]:.0f} Hz)", float(f[c]),
                                            (float(f[seg[0]]), float(f[seg[-1]])), float(smooth[c]),
                                            float(np.sum(d2[seg_free]) / total)))
                    used[seg] = True
                start = None
    # impulsiveness of the synchronous average over the pinion revolution
    angle = shaft_angle_from_speed(n, fs, shaft_hz)
    _, tsa_p, _ = synchronous_average(measured, fs, angle, samples_per_rev=512)
    _, tsa_m, _ = synchronous_average(model, fs, angle, samples_per_rev=512)
    kp, km = float(kurtosis(tsa_p)), float(kurtosis(tsa_m))
    if kp - km > 1.5 and kp > 1.0:
        findings.append(Finding("impulsive", f"impulsive once per pinion revolution (TSA kurtosis {kp:.1f} "
                                             f"measured vs {km:.1f} model)", float(shaft_hz), (0.0, float(f[-1])),
                                kp - km, float(np.sum(d2[~used]) / total), 1.0))
    findings.extend(_envelope_findings(model, measured, fs, shaft_hz, z1, z2, f, d2, used, total, discrepancy))
    findings.sort(key=lambda x: -x.share)
    f1 = waveform_mismatch(model, measured, fs, shaft_hz)
    f2 = spectrum_mismatch(model, measured, fs, fmin=fmin, fmax=fmax, resolution=resolution)
    return Comparison(lsd, f1, f2, float(np.sqrt(np.mean(measured ** 2))), float(np.sqrt(np.mean(model ** 2))),
                      float(shaft_hz), tuple(findings), f, lp, lm)


def _envelope_findings(model, measured, fs, shaft_hz, z1, z2, f, d2, used, total, discrepancy) -> list[Finding]:
    """Harmonic series in the measured record's envelope, locked to neither shaft, that neither
    the model's envelope nor the baseline's (``discrepancy.envelope_orders``) holds: repeated
    impacts not synchronous with the gears, as a rolling-element bearing defect gives
    (:mod:`twin.signals.envelope`). ``share``: of the squared level difference in the
    demodulated band's bins not already explained by another finding (0 when it lies above the
    compared band); the verdict (:func:`twin.effects.verdict.judge`) counts such a finding
    whatever its share."""
    from twin.signals.envelope import envelope_series

    ratio = z1 / z2
    measured_series = [s for s in envelope_series(measured, fs, shaft_hz, gear_ratio=ratio) if s.locked_to is None]
    if not measured_series:
        return []
    known = [s.order for s in envelope_series(model, fs, shaft_hz, gear_ratio=ratio)]
    known += list(getattr(discrepancy, "envelope_orders", ()) or ())
    out = []
    for s in measured_series:
        if any(abs(s.order - o) <= 0.02 * max(s.order, 1.0) for o in known):
            continue
        sel = (f >= s.band_hz[0]) & (f <= s.band_hz[1]) & ~used
        out.append(Finding("envelope_line",
                           f"a modulation at {s.frequency_hz:.1f} Hz ({s.order:.2f}x pinion speed, locked to neither "
                           f"shaft) with {s.harmonics} harmonics, {s.prominence_db:+.0f} dB in the envelope of "
                           f"{s.band_hz[0]:.0f}-{s.band_hz[1]:.0f} Hz: repeated impacts not synchronous with the "
                           "gears, as a rolling-element bearing defect gives", s.frequency_hz, s.band_hz,
                           s.prominence_db, float(np.sum(d2[sel]) / total), s.order))
    return out


@dataclass(frozen=True)
class MeasuredRecord:
    """One measured record with the operating conditions it was taken at."""

    name: str
    signal: np.ndarray          # (n,) [channel unit, m/s2 for accelerations]
    sample_rate: float          # Hz
    nominal_speed: float        # drive setting [Hz]
    load: float                 # brake load [N.m]


def read_record(measurements, channel: str = "accel_pinion_casing", record: str | None = None, *,
                resample_to: float | None = None) -> MeasuredRecord:
    """One record of a measurement file (the first unless ``record`` names one).

    ``resample_to`` [Hz] resamples it (the loader prints what it changed).

    Raises
    ------
    MeasurementError
        An unknown ``record`` (the message lists the file's records), or a record without the
        ``nominal_speed`` [Hz] and ``load`` [N.m] it was taken at.
    """
    from twin.errors import MeasurementError
    from twin.measurements import load_measurements
    mset = load_measurements(measurements, channels=[channel], resample_to=resample_to)
    for note in mset.notes:
        print(f"note: {note}")
    if record and record not in mset.names:
        raise MeasurementError(str(measurements), record, f"no such record; the file has: {', '.join(mset.names)}")
    rec = mset[record] if record else mset[0]
    missing = [a for a in ("nominal_speed", "load") if getattr(rec, a) is None]
    if missing:
        raise MeasurementError(str(measurements), rec.name, f"lacks {', '.join(missing)} (the drive speed [Hz] "
                                                            "and brake load [N.m] the record was taken at)")
    return MeasuredRecord(rec.name, np.asarray(rec[channel], float), float(rec.sample_rate),
                          float(rec.nominal_speed), float(rec.load))


#: Pinion revolutions a compared record must hold: the shaft speed is estimated from the mesh
#: line and the synchronous average needs whole revolutions.
MIN_REVOLUTIONS = 4


def check_duration(measurements, rec: MeasuredRecord, duration: float) -> None:
    """Refuse a non-finite, non-positive or too long ``duration`` [s] of record ``rec``."""
    from twin.errors import MeasurementError
    available = rec.signal.size / rec.sample_rate
    if not (np.isfinite(duration) and duration > 0):
        raise MeasurementError(str(measurements), rec.name, f"--duration must be a positive number of seconds, "
                                                            f"got {duration}")
    if duration > available * (1 + 1e-9):
        raise MeasurementError(str(measurements), rec.name, f"--duration {duration:g} s is longer than the record "
                                                            f"({available:.6g} s)")


def check_length(measurements, rec: MeasuredRecord, n: int) -> None:
    """Refuse a record too short to compare: it must hold :data:`MIN_REVOLUTIONS` pinion
    revolutions at its drive speed; the message gives the length needed."""
    from twin.errors import MeasurementError
    if not rec.nominal_speed > 0:
        raise MeasurementError(str(measurements), rec.name, f"nominal_speed must be > 0 Hz, got {rec.nominal_speed}")
    need = int(np.ceil(MIN_REVOLUTIONS * rec.sample_rate / rec.nominal_speed))
    if n < need:
        raise MeasurementError(str(measurements), rec.name,
                               f"{n} samples ({n / rec.sample_rate:.3g} s) are too short to compare: at least {need} "
                               f"samples ({need / rec.sample_rate:.3g} s, {MIN_REVOLUTIONS} revolutions at "
                               f"{rec.nominal_speed:g} Hz) are needed")


def compare(scenario, measurements, out_dir, *, record: str | None = None, duration: float | None = None,
            solver_step: float | None = 1e-5):
    """``twin compare``: simulate at the record's measured operating point and write the comparison.

    The model runs where the record was taken, as ``twin diagnose`` runs it
    (:func:`twin.operating.measured_operating`): its pinion turns at the shaft speed measured on
    the record (by its encoder, tachometer or speed channel when it has one, else off its gear-mesh
    line, the record's ``nominal_speed`` [Hz] only where that search starts), under the
    record's ``load`` [N.m], sampled at the record's rate, on the RK4 step ``solver_step`` [s]
    (the model's own when None). The parameters are the scenario's.

    Writes to ``out_dir``: ``compare.json`` (headline metric, f1/f2, the operating point and the
    findings), ``simulated.h5`` (the simulated signal), ``compare.png`` (spectra and order
    spectra with the findings marked) and ``compare.html``. Returns the :class:`Comparison`.
    """
    import json
    from dataclasses import asdict
    from pathlib import Path

    from twin.errors import MeasurementError, OutputPathError, ParameterError
    from twin.fmu import FMU
    from twin.operating import measured_operating, simulate_at, stretch_speed
    from twin.results import SimulationResult, write_hdf5

    out_dir = Path(out_dir)
    if not out_dir.parent.exists():
        raise OutputPathError(f"parent directory {out_dir.parent} does not exist")
    if duration is not None and not (duration > 0):
        raise ParameterError(f"duration must be > 0 s, got {duration!r}")
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    rec = read_record(measurements, channel, record)
    measured = rec.signal
    if duration is not None:
        check_duration(measurements, rec, duration)
        measured = measured[-int(round(duration * rec.sample_rate)):]
    check_length(measurements, rec, measured.size)
    fmu_path = scenario.fmu_path()
    params = dict(scenario.parameters)
    with FMU(fmu_path) as fmu:
        current = fmu.parameter_values()
        teeth = {**{k: v for k, v in current.items() if k in ("z1", "z2")}, **fmu.structural_values()}
    z1 = int(round(float(teeth.get("z1", 19))))
    z2 = int(round(float(teeth.get("z2", 52))))
    c_motor = params.get("c_motor", current.get("c_motor"))
    # the pinion speed from the record's encoder, tachometer or speed channel when it has one (as
    # twin diagnose takes it), else from its gear-mesh line
    from twin.effects.records import read_records
    shaft_hz = stretch_speed(read_records(measurements, channel, [rec.name])[0].shaft_hz, measured.size)
    if shaft_hz is not None and not shaft_hz > 0:
        raise MeasurementError(str(measurements), rec.name, f"its pinion speed is {shaft_hz:g} Hz over the stretch "
                                                            "compared; the gearbox must turn")
    op = measured_operating(measured, rec.sample_rate, rec.nominal_speed, rec.load, teeth=z1, gear_teeth=z2,
                            c_motor=c_motor, solver_step=solver_step if "solver.step_size" in current else None,
                            shaft_hz=shaft_hz)
    out_dir.mkdir(exist_ok=True)
    block = simulate_at(fmu_path, params, op, measured.size, [channel, "motor_speed"])
    simulated = block[:, 0]
    comp = compare_signals(simulated, measured, rec.sample_rate, op.shaft_hz, z1=z1, z2=z2)
    from twin._atomic import atomic_path
    with FMU(fmu_path) as fmu:
        identity = (fmu.model_name, fmu.guid, fmu.sha256)
    with atomic_path(out_dir / "compare.json") as tmp:
        Path(tmp).write_text(json.dumps({"scenario": scenario.name, "record": rec.name,
                                         "measurements": str(measurements), "operating": asdict(op),
                                         **comp.to_dict()}, indent=2))
    dt = 1.0 / rec.sample_rate
    t = op.settle + dt * np.arange(1, simulated.size + 1)
    write_hdf5(SimulationResult(t, {channel: simulated, "motor_speed": block[:, 1]},
                                {channel: "m/s2", "motor_speed": "rad/s"}, rec.sample_rate,
                                {**current, **params}, *identity), out_dir / "simulated.h5")
    _plot(comp, simulated, measured, rec.sample_rate, out_dir / "compare.png")
    _html(comp, scenario, rec, out_dir / "compare.html")
    return comp


def _plot(comp: Comparison, simulated, measured, fs, path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from twin._atomic import atomic_path
    from twin.signals import order_spectrum, shaft_angle_from_speed
    envelope = [fd for fd in comp.findings if fd.kind == "envelope_line"]
    fig, axes = plt.subplots(3 if envelope else 2, 1, figsize=(11, 11 if envelope else 8))
    a1, a2 = axes[0], axes[1]
    a1.plot(comp.freqs, comp.level_measured, "k", lw=0.8, label="measured")
    a1.plot(comp.freqs, comp.level_model, "tab:blue", lw=0.8, label="model")
    colors = {"mesh_harmonic": "tab:orange", "sideband": "tab:purple", "shaft_order": "tab:green",
              "unlocked_line": "tab:red", "resonance": "tab:brown", "impulsive": "tab:pink"}
    for i, fd in enumerate(comp.findings[:8]):
        if fd.kind == "envelope_line":           # an envelope frequency: drawn in its own panel
            continue
        c = colors.get(fd.kind, "gray")
        if fd.kind in ("resonance",):
            a1.axvspan(*fd.band_hz, color=c, alpha=0.15)
        elif fd.kind != "impulsive":
            a1.axvline(fd.frequency_hz, color=c, ls="--", lw=0.8)
        a1.annotate(f"{i + 1}", (fd.frequency_hz, float(np.max(comp.level_measured))), color=c, fontsize=9,
                    ha="center")
    a1.set_xlabel("frequency [Hz]")
    a1.set_ylabel("PSD [dB re 1 (m/s2)^2/Hz]")
    a1.set_title(f"Spectra; log-spectral distance {comp.lsd_db:.2f} dB; numbered: findings by share")
    a1.legend(loc="upper right")
    a1.grid(alpha=0.3)
    angle = shaft_angle_from_speed(measured.size, fs, comp.shaft_hz)
    spr = 4096
    for x, lab, col in ((measured, "measured", "k"), (simulated, "model", "tab:blue")):
        o, amp = order_spectrum(x, fs, angle, samples_per_rev=spr, max_order=120)
        a2.semilogy(o, amp + 1e-12, color=col, lw=0.8, label=lab)
    for k in range(1, 7):
        a2.axvline(19 * k, color="0.7", ls=":", lw=0.8)
    a2.set_xlabel("pinion order (dotted: mesh harmonics)")
    a2.set_ylabel("amplitude [m/s2]")
    a2.legend(loc="upper right")
    a2.grid(alpha=0.3)
    if envelope:
        _plot_envelope(axes[2], envelope[0], comp, simulated, measured, fs)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def _plot_envelope(ax, fd: Finding, comp: Comparison, simulated, measured, fs) -> None:
    """The squared-envelope spectra of the band where the strongest envelope series was found,
    its harmonics dashed, the pinion's orders dotted."""
    from twin.signals.envelope import squared_envelope_spectrum
    top = 6.5 * fd.frequency_hz
    for x, lab, col in ((measured, "measured", "k"), (simulated, "model", "tab:blue")):
        f, amp = squared_envelope_spectrum(x, fs, fd.band_hz, fmax=top)
        ax.semilogy(f, amp + 1e-30, color=col, lw=0.8, label=lab)
    for h in range(1, 7):
        ax.axvline(h * fd.frequency_hz, color="tab:red", ls="--", lw=0.8)
    for k in range(1, int(top / comp.shaft_hz) + 1):
        ax.axvline(k * comp.shaft_hz, color="0.75", ls=":", lw=0.8)
    ax.set_xlim(0, top)
    ax.set_xlabel("envelope frequency [Hz] (dashed: the series found, "
                  f"{fd.order:.2f}x pinion; dotted: pinion orders)")
    ax.set_ylabel("squared envelope [(m/s2)^2]")
    ax.set_title(f"Envelope of {fd.band_hz[0]:.0f}-{fd.band_hz[1]:.0f} Hz: repeated impacts locked to neither shaft")
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)


def _html(comp: Comparison, scenario, rec, path) -> None:
    import html
    from pathlib import Path

    from twin._atomic import atomic_path
    rows = "".join(f"<tr><td>{i + 1}</td><td>{html.escape(f.kind)}</td><td style='text-align:left'>"
                   f"{html.escape(f.description)}</td><td>{f.size_db:+.1f}</td><td>{100 * f.share:.1f} %</td></tr>"
                   for i, f in enumerate(comp.findings))
    none = "" if comp.findings else "<p>No localised discrepancy above the thresholds: nothing appears to be missing.</p>"
    doc = f"""<!doctype html><html><head><meta charset="utf-8"><title>Compare: {html.escape(scenario.name)}</title>
<style>body{{font-family:sans-serif;max-width:62em;margin:2em auto}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:.25em .6em;text-align:right}}</style></head><body>
<h1>Model vs measurement: {html.escape(scenario.name)} / record {html.escape(rec.name)}</h1>
<p><b>Log-spectral distance: {comp.lsd_db:.2f} dB</b> (RMS of measured minus model PSD in dB over the band, both floored
at the measured median level). Paper objectives: f1 = {comp.f1:.4f} (waveform), f2 = {comp.f2:.4f} (spectrum).
RMS level: measured {comp.rms_measured:.3g}, model {comp.rms_model:.3g} m/s2. Pinion speed {comp.shaft_hz:.3f} Hz.</p>
<h2>Where the model fails</h2>{none}
<table><tr><th>#</th><th>kind</th><th>finding</th><th>size [dB]</th><th>share of error</th></tr>{rows}</table>
<img src="compare.png" style="max-width:100%"></body></html>"""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(doc)
