"""Is an effect's physical signature in the data? Read from the records alone, never from a model.

Each catalogue effect leaves a signature that a run-up separates from others:

* a **run-out** (``pinion_eccentricity``, ``gear_eccentricity``) modulates the mesh once per
  revolution of its shaft: first sidebands at that shaft's speed beside the mesh harmonics, in
  every steady record, and in the run-up as orders ``k z1 +- 1`` (pinion) or ``k z1 +- z1/z2``
  (gear, in pinion orders) that follow the speed. A ``local_tooth_damage`` of the pinion gives
  the same first pinion sidebands (and more), so it shares the pinion test;
* a **resonance** (``housing_mode``) is a band fixed in frequency across the run-up, excited by
  broadband content: a mode of the run-up analysis near the fitted frequency;
* a **drive ripple** (``motor_torque_ripple``) is a narrow line fixed in frequency across the
  run-up, not a hump: a fixed line of the run-up analysis at the fitted frequency.

With a pinion encoder (:mod:`twin.angular`) a run-out has a second signature: below the first
torsional mode the shafts turn to follow it, so the encoder's angular vibration carries a line at
that shaft's speed which the casing may hardly show (``bench/encoder_rigs.py``). It is present when
that line rose by :data:`ENCODER_RISE_DB` or more since the baseline record in every steady record
(with baseline records), or else stands :data:`LINE_DB` above the median of the angular spectrum
within +-3 shaft speeds (a weaker test: a healthy shaft has such a line too). Either signature,
the casing's or the encoder's, is enough.

The other effects (``load_torque_fluctuation``, ``backlash``, ``tooth_friction``,
``distributed_wear``) have no test here: they earn their place on the held-out record alone.
The run-up is read by :func:`twin.modes.survey_record` (orders, fixed lines and modes told apart
by :func:`twin.signals.runup.analyse_runup`); nothing is re-implemented here.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from twin.signals.spectral import padded_spectrum

#: A steady line is present when it stands this much above the median of the fine spectrum
#: around it [dB]: a Rayleigh-distributed noise bin exceeds its median by 10 dB with
#: probability exp(-10 ln 2) ~ 1e-3.
LINE_DB = 10.0
#: Mesh harmonics at which a first sideband must be present (steady) or locked (run-up): one
#: could be a coincidence, a run-out modulates them all.
MIN_HARMONICS = 2
#: Order tolerance [cycles/rev] of a run-up order to its expected value.
ORDER_TOL = 0.05
#: Relative tolerance of a fitted frequency to a fixed line or mode of the run-up (at least
#: two bins of the analysis).
FREQ_TOL = 0.02
#: Rise [dB] of the encoder's line at a shaft's speed since the baseline record that counts as a
#: run-out's signature (the compare's line threshold).
ENCODER_RISE_DB = 6.0


@dataclass(frozen=True)
class Survey:
    """What the records show about shafts, lines and resonances (model-free).

    ``runup``: name of the run-up analysed (None without one); ``lines`` fixed lines [Hz],
    ``modes`` (frequency [Hz], damping ratio) with confidence >= ``twin.modes.MIN_CONFIDENCE``,
    ``orders`` [pinion orders] locked to the shaft; ``resolution`` [Hz] of the run-up analysis;
    ``steady_sidebands``: per steady record, ``{"pinion": n, "gear": n}`` mesh harmonics with a
    first sideband at that shaft's speed.
    """

    runup: str | None
    lines: tuple[float, ...] = ()
    modes: tuple[tuple[float, float], ...] = ()
    orders: tuple[float, ...] = ()
    resolution: float = 0.0
    steady_sidebands: Mapping[str, Mapping[str, int]] = field(default_factory=dict)
    z1: int = 19
    z2: int = 71
    # per steady record with an encoder, {"pinion": dB, "gear": dB}: its angular-vibration line
    # at that shaft's speed, risen since the baseline record (encoder_basis "baseline") or above
    # the local median of its spectrum ("median")
    encoder_lines: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    encoder_basis: str = ""


def steady_sidebands(x: np.ndarray, fs: float, shaft_hz: float, z1: int, z2: int, n_harmonics: int = 10
                     ) -> dict[str, int]:
    """Mesh harmonics (of the first ``n_harmonics`` below 0.4 fs) with a first sideband at the
    pinion / gear speed standing ``LINE_DB`` above the median spectrum within +-3 shaft speeds."""
    f, amp = padded_spectrum(np.asarray(x, float), fs)
    df = f[1] - f[0]
    gmf = z1 * shaft_hz
    out = {}
    for shaft, spacing in (("pinion", shaft_hz), ("gear", shaft_hz * z1 / z2)):
        count = 0
        tol = max(2 * df, 0.3 * fs / x.size)
        for k in range(1, n_harmonics + 1):
            fk = k * gmf
            if fk + 3 * shaft_hz > 0.4 * fs:
                break
            around = (f >= fk - 3 * shaft_hz) & (f <= fk + 3 * shaft_hz)
            floor = float(np.median(amp[around]))
            side = [float(np.max(amp[(f >= fs_ - tol) & (f <= fs_ + tol)])) for fs_ in (fk - spacing, fk + spacing)]
            if floor > 0 and max(side) >= floor * 10 ** (LINE_DB / 20):
                count += 1
        out[shaft] = count
    return out


def encoder_line(angle: np.ndarray, fs: float, shaft_hz: float, spacing_hz: float) -> tuple[float, float]:
    """(amplitude [rad], the median of the angular spectrum within +-3 pinion speeds [rad]) of the
    encoder's angular-vibration line at ``spacing_hz`` (a shaft's speed) [Hz]."""
    from twin.angular import angular_vibration
    x = angular_vibration(angle, fs)
    f, amp = padded_spectrum(x, fs)
    tol = max(2 * (f[1] - f[0]), 0.3 * fs / x.size)
    line = float(np.max(amp[(f >= spacing_hz - tol) & (f <= spacing_hz + tol)]))
    around = (f >= max(spacing_hz - 3 * shaft_hz, 0.5)) & (f <= spacing_hz + 3 * shaft_hz)
    return line, float(np.median(amp[around]))


def survey_records(fit: Sequence, runup, channel: str, z1: int, z2: int, shaft_hz: Mapping[str, float], *,
                   encoder: bool = False, baseline: Mapping | None = None) -> Survey:
    """The :class:`Survey` of the steady records ``fit`` (their measured pinion speeds in
    ``shaft_hz`` by name) and of a run-up record (or None). With ``encoder`` the steady records'
    encoder lines are read too, against ``baseline`` (record name -> its baseline record) when
    given."""
    from twin.modes import MIN_CONFIDENCE, survey_record
    steady = {r.name: steady_sidebands(r.signal, r.sample_rate, shaft_hz[r.name], z1, z2) for r in fit}
    lines: dict[str, dict[str, float]] = {}
    basis = ""
    if encoder:
        basis = "baseline" if baseline else "median"
        for r in fit:
            s0 = shaft_hz[r.name]
            n = int(round(min(r.angle.size, r.signal.size)))
            b = baseline.get(r.name) if baseline else None
            s_b = float(np.median(b.shaft_hz)) if b is not None and b.shaft_hz is not None else s0
            out = {}
            for name, ratio in (("pinion", 1.0), ("gear", z1 / z2)):
                amp, med = encoder_line(r.angle[-n:], r.sample_rate, s0, s0 * ratio)
                if b is not None:
                    amp_b, _ = encoder_line(b.angle[-n:], b.sample_rate, s_b, s_b * ratio)
                    out[name] = float(20 * np.log10(max(amp, 1e-30) / max(amp_b, 1e-30)))
                else:
                    out[name] = float(20 * np.log10(max(amp, 1e-30) / max(med, 1e-30)))
            lines[r.name] = out
    if runup is None or runup.raw is None:
        return Survey(None, steady_sidebands=steady, z1=z1, z2=z2, encoder_lines=lines, encoder_basis=basis)
    s = survey_record(runup.raw, channels=[channel])
    modes = tuple((m.frequency, m.damping) for m in s.modes if m.confidence >= MIN_CONFIDENCE)
    return Survey(runup.name, tuple(ln.frequency for ln in s.lines), modes, tuple(o.order for o in s.orders),
                  float(s.resolution), steady, z1, z2, lines, basis)


def _locked_sidebands(orders: Sequence[float], z1: int, spacing: float, max_order: float) -> int:
    """Mesh harmonics k z1 with an order at k z1 +- spacing (within ORDER_TOL)."""
    o = np.asarray(orders, float)
    count = 0
    for k in range(1, int(max_order // z1) + 2):
        if o.size and any(np.min(np.abs(o - (k * z1 + s * spacing))) <= ORDER_TOL for s in (-1, 1)):
            count += 1
    return count


def signature(effect_id: str, fitted: Mapping[str, float], survey: Survey | None) -> tuple[bool | None, str]:
    """(present?, what was looked for and found). None: this effect has no signature test, or
    the records cannot show it (a run-up is needed and there is none)."""
    if survey is None:
        return None, "no signature test with one record"
    z1, z2 = survey.z1, survey.z2
    if effect_id in ("pinion_eccentricity", "gear_eccentricity", "local_tooth_damage"):
        shaft = "gear" if effect_id == "gear_eccentricity" else "pinion"
        spacing = z1 / z2 if shaft == "gear" else 1.0
        steady = {k: v.get(shaft, 0) for k, v in survey.steady_sidebands.items()}
        ok_steady = bool(steady) and all(v >= MIN_HARMONICS for v in steady.values())
        text = "first " + shaft + " sidebands at " + ", ".join(f"{v} mesh harmonics of {k}" for k, v in steady.items())
        ok = ok_steady
        if survey.runup is not None:
            locked = _locked_sidebands(survey.orders, z1, spacing, max(survey.orders, default=0.0))
            text += f"; {locked} locked to the {shaft} in run-up {survey.runup}"
            ok = ok_steady and locked >= MIN_HARMONICS
        if survey.encoder_lines and effect_id != "local_tooth_damage":
            rise = {k: v[shaft] for k, v in survey.encoder_lines.items()}
            need = ENCODER_RISE_DB if survey.encoder_basis == "baseline" else LINE_DB
            seen = all(v >= need for v in rise.values())
            text += ("; the encoder's line at the " + shaft + " speed "
                     + ", ".join(f"{v:+.1f} dB" for v in rise.values())
                     + (" since the baseline" if survey.encoder_basis == "baseline" else " above its surroundings")
                     + (" (present)" if seen else ""))
            ok = ok or seen
        return ok, text
    if survey.runup is None:
        return None, "no run-up to tell fixed from shaft-locked content"
    if effect_id == "motor_torque_ripple":
        fr = float(fitted.get("motor_torque_ripple.frequency", np.nan))
        tol = max(FREQ_TOL * fr, 2 * survey.resolution)
        near = [ln for ln in survey.lines if abs(ln - fr) <= tol]
        return bool(near), (f"fixed line at {near[0]:.1f} Hz in run-up {survey.runup}" if near else
                            f"no fixed line within {tol:.1f} Hz of {fr:.1f} Hz in run-up {survey.runup}")
    if effect_id == "housing_mode":
        fr = float(fitted.get("housing_mode.frequency", np.nan))
        tol = max(FREQ_TOL * fr, 2 * survey.resolution)
        near = [m for m in survey.modes if abs(m[0] - fr) <= tol]
        return bool(near), (f"broadband-excited band fixed at {near[0][0]:.0f} Hz in run-up {survey.runup}" if near
                            else f"no resonance within {tol:.0f} Hz of {fr:.0f} Hz in run-up {survey.runup}")
    return None, "no signature test for this effect"
