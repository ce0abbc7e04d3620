"""Simulation results as CSV files with a JSON sidecar (:func:`write_csv`, :func:`read_csv`).

CSV layout
----------
``<path>``
    Header ``time,<channel>,...`` (plain names, as fmpy writes and reads them;
    units are in the sidecar), then one row per sample: floats printed with 17
    significant digits (9 for float32) so a round trip is exact, integers in
    full, booleans as 1/0, strings quoted where needed.
``<path>.json``
    Sidecar with ``format``, ``format_version``, ``model_name``, ``guid``,
    ``fmu_sha256``, ``sample_rate`` (Hz), ``channels`` (ordered names),
    ``units``, ``types`` (FMI type per channel), ``dtypes`` (numpy dtype name
    per channel, ``str`` for strings), ``enumerations`` (channel ->
    item name -> value), ``parameters``, ``ended_by_fmu`` and ``end_reason``;
    a scenario run adds ``complete``, ``scenario_name``, ``scenario`` and
    ``events``.

Both files are written atomically (see :mod:`twin._atomic`).  :mod:`twin.results` holds the
container and chooses between this format and HDF5 (:mod:`twin.results_hdf5`) by suffix.
"""
from __future__ import annotations

import csv
import io
import json
import os
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from twin._atomic import atomic_path
from twin.errors import OutputPathError
from twin.results import FORMAT, FORMAT_VERSION, SimulationResult, _is_text, _param_value

__all__ = ["read_csv", "write_csv"]


def _sidecar_path(path: Path) -> Path:
    return path.with_name(path.name + ".json")


def _csv_column(values: np.ndarray) -> list[str]:
    """One channel as CSV fields: exact round trip for every dtype."""
    kind = values.dtype.kind
    if kind == "f":
        fmt = ".9g" if values.dtype.itemsize == 4 else ".17g"
        return [format(x, fmt) for x in values.tolist()]
    if kind == "b":
        return ["1" if x else "0" for x in values.tolist()]
    return [str(x) for x in values.tolist()]


def write_csv(result: SimulationResult, path: str | os.PathLike[str], *,
              extra: Mapping[str, Any] | None = None) -> Path:
    """Write ``result`` as CSV plus a ``<path>.json`` metadata sidecar (``extra`` adds keys to it).

    Both files are written atomically, the CSV first, so a sidecar never
    describes data that are not there yet. Returns the CSV path.
    """
    target = Path(path)
    names = list(result.signals)
    header = io.StringIO()
    # Plain names, as fmpy writes and reads them (units are in the sidecar); csv.writer quotes
    # channel names containing commas or quotes.
    csv.writer(header, lineterminator="").writerow(["time", *names])
    with atomic_path(target) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            if all(result.signals[n].dtype == np.float64 for n in names):
                table = np.column_stack([result.time, *(result.signals[n] for n in names)])
                np.savetxt(fh, table, fmt="%.17g", delimiter=",", header=header.getvalue(),
                           comments="")
            else:
                fh.write(header.getvalue() + "\n")
                columns = [_csv_column(result.time), *(_csv_column(result.signals[n]) for n in names)]
                csv.writer(fh, lineterminator="\n").writerows(zip(*columns))
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "model_name": result.model_name,
        "guid": result.guid,
        "fmu_sha256": result.fmu_sha256,
        "sample_rate": result.sample_rate,
        "channels": names,
        "units": {n: result.units.get(n, "") for n in names},
        "types": {n: result.types[n] for n in names if n in result.types},
        "dtypes": {n: "str" if _is_text(result.signals[n]) else result.signals[n].dtype.name for n in names},
        "enumerations": {n: result.enumerations[n] for n in names if n in result.enumerations},
        "parameters": {k: _param_value(v) for k, v in result.parameters.items()},
        "ended_by_fmu": result.ended_by_fmu,
        "end_reason": result.end_reason,
        **(extra or {}),
    }
    with atomic_path(_sidecar_path(target)) as tmp:
        tmp.write_text(json.dumps(meta, indent=2) + "\n", encoding="utf-8")
    return target


