"""``twin modes``: natural frequencies of a measured record, with orders and fixed lines set apart.

A run-up (any record with a tachometer, an encoder or a speed channel) goes through
:func:`twin.signals.runup.analyse_runup`; a hammer test (a force channel in N) through
:func:`twin.signals.impact.analyse_impacts`. With several vibration channels each is analysed
and the results are merged: a mode seen by any sensor is a mode of the structure, kept with the
estimate of the sensor that saw it most clearly. With ``fdd`` the channels' cross-spectral matrix
adds the modes no single channel separates (a close mode of another shape under a hump).
With ``lscf`` (opt-in) the hammer tests' FRFs, every struck point and sensor at once, are fitted by
the poly-reference LSCF method (:mod:`twin.signals.lscf`), which adds the modes whose humps overlap.

    survey = survey_file("rig.h5", record="runup")
    survey.frequencies(min_confidence=0.5)      # Hz, ascending
    write_survey_json(survey, "modes.json"); plot_survey(survey, "modes.png")
"""
from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from twin.errors import MeasurementError
from twin.signals.survey import Line, ModalSurvey, Mode, Order

VIBRATION_UNITS = ("m/s2", "m/s", "m")
#: Default confidence a mode needs to be used for calibration.
MIN_CONFIDENCE = 0.3
#: Whether a run-up with several vibration channels is also read through their cross-spectral
#: matrix (frequency-domain decomposition, :mod:`twin.signals.fdd`) by default.
FDD = True
#: Whether the hammer tests among the records are also fitted together by the poly-reference LSCF
#: method (:mod:`twin.signals.lscf`) by default. Off: on the rigs' records (seeds 91-95) it raised
#: the pedestal rig's calibrated matches and left one more beam gearbox with a parameter on a bound
#: (docs/calibration.md); ``lscf=True``, ``twin modes --lscf`` or ``calibration.lscf: true`` turn it on.
LSCF = False


def shaft_angle(record) -> np.ndarray | None:
    """Unwrapped reference-shaft angle [rad] per sample, or None when the record has no speed.

    From the tachometer (pulse train or encoder angle), else from a speed channel (unit ``Hz``
    or ``rad/s``), else None. A pulse tachometer leaves NaN before its first and after its last
    edge.
    """
    from twin.signals import shaft_angle_from_encoder, shaft_angle_from_speed, shaft_angle_from_tacho

    fs = record.sample_rate
    if record.tachometer is not None:
        x = record[record.tachometer]
        if record.tachometer_kind == "angle":
            return smooth_counts(shaft_angle_from_encoder(x))
        return shaft_angle_from_tacho(x, fs, record.pulses_per_rev or 1)
    for name in record.channel_names:
        unit = record.units[name]
        if unit in ("Hz", "rad/s"):
            speed = np.asarray(record[name], float) / (2 * np.pi if unit == "rad/s" else 1.0)
            return shaft_angle_from_speed(speed.size, fs, speed)
    return None


def smooth_counts(angle: np.ndarray) -> np.ndarray:
    """A quantised encoder angle [rad] made smooth and strictly increasing.

    A 512-line encoder read at 50 kHz holds each count for many samples at low speed. Each
    change of count is taken to happen half a sample before it is seen, and the angle between
    changes follows a monotone cubic (PCHIP) through them; before the first and after the last
    change it is extrapolated at the speed of the nearest interval. An angle that already
    increases at every sample is returned unchanged.
    """
    from scipy.interpolate import PchipInterpolator

    angle = np.asarray(angle, float)
    step = np.diff(angle)
    if np.all(step > 0):
        return angle
    change = np.flatnonzero(step != 0) + 1
    if change.size < 3:
        return angle
    t = change - 0.5
    a = angle[change]
    keep = np.concatenate([[True], np.diff(a) > 0])
    t, a = t[keep], a[keep]
    n = np.arange(angle.size, dtype=float)
    out = PchipInterpolator(t, a, extrapolate=False)(n)
    first = (a[1] - a[0]) / (t[1] - t[0])
    last = (a[-1] - a[-2]) / (t[-1] - t[-2])
    out[n < t[0]] = a[0] + first * (n[n < t[0]] - t[0])
    out[n > t[-1]] = a[-1] + last * (n[n > t[-1]] - t[-1])
    return out


def _force_channel(record) -> str | None:
    forces = [n for n in record.channel_names if record.units[n] == "N"]
    return forces[0] if forces else None


