"""The measured modes a ``calibration:`` block asks for: read from records by ``twin modes``
(``modes_from``, with their shapes at the sensors and, with ``struck_shafts``, the shaft each lives
on), or typed (``natural_frequencies``), less the foundation's modes (``foundation_modes``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from twin.calibration.pairing import SHAFTS
from twin.errors import ScenarioError


def _struck_shafts(spec: dict, names, source: str) -> dict[str, str]:
    """``calibration.struck_shafts`` checked against the records the modes are read from: every record
    it names is one of them, and each shaft has one (a ScenarioError naming the value otherwise)."""
    struck = dict(spec.get("struck_shafts") or {})
    if not struck:
        return struck
    for name in struck:
        if name not in names:
            raise ScenarioError([(source, f"calibration.struck_shafts.{name}",
                                  f"{name!r} is not one of the records the modes are read from (modes_from: "
                                  f"{', '.join(names)})")])
    for shaft in SHAFTS:
        if shaft not in struck.values():
            raise ScenarioError([(source, "calibration.struck_shafts", f"no record struck on the {shaft} shaft: a "
                                  "mode's shaft is read from blows on both")])
    return struck


def measured_modes(spec: dict, mset, source: str, out_dir: Path, *, with_damping: bool = False):
    """(frequencies [Hz], relative sd, description) of the measured modes the block asks for;
    with ``with_damping`` also their damping ratios (NaN where unknown), confidences, the
    channels they were read from (empty when typed) and their shapes at those channels
    (:class:`twin.calibration.pairing.MeasuredShapes`, None when typed or read from one channel)."""
    from twin.calibration.pairing import MeasuredShapes
    from twin.modes import MIN_CONFIDENCE, survey_records, write_survey_json
    from twin.signals import remove_foundation_modes

    if isinstance(spec.get("foundation_modes"), str):      # refused before any survey is run or written
        hammer_record(spec["foundation_modes"], mset, source)
    if spec.get("modes_from"):
        names = modes_records(spec)
        for name in names:
            if name not in mset.names:
                raise ScenarioError([(source, "calibration.modes_from",
                                      f"no record {name!r} in the measurements (they have {', '.join(mset.names)})")])
        struck = _struck_shafts(spec, names, source)
        survey = survey_records(mset, names, lscf=spec.get("lscf"))
        label = f"record {names[0]!r}" if len(names) == 1 else "records " + ", ".join(map(repr, names))
        write_survey_json(survey, out_dir / "modes.json", record=names[0] if len(names) == 1 else names)
        threshold = float(spec.get("min_confidence", MIN_CONFIDENCE))
        used = [m for m in survey.modes if m.confidence >= threshold]
        if not used:
            raise ScenarioError([(source, "calibration.modes_from", f"{label} show{'s' * (len(names) == 1)} no mode with "
                                  f"confidence >= {threshold:g} (see {out_dir / 'modes.json'})")])
        freqs = np.array([m.frequency for m in used])
        rel = np.array([m.evidence.get("frequency_sd_hz", 0.0) / m.frequency for m in used])
        damping = np.array([m.damping for m in used])
        confidence = np.array([m.confidence for m in used])
        channels = tuple(survey.channels)
        shapes = MeasuredShapes.from_evidence([m.evidence for m in used], struck)
        what = (f"{freqs.size} modes read from {label} ({survey.method}, confidence >= {threshold:g}; "
                f"{len(survey.lines)} fixed lines and {len(survey.orders)} orders set aside)")
    elif spec.get("natural_frequencies"):
        freqs = np.asarray(spec["natural_frequencies"], float)
        rel = np.zeros(freqs.size)
        damping = np.full(freqs.size, np.nan)
        confidence = np.ones(freqs.size)
        channels = ()
        shapes = None
        what = "typed in the scenario"
    else:
        raise ScenarioError([(source, "calibration.natural_frequencies",
                              "give the measured natural frequencies, or modes_from: RECORD to read them from a "
                              "run-up or hammer record")])
    foundation = spec.get("foundation_modes")
    if isinstance(foundation, str):
        foundation = foundation_modes_of(foundation, spec, mset, source, out_dir)
    if foundation is not None and len(foundation):
        kept, removed = remove_foundation_modes(freqs, np.asarray(foundation, float))
        keep = np.isin(freqs, kept)
        freqs, rel, damping, confidence = freqs[keep], rel[keep], damping[keep], confidence[keep]
        if shapes is not None:
            shapes = shapes.subset(keep)
        print(f"removed foundation modes {[round(float(f), 1) for f in removed]} Hz from the measured list")
    if with_damping:
        return freqs, rel, what, damping, confidence, channels, shapes
    return freqs, rel, what


def modes_records(spec: dict) -> list[str]:
    """The record names of a calibration block's ``modes_from`` (one name or a list), as a list."""
    names = spec.get("modes_from") or []
    return [names] if isinstance(names, str) else list(names)


def hammer_record(name: str, mset, source: str, where: str = "calibration.foundation_modes",
                  hint: str = ": give the foundation's modes from an impact test, or in Hz"):
    """The record ``name`` of ``mset`` if it is a hammer test (a force channel in N); ScenarioError
    at ``where`` naming it otherwise (``hint`` ends the message)."""
    if name not in mset.names:
        raise ScenarioError([(source, where, f"no record {name!r} in the measurements "
                                             f"(they have {', '.join(mset.names)})")])
    record = mset[name]
    if not any(record.units[c] == "N" for c in record.channel_names):
        raise ScenarioError([(source, where, f"record {name!r} is not a hammer test (it has no force channel "
                                             f"in N){hint}")])
    return record


def foundation_modes_of(name: str, spec: dict, mset, source: str, out_dir: Path) -> np.ndarray:
    """(q,) natural frequencies [Hz] of the foundation read from the hammer-test record ``name``
    (a force channel in N, see :func:`twin.modes.survey_record`), the paper's impact test on the
    casing root: the modes the calibration must not fit with the gearbox.  Modes below the
    block's ``min_confidence`` are left in; the survey is written to ``foundation_modes.json``."""
    from twin.modes import MIN_CONFIDENCE, survey_record, write_survey_json

    survey = survey_record(hammer_record(name, mset, source))
    write_survey_json(survey, out_dir / "foundation_modes.json", record=name)
    threshold = float(spec.get("min_confidence", MIN_CONFIDENCE))
    return np.array([m.frequency for m in survey.modes if m.confidence >= threshold])
