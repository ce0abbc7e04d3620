"""The calibrated twin as a scenario file that every later step takes.

``twin calibrate`` writes ``OUT/calibrated.yaml``: the input scenario (all its blocks: operating
point, degradation, archive, ...) with the calibrated parameter set in place of its own
parameters. Paths stay valid wherever the file is read from:

* files written next to it (``calibrated.json``) are referenced relative to it, so the output
  directory can be moved or copied as a whole;
* files outside it (an ``.fmu``, an operating-profile CSV table) are made absolute;
* a Modelica model name (``GearTwin.Gearbox21``) is kept: it is built from the repository's
  ``modelica/`` wherever the scenario is.
"""
from __future__ import annotations

import copy
import datetime as _dt
from collections.abc import Mapping
from pathlib import Path

import yaml


def _absolute(value: str, base: Path | None) -> str:
    p = Path(value)
    if p.is_absolute() or base is None:
        return str(p)
    return str((base / p).resolve())


def calibrated_scenario_dict(scenario, parameter_file: str, *, note: str = "",
                             structural: Mapping[str, float] | None = None) -> dict:
    """The scenario's raw dict with paths made location-independent and the calibrated set in place.

    ``parameter_file`` is the parameter set's path relative to where the new scenario will be
    written; it holds every parameter (the scenario's own and the calibrated ones). ``structural``
    replaces the scenario's build options (a measured path's ``n_path_sections``).
    """
    data = copy.deepcopy(dict(scenario.raw))
    if structural:
        data["structural"] = dict(structural)
    base = scenario.source.parent if scenario.source is not None else None
    if str(data.get("fmu", "")).endswith(".fmu"):
        data["fmu"] = _absolute(data["fmu"], base)
    data.pop("parameters", None)
    data["parameter_files"] = [parameter_file]
    op = data.get("operating", {})
    for key, spec in list(op.items()) + list(op.get("inputs", {}).items()):
        if isinstance(spec, Mapping) and "table" in spec:
            spec["table"]["file"] = _absolute(spec["table"]["file"], base)
    data["name"] = f"{scenario.name}-calibrated"
    stamp = _dt.date.today().isoformat()
    data["description"] = (f"{scenario.description} Calibrated on {stamp}{': ' + note if note else ''}.").strip()
    return data


def write_calibrated_scenario(scenario, out_path: str | Path, parameter_file: str | Path, *, note: str = "",
                              calibrated: Mapping[str, float] | None = None,
                              structural: Mapping[str, float] | None = None) -> Path:
    """Write the calibrated scenario (YAML) atomically; returns its path.

    ``calibrated`` (the fitted parameters) only goes into the header comment, for the reader;
    the values in force are those of ``parameter_file``.
    """
    from twin._atomic import atomic_path
    from twin.scenario import scenario_from_dict

    out_path = Path(out_path)
    rel = Path(parameter_file)
    if rel.is_absolute():
        try:
            rel = rel.relative_to(out_path.parent.resolve())
        except ValueError:
            pass
    data = calibrated_scenario_dict(scenario, rel.as_posix(), note=note, structural=structural)
    scenario_from_dict(data, source=out_path)          # what is written must load
    header = ["# Written by twin calibrate. The parameter set in force is " + rel.as_posix() + "."]
    if calibrated:
        header.append("# Calibrated: " + ", ".join(f"{k} = {v:.6g}" for k, v in calibrated.items()))
    text = "\n".join(header) + "\n" + yaml.safe_dump(data, sort_keys=False)
    with atomic_path(out_path) as tmp:
        Path(tmp).write_text(text)
    return out_path
