"""Reading a CSV measurement file and its YAML/JSON sidecar into raw records
(:mod:`twin.measurements.load` validates them)."""
from __future__ import annotations

import csv
import json
import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from twin.errors import MeasurementError
from twin.measurements._raw import _number, _Problems, _RawRecord
from twin.measurements.format import nonfinite_problem, plain_value, rate_from_step, sidecar_candidates, time_axis


def read_sidecar(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Parse a YAML (``.yaml``/``.yml``) or JSON (``.json``) sidecar into a dict.

    Raises
    ------
    ValueError
        Unreadable or unparsable file, or a top level that is not a mapping.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"sidecar '{p}' cannot be read: {exc}") from None
    if p.suffix.lower() == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ValueError(f"sidecar '{p}' is not valid JSON: {exc}") from None
    elif p.suffix.lower() in (".yaml", ".yml"):
        import yaml
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise ValueError(f"sidecar '{p}' is not valid YAML: {exc}") from None
    else:
        raise ValueError(f"sidecar '{p}' must end in .yaml, .yml or .json")
    if not isinstance(data, dict):
        raise ValueError(f"sidecar '{p}' must hold a mapping of record attributes, got {type(data).__name__}")
    return data


def _read_csv(p: Path, problems: _Problems, sidecar) -> list[_RawRecord]:
    # --- sidecar: found, parsed, split into attributes / units / name / metadata
    side: dict[str, Any] | None = None
    side_problem = None
    if sidecar is not None:
        side_path = Path(sidecar)
        if not side_path.is_file():
            side_problem = f"sidecar '{side_path}' does not exist"
    else:
        found = [c for c in sidecar_candidates(p) if c.is_file()]
        side_path = found[0] if len(found) == 1 else None
        if not found:
            side_problem = ("no sidecar with units and record attributes: looked for "
                            + ", ".join(c.name for c in sidecar_candidates(p)))
        elif len(found) > 1:
            side_problem = (f"ambiguous sidecars {', '.join(c.name for c in found)}; "
                            "keep one or pass sidecar= explicitly")
    if side_problem is None:
        try:
            side = read_sidecar(side_path)
        except ValueError as exc:
            side_problem = str(exc)
    side = dict(side) if side is not None else None
    name = p.stem
    units_raw: Any = {}
    extra_meta: Any = {}
    if side is not None:
        rec_name = side.pop("record", None)
        if rec_name is not None:
            if isinstance(rec_name, str) and rec_name and "/" not in rec_name:
                name = rec_name
            else:
                problems.add(name, f"sidecar key 'record' must be a name without '/', got {rec_name!r}")
        units_raw = side.pop("units", {})
        extra_meta = side.pop("metadata", {})
        if not isinstance(units_raw, dict):
            problems.add(name, f"sidecar key 'units' must map channel -> unit, got {units_raw!r}")
            units_raw = {}
        if not isinstance(extra_meta, dict):
            problems.add(name, f"sidecar key 'metadata' must be a mapping, got {extra_meta!r}")
            extra_meta = {}
    if side_problem is not None:
        problems.add(name, side_problem)

    # --- header: checked by hand because pandas silently renames duplicate columns
    try:
        with p.open(newline="", encoding="utf-8-sig") as fh:   # tolerate an Excel BOM
            header = next(csv.reader(fh), None)
    except UnicodeDecodeError:
        raise MeasurementError(str(p), None, "not a CSV text file (not UTF-8)") from None
    if header is None:
        problems.add(None, "empty file: no header row")
        problems.raise_if_any()
    columns = [h.strip() for h in header]
    if "time" not in columns:
        problems.add(None, f"no 'time' column (columns: {', '.join(columns)})")
    if any(not c for c in columns):
        problems.add(None, "empty column name in the header")
    dup = sorted({c for c in columns if columns.count(c) > 1})
    if dup:
        problems.add(None, f"duplicate column names: {', '.join(dup)}")
    if "time" not in columns or dup or any(not c for c in columns):
        problems.raise_if_any()
    values, bad_cells = _read_columns(p, columns, problems)
    n = next(iter(values.values())).size
    unchecked: set[str] = set()
    for col, (count, i, text) in bad_cells.items():
        problems.add(name, f"column '{col}' has {count} non-numeric cells; first at sample {i}: {text!r}")
        unchecked.add(col)

    # --- time axis: strictly increasing and uniform; gives sample_rate and time_start
    t = values.pop("time")
    attrs = dict(side) if side is not None else None
    time_ok = "time" not in unchecked
    if time_ok and not np.all(np.isfinite(t)):
        problems.add(name, nonfinite_problem("time", t, None, 0.0))
        time_ok = False
    step = None
    if time_ok:
        step, time_problems = time_axis(t)
        problems.extend(name, time_problems)
        time_ok = not time_problems
    if attrs is not None and n >= 1 and time_ok:
        if step is not None:
            derived = rate_from_step(step)
            if "sample_rate" in attrs:
                given = attrs["sample_rate"]
                g = plain_value(given)
                if _number(g) and g > 0 and abs(g - derived) > 1e-6 * g:
                    problems.add(name, f"sidecar sample_rate {g:g} Hz disagrees with the time column "
                                       f"({derived:.9g} Hz)")
            else:
                attrs["sample_rate"] = derived
        if "time_start" in attrs:
            g = plain_value(attrs["time_start"])
            tol = 1e-6 * step if step is not None else 1e-12 * max(1.0, abs(t[0]))
            if _number(g) and abs(g - t[0]) > tol:
                problems.add(name, f"sidecar time_start {g:g} s disagrees with the first time sample {t[0]:.9g} s")
        else:
            attrs["time_start"] = float(t[0])
    # When the time column is broken it already explains why no rate could be derived.
    require_rate = time_ok or (attrs is not None and "sample_rate" in attrs)

    units: dict[str, Any] = {c: None for c in values}
    for key, unit in units_raw.items():
        if key == "time":
            if plain_value(unit) != "s":
                problems.add(name, f"the 'time' column must be in 's', sidecar says {unit!r}")
        elif key not in values:
            problems.add(name, f"sidecar 'units' names '{key}', which is not a column of the CSV")
        else:
            units[key] = unit
    if side is None:
        units = {c: "" for c in values}      # the missing sidecar is reported once, not per channel
    raw = _RawRecord(name, values, units, list(values), attrs, dict(extra_meta), unchecked, require_rate,
                     "entry in the sidecar's 'units'")
    return [raw]