def survey_record(record, *, channels=None, fmin: float | None = None, fmax: float | None = None,
                  resolution: float | None = None, fdd: bool | None = None) -> ModalSurvey:
    """Modes, fixed lines and orders of one record (see the module docstring).

    ``fdd``: with two or more vibration channels of a run-up, also read the channels' cross-spectral
    matrix for modes the per-channel search misses (:mod:`twin.signals.fdd`); default ``FDD``.
    """
    from twin.signals.impact import analyse_impacts
    from twin.signals.runup import analyse_runup

    vib = list(channels) if channels else [n for n in record.channel_names if record.units[n] in VIBRATION_UNITS
                                           and n != record.tachometer]
    missing = [c for c in vib if c not in record]
    if missing:
        raise MeasurementError(record.source or "<memory>", record.name,
                               f"no channel {missing[0]!r} (it has {', '.join(record.channel_names)})")
    if not vib:
        raise MeasurementError(record.source or "<memory>", record.name,
                               "no vibration channel (unit m/s2, m/s or m) to read modes from")
    force = _force_channel(record)
    surveys = []
    if force is not None:
        for c in vib:
            surveys.append(replace(analyse_impacts(record[force], record[c], record.sample_rate, fmin=fmin, fmax=fmax),
                                   channels=(c,)))
    else:
        angle = shaft_angle(record)
        keep = slice(None)
        if angle is not None and not np.all(np.isfinite(angle)):
            ok = np.flatnonzero(np.isfinite(angle))
            keep = slice(int(ok[0]), int(ok[-1]) + 1)
            angle = angle[keep]
        if angle is None and record.nominal_speed is not None:
            from twin.signals import shaft_angle_from_speed
            angle = shaft_angle_from_speed(record.n_samples, record.sample_rate, float(record.nominal_speed))
        for c in vib:
            surveys.append(replace(analyse_runup(np.asarray(record[c])[keep], record.sample_rate, angle, fmin=fmin,
                                                 fmax=fmax, resolution=resolution), channels=(c,)))
        if len(vib) > 1:
            xs = [np.asarray(record[c], float)[keep] for c in vib]
            merged = merge_surveys(surveys)
            if FDD if fdd is None else fdd:
                merged = with_fdd(merged, xs, record.sample_rate, angle)
            return with_shapes(merged, xs, vib, record.sample_rate)
    return merge_surveys(surveys)


def with_fdd(survey: ModalSurvey, xs, fs: float, angle) -> ModalSurvey:
    """The survey with the modes the channels' cross-spectral matrix adds (:mod:`twin.signals.fdd`)."""
    from twin.signals.fdd import fdd_modes

    modes = fdd_modes(xs, fs, angle, survey)
    return replace(survey, modes=tuple(replace(m, evidence={**m.evidence, "channels": list(survey.channels)})
                                       if "found_by" in m.evidence else m for m in modes))


def with_shapes(survey: ModalSurvey, xs, names, fs: float) -> ModalSurvey:
    """The survey with each mode's shape at the channels (``evidence["shape"]``, see
    :mod:`twin.signals.shapes`): cross-spectra over the run-up slices in the bins of its hump."""
    from twin.signals.shapes import channel_shapes

    if not survey.modes:
        return survey
    freqs = np.array([m.frequency for m in survey.modes])
    damping = np.array([m.damping for m in survey.modes])
    half = np.where(np.isfinite(damping), freqs * np.nan_to_num(damping), 0.0)
    nperseg = int(round(fs / survey.resolution))
    shapes = channel_shapes(xs, list(names), fs, freqs, half, nperseg=nperseg,
                            exclude_hz=[ln.frequency for ln in survey.lines])
    return replace(survey, modes=tuple(replace(m, evidence={**m.evidence, "shape": s.to_dict()})
                                       for m, s in zip(survey.modes, shapes)))


def _same_mode(f_seen: float, f: float, resolution: float) -> bool:
    """Whether a mode at ``f_seen`` [Hz] is the one at ``f`` [Hz] read by a survey of ``resolution``
    [Hz]: within 1 % or two bins."""
    return abs(f_seen - f) <= max(0.01 * f, 2 * resolution)