def _parse_column(values: list[str], fmi_type: str | None, name: str, source: Path,
                  dtype: str | None = None) -> np.ndarray:
    """CSV fields of one channel back to its dtype (the sidecar's, else the FMI type's, else float64)."""
    from twin.variables import FLOAT_TYPES, INTEGER_TYPES
    try:
        if dtype == "str":
            fmi_type = "String"
        elif dtype == "bool":
            fmi_type = "Boolean"
        elif dtype is not None:
            kind = np.dtype(dtype).kind
            if kind in "iu":
                return np.array([int(x) for x in values], dtype=dtype)
            if kind == "f":
                return np.array([float(x) for x in values], dtype=dtype)
        if fmi_type in FLOAT_TYPES:
            return np.array([float(x) for x in values], dtype=FLOAT_TYPES[fmi_type])
        if fmi_type in INTEGER_TYPES:
            return np.array([int(x) for x in values], dtype=INTEGER_TYPES[fmi_type][0])
        if fmi_type == "Enumeration":
            return np.array([int(x) for x in values], dtype=np.int64)
        if fmi_type == "Boolean":
            bad = [x for x in values if x not in ("0", "1")]
            if bad:
                raise ValueError(f"{bad[0]!r} is not 0 or 1")
            return np.array([x == "1" for x in values], dtype=bool)
        if fmi_type == "String":
            out = np.empty(len(values), dtype=object)
            out[:] = values
            return out
        return np.array([float(x) for x in values], dtype=np.float64)
    except ValueError as exc:
        raise OutputPathError(f"'{source}': channel '{name}' ({fmi_type or 'Real'}): {exc}") from None


def read_csv(path: str | os.PathLike[str]) -> SimulationResult:
    """Read a CSV result and its ``<path>.json`` sidecar written by :func:`write_csv`.

    Raises
    ------
    FileNotFoundError
        If the CSV or its sidecar is missing.
    OutputPathError
        If the sidecar is not a gear-twin result or disagrees with the column count.
    """
    source = Path(path)
    sidecar = _sidecar_path(source)
    for p in (source, sidecar):
        if not p.is_file():
            raise FileNotFoundError(f"result file '{p}' does not exist")
    meta = json.loads(sidecar.read_text(encoding="utf-8"))
    if meta.get("format") != FORMAT or meta.get("format_version") != FORMAT_VERSION:
        raise OutputPathError(f"'{sidecar}' is not a {FORMAT} v{FORMAT_VERSION} sidecar")
    names = list(meta["channels"])
    types = dict(meta.get("types", {}))
    dtypes = dict(meta.get("dtypes", {}))
    if any(types.get(n, "Real") not in ("Real", "Float64") or dtypes.get(n, "float64") != "float64" for n in names):
        with open(source, encoding="utf-8", newline="") as fh:
            rows = list(csv.reader(fh))[1:]
        bad = [i for i, r in enumerate(rows) if len(r) != len(names) + 1]
        if bad:
            raise OutputPathError(f"'{source}' row {bad[0] + 2} has {len(rows[bad[0]])} columns, "
                                  f"sidecar lists {len(names)} channels + time")
        fields = list(zip(*rows)) if rows else [() for _ in range(len(names) + 1)]
        time = _parse_column(list(fields[0]), "Float64", "time", source)
        signals = {n: _parse_column(list(fields[i + 1]), types.get(n), n, source, dtypes.get(n))
                   for i, n in enumerate(names)}
    else:
        with warnings.catch_warnings():
            # A header-only file (zero samples) is valid here, not worth a warning.
            warnings.filterwarnings("ignore", message="loadtxt: input contained no data")
            table = np.loadtxt(source, delimiter=",", skiprows=1, ndmin=2, dtype=np.float64)
        if table.size == 0:
            table = np.empty((0, len(names) + 1))
        if table.shape[1] != len(names) + 1:
            raise OutputPathError(
                f"'{source}' has {table.shape[1]} columns, sidecar lists {len(names)} channels + time"
            )
        time = table[:, 0]
        signals = {n: table[:, i + 1] for i, n in enumerate(names)}
    return SimulationResult(
        time=time,
        signals=signals,
        units=meta.get("units", {}),
        sample_rate=meta["sample_rate"],
        parameters=meta.get("parameters", {}),
        model_name=meta.get("model_name", ""),
        guid=meta.get("guid", ""),
        fmu_sha256=meta.get("fmu_sha256", ""),
        types=types,
        enumerations=meta.get("enumerations", {}),
        ended_by_fmu=bool(meta.get("ended_by_fmu", False)),
        end_reason=str(meta.get("end_reason", "")),
    )