_NAN_TEXT = ["nan", "NaN", "NAN", "+nan", "-nan"]


def _read_columns(p: Path, columns: list[str], problems: _Problems
                  ) -> tuple[dict[str, np.ndarray], dict[str, tuple[int, int, str]]]:
    """Parse the CSV body into float64 columns ``(n,)``.

    Returns the columns and, per column with cells that are not numbers, ``(count, first
    index, first offending text)``; those cells are NaN in the column. ``nan``/``inf`` cells
    are numbers here (the non-finite check reports them with their time).
    """
    import pandas as pd
    # index_col=False with explicit names: pandas would otherwise take a first data row with
    # one field too many as an index column and shift every channel silently.
    kw = dict(header=0, names=columns, index_col=False, skipinitialspace=True, keep_default_na=False)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", pd.errors.ParserWarning)
            try:
                # Fast path: the C parser straight to float64 (~10x faster than the text path).
                df = pd.read_csv(p, dtype=np.float64, na_values=_NAN_TEXT, **kw)
                return {c: df[c].to_numpy(dtype=np.float64) for c in columns}, {}
            except pd.errors.ParserError:
                raise
            except ValueError:
                df = pd.read_csv(p, dtype=str, **kw)     # some cell is not a number: find them all
    except (pd.errors.ParserError, pd.errors.ParserWarning) as exc:
        problems.add(None, f"malformed CSV (a row has more fields than the header): {exc}")
        problems.raise_if_any()
    values, bad_cells = {}, {}
    for col in columns:
        text = df[col].fillna("").astype(str).str.strip()
        num = pd.to_numeric(text, errors="coerce").to_numpy(dtype=np.float64)
        bad = np.isnan(num) & ~text.isin(_NAN_TEXT).to_numpy()
        if bad.any():
            i = int(np.argmax(bad))
            bad_cells[col] = (int(bad.sum()), i, text.iloc[i])
        values[col] = num
    return values, bad_cells


# --------------------------------------------------------------------------- validation