def merge_surveys(surveys) -> ModalSurvey:
    """One survey from several sensors' surveys of the same record (modes within 1 % merged)."""
    if len(surveys) == 1:
        return surveys[0]
    modes: list[Mode] = []
    for s in surveys:
        for m in s.modes:
            m = replace(m, evidence={**m.evidence, "channels": list(s.channels)})
            same = [i for i, o in enumerate(modes) if _same_mode(o.frequency, m.frequency, s.resolution)]
            if not same:
                modes.append(m)
                continue
            i = same[0]
            seen = sorted(set(modes[i].evidence["channels"]) | set(s.channels))
            best = m if m.confidence > modes[i].confidence else modes[i]
            modes[i] = replace(best, evidence={**best.evidence, "channels": seen})
    lines: list[Line] = []
    orders: list[Order] = []
    for s in surveys:
        lines += [ln for ln in s.lines if all(abs(ln.frequency - o.frequency) > 2 * s.resolution for o in lines)]
        orders += [o for o in s.orders if all(abs(o.order - p.order) > 0.05 for p in orders)]
    first = surveys[0]
    notes = tuple(dict.fromkeys(n for s in surveys for n in s.notes))
    return replace(first, modes=tuple(sorted(modes, key=lambda m: m.frequency)),
                   lines=tuple(sorted(lines, key=lambda ln: ln.frequency)),
                   orders=tuple(sorted(orders, key=lambda o: o.order)), notes=notes,
                   channels=tuple(c for s in surveys for c in s.channels))


def survey_records(mset, names, **kwargs) -> ModalSurvey:
    """One survey of the structure from several records of ``mset`` (for example a run-up and a
    hammer test per struck point): each record surveyed (:func:`survey_record`), then merged like
    several sensors (a mode seen in any record is a mode of the structure, kept with the estimate of
    the record that saw it most clearly, modes within 1 % merged). Each mode's evidence names the
    records that saw it (``records``). ``names``: one record name or a sequence of them; a name
    ``mset`` lacks raises :class:`MeasurementError` naming it."""
    names = [names] if isinstance(names, str) else list(names)
    if not names:
        raise MeasurementError(mset.source or "<memory>", "", "no record named to read modes from")
    missing = [n for n in names if n not in mset.names]
    if missing:
        raise MeasurementError(mset.source or "<memory>", missing[0],
                               f"no such record (the file has {', '.join(mset.names)})")
    lscf = kwargs.pop("lscf", None)
    lscf = LSCF if lscf is None else bool(lscf)
    hammer = [mset[n] for n in names if _force_channel(mset[n]) is not None]
    if len(names) == 1:
        survey = survey_record(mset[names[0]], **kwargs)
        return with_lscf(survey, hammer, kwargs.get("channels"), kwargs.get("fmin"), kwargs.get("fmax")) \
            if lscf and hammer else survey
    surveys = [survey_record(mset[n], **kwargs) for n in names]
    merged = merge_surveys(surveys)
    # which records saw each merged mode: every record with a mode within the merge's reach
    modes = []
    for m in merged.modes:
        seen = [n for n, s in zip(names, surveys) if any(_same_mode(o.frequency, m.frequency, s.resolution)
                                                          for o in s.modes)]
        modes.append(replace(m, evidence={**m.evidence, "records": seen}))
    method = "+".join(dict.fromkeys(s.method for s in surveys))
    merged = replace(merged, modes=tuple(modes), method=method, channels=tuple(dict.fromkeys(merged.channels)))
    if not (hammer and (lscf or len(hammer) > 1)):
        return merged
    matrix = _hammer_matrix(hammer, kwargs.get("channels"))      # read once for both
    if lscf:
        merged = _with_lscf(merged, hammer, matrix, kwargs.get("fmin"), kwargs.get("fmax"))
    return _with_struck_levels(merged, hammer, matrix)


def _hammer_matrix(records, channels=None):
    """``(f, H, coherence, f_tip, channels)`` of the hammer ``records`` together
    (:func:`twin.signals.impact.hammer_frf_matrix`: every record one struck point, every vibration
    channel they share one sensor), or a string saying why they cannot be read together."""
    from twin.signals._checks import SignalError
    from twin.signals.impact import hammer_frf_matrix

    vib = [c for c in (channels or records[0].channel_names)
           if c in records[0] and records[0].units[c] in VIBRATION_UNITS and c != records[0].tachometer]
    common = [c for c in vib if all(c in r for r in records)]
    fs = {r.sample_rate for r in records}
    if not common or len(fs) != 1:
        return "no vibration channel common to all" if not common else "their sample rates differ"
    try:
        f, H, coh, top = hammer_frf_matrix([(r[_force_channel(r)], [r[c] for c in common]) for r in records],
                                           fs.pop())
    except SignalError as exc:
        return str(exc)
    return f, H, coh, top, common


def with_struck_levels(survey: ModalSurvey, records, channels=None) -> ModalSurvey:
    """The survey with each mode's response to each struck point (``evidence["struck_db"]``).

    Two or more hammer ``records`` struck at different points: for each mode in their band, the
    r.m.s. FRF magnitude over the shared sensors and the bins of its hump (half-power half-width,
    at least one bin each side) per record, in dB re the record that excites it most. Where a mode
    is struck tells whose mode it is (a shaft's mode answers a blow at that shaft's end), which
    the sensors on the casing alone may not (docs/calibration.md). Frequencies are not changed;
    records that cannot be read together leave the survey as it is, with a note."""
    return _with_struck_levels(survey, records, _hammer_matrix(records, channels) if len(records) > 1 else "")


def _with_struck_levels(survey: ModalSurvey, records, matrix) -> ModalSurvey:
    if len(records) < 2:
        return survey
    if isinstance(matrix, str):
        return replace(survey, notes=survey.notes + (f"struck-point levels not read: {matrix}",))
    f, H, _, top, _ = matrix
    df = float(f[1] - f[0])
    power = np.mean(np.abs(H) ** 2, axis=1)                                      # (n_f, n_records)
    modes = []
    for m in survey.modes:
        if not 4 * df <= m.frequency <= top:
            modes.append(m)
            continue
        half = max(df, m.frequency * (m.damping if np.isfinite(m.damping) else 0.0))
        band = (f >= m.frequency - half) & (f <= m.frequency + half)
        level = 10 * np.log10(np.maximum(power[band].mean(axis=0), np.finfo(float).tiny))
        modes.append(replace(m, evidence={**m.evidence, "struck_db": {r.name: round(float(v - level.max()), 1)
                                                                      for r, v in zip(records, level)}}))
    return replace(survey, modes=tuple(modes))


def with_lscf(survey: ModalSurvey, records, channels=None, fmin: float | None = None,
              fmax: float | None = None) -> ModalSurvey:
    """The survey with the modes a poly-reference LSCF fit of the hammer ``records`` adds or splits.

    Every hammer record is one reference (its force channel), every vibration channel they share
    one output (:func:`twin.signals.impact.hammer_frf_matrix`). A survey mode with one stable pole
    within the merge's reach (:func:`_same_mode`) stays as it is; one with two or more is a hump
    that held close modes, and the poles replace it (evidence ``replaces_hz``: the parametric fit
    resolves poles closer than the FRF's bins, peak picking cannot). Any other pole is a new mode with
    confidence = its stability (the share of the diagram's orders it was stable at; the coherence
    already weights the fit, and a running gearbox's own vibration keeps it low at modes the fit
    finds plainly) and evidence ``found_by: "lscf"``.
    The band: ``fmin`` (default four bins) to ``fmax`` (default the tips' band, at most 0.4 fs and
    10 kHz). A set of records whose FRFs cannot be formed together (different sample rates, no
    common channel) is fitted no further: the survey is returned with a note saying why.
    """
    return _with_lscf(survey, records, _hammer_matrix(records, channels), fmin, fmax)


def _with_lscf(survey: ModalSurvey, records, matrix, fmin: float | None, fmax: float | None) -> ModalSurvey:
    from twin.signals.impact import local_floor
    from twin.signals.lscf import lscf_modes

    if isinstance(matrix, str):
        return replace(survey, notes=survey.notes + (f"hammer tests not fitted together by LSCF: {matrix}",))
    f, H, coh, top, common = matrix
    fs = records[0].sample_rate
    df = float(f[1] - f[0])
    lo = float(4 * df if fmin is None else fmin)
    hi = float(min(0.4 * fs, 10_000.0, top) if fmax is None else fmax)
    if not lo < hi:
        return survey
    level = 20 * np.log10(np.maximum(np.sqrt(np.mean(np.abs(H) ** 2, axis=(1, 2))), np.finfo(float).tiny))
    mean_coh = np.nanmean(coh, axis=(1, 2))
    poles = lscf_modes(f, H, coh, lo, hi)

    def as_mode(p, **extra) -> Mode:
        k = int(np.argmin(np.abs(f - p.frequency)))
        c = float(np.clip(mean_coh[k], 0.0, 1.0))
        return Mode(p.frequency, p.damping, p.stability, float(level[k] - local_floor(f, level, p.frequency)),
                    {"reason": "stable pole of a poly-reference LSCF fit of the hammer FRFs",
                     "found_by": "lscf", "stability": round(p.stability, 3), "coherence": round(c, 3),
                     "resolution_hz": round(df, 4), "frequency_sd_hz": round(max(p.frequency_sd, df / 4), 4),
                     "records": [r.name for r in records], "channels": common, **extra})

    modes, used, split = [], set(), 0
    for m in survey.modes:
        near = [i for i, p in enumerate(poles) if _same_mode(m.frequency, p.frequency, df)]
        if len(near) >= 2:      # one hump read as one mode holds several poles: they replace it
            modes += [as_mode(poles[i], replaces_hz=round(m.frequency, 2)) for i in near if i not in used]
            used.update(near)
            split += 1
        else:
            modes.append(m)
            used.update(near)
    added = [as_mode(p) for i, p in enumerate(poles) if i not in used]
    note = (f"LSCF fit of {len(records)} hammer test(s) x {len(common)} channel(s), {lo:.0f}-{hi:.0f} Hz: "
            f"{len(added)} mode(s) added, {split} hump(s) split into close modes")
    return replace(survey, modes=tuple(sorted(modes + added, key=lambda m: m.frequency)), notes=survey.notes + (note,))


def survey_file(path, record=None, **kwargs) -> ModalSurvey:
    """Survey of record ``record`` (default: the first) of a measurement file; several record
    names (a sequence) are surveyed together (:func:`survey_records`)."""
    from twin.measurements import load_measurements

    mset = load_measurements(path)
    return survey_records(mset, mset.names[0] if record is None else record, **kwargs)


def write_survey_json(survey: ModalSurvey, path, **extra) -> Path:
    """The survey as JSON (modes, lines, orders, notes), written atomically."""
    from twin._atomic import atomic_path

    with atomic_path(path) as tmp:
        Path(tmp).write_text(json.dumps({**extra, **survey.to_dict()}, indent=2))
    return Path(path)


def shape_text(shape: dict) -> str:
    """A mode's shape at the channels in a few words: each channel re the reference."""
    ref = shape["reference"]
    parts = [f"{c} {v['level_db']:+.1f} dB {v['phase_deg']:+.0f} deg (coherence {v['coherence']:.2f})"
             for c, v in shape["channels"].items() if c != ref]
    return f"shape re {ref}: " + ", ".join(parts)


def survey_table(survey: ModalSurvey, min_confidence: float = MIN_CONFIDENCE) -> str:
    """The survey as text: modes, lines, orders and notes."""
    rows = [f"{survey.method} survey, band {survey.band[0]:g}-{survey.band[1]:g} Hz, "
            f"resolution {survey.resolution:.3g} Hz, channels {', '.join(survey.channels) or '-'}",
            "", "structural modes (confidence >= %.2f used for calibration)" % min_confidence,
            "   freq [Hz]  damping  confidence  evidence"]
    for m in survey.modes:
        mark = " " if m.confidence >= min_confidence else "-"
        ev = m.evidence
        crossing = ev.get("orders_crossing") or []
        bits = [ev.get("reason", "")]
        if crossing:
            bits.append(f"crossed by orders {', '.join(f'{o:g}' for o in crossing[:4])}"
                        + (" ..." if len(crossing) > 4 else ""))
        if ev.get("line_on_top_hz"):
            bits.append(f"line on top at {ev['line_on_top_hz']} Hz")
        if ev.get("shape"):
            bits.append(shape_text(ev["shape"]))
        if ev.get("records"):
            bits.append(f"seen in {', '.join(ev['records'])}")
        if ev.get("struck_db"):
            bits.append("struck: " + ", ".join(f"{r} {v:+.1f} dB" for r, v in ev["struck_db"].items()))
        damping = f"{m.damping:7.4f}" if np.isfinite(m.damping) else "    n/a"
        rows.append(f"{mark}{m.frequency:10.2f}  {damping}  {m.confidence:10.2f}  {'; '.join(b for b in bits if b)}")
    if not survey.modes:
        rows.append("   (none)")
    if survey.lines:
        rows += ["", "fixed non-synchronous lines (not modes)", "   freq [Hz]  level [dB]  evidence"]
        rows += [f" {ln.frequency:10.2f}  {ln.level_db:10.1f}  {ln.evidence.get('reason', '')}" for ln in survey.lines]
    if survey.orders:
        rows += ["", "speed-locked orders (not modes): " + ", ".join(f"{o.order:g}" for o in survey.orders)]
    rows += [f"note: {n}" for n in survey.notes]
    return "\n".join(rows)
