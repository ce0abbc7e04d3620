"""Writing measurement files: :func:`write_measurements` (HDF5) and :func:`import_csv`.

Files are written in the layout of ``twin/measurements/README.md`` (``format =
"gear-twin-measurements"``, version 1), atomically (:func:`twin._atomic.atomic_path`): a
reader never sees a half-written file and a failed write leaves an existing file as it was.
Samples are stored as float64 in their canonical unit, gzip-compressed (level 4, byte
shuffle), so ``load_measurements(write_measurements(s, p))`` gives back the same numbers.
"""
from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from twin._atomic import atomic_path, check_parent
from twin.errors import MeasurementError, OutputPathError
from twin.measurements.format import (CSV_SUFFIXES, FORMAT_VERSION, HDF5_SUFFIXES, MEASUREMENT_FORMAT,
                                      RECORD_ATTRIBUTE_NAMES)
from twin.measurements.load import load_measurements
from twin.measurements.record import MeasurementSet, Record

__all__ = ["import_csv", "write_measurements"]

_GZIP_LEVEL = 4
_OPTIONAL = ("nominal_speed", "load", "tachometer", "tachometer_kind", "pulses_per_rev", "label", "damage",
             "resampled_from")


def _check_h5_path(path: str | os.PathLike[str]) -> Path:
    target = Path(path)
    if target.suffix.lower() not in HDF5_SUFFIXES:
        raise OutputPathError(f"measurement files are HDF5: '{target}' must end in "
                              f"{' or '.join(HDF5_SUFFIXES)}")
    return check_parent(target)


def write_measurements(data: MeasurementSet | Iterable[Record], path: str | os.PathLike[str]) -> Path:
    """Write records to an HDF5 measurement file, atomically.

    Parameters
    ----------
    data : MeasurementSet or iterable of Record
        Records to write, in order (names must be unique). A set's ``metadata`` becomes root
        attributes; each record's ``metadata`` becomes record attributes.
    path : path
        Target ``.h5``/``.hdf5`` file; replaced if it exists.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    OutputPathError
        Wrong suffix, missing directory, or ``path`` is a directory.
    MeasurementError
        No records, duplicate names, or metadata that HDF5 cannot store / that shadows a
        format attribute.
    """
    target = _check_h5_path(path)
    file = str(target)
    if isinstance(data, MeasurementSet):
        mset = data
    else:
        try:
            mset = MeasurementSet(tuple(data), None)
        except MeasurementError as exc:
            problems = [(file, r, p) for _, r, p in exc.problems]
            raise MeasurementError(*problems[0], problems=problems) from None
    if len(mset) == 0:
        raise MeasurementError(file, None, "nothing to write: no records")
    import h5py
    with atomic_path(target) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            _attrs(f.attrs, mset.metadata, file, None, reserved=("format", "format_version"))
            f.attrs["format"] = MEASUREMENT_FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            group = f.create_group("records", track_order=True)
            for rec in mset:
                g = group.create_group(rec.name, track_order=True)
                _attrs(g.attrs, rec.metadata, file, rec.name, reserved=RECORD_ATTRIBUTE_NAMES)
                g.attrs["sample_rate"] = rec.sample_rate
                if rec.time_start != 0.0:
                    g.attrs["time_start"] = rec.time_start
                for key in _OPTIONAL:
                    value = getattr(rec, key)
                    if value is not None:
                        g.attrs[key] = value
                for c, x in rec.channels.items():
                    ds = g.create_dataset(c, data=np.asarray(x, dtype=np.float64), compression="gzip",
                                          compression_opts=_GZIP_LEVEL, shuffle=True)
                    ds.attrs["unit"] = rec.units[c]
    return target


def _attrs(attrs, metadata, file: str, record: str | None, *, reserved: tuple[str, ...]) -> None:
    """Store free metadata as HDF5 attributes; refuse what would shadow the format or not fit."""
    for key, value in metadata.items():
        if key in reserved:
            raise MeasurementError(file, record, f"metadata key '{key}' is a format attribute; "
                                                 "set it on the record itself")
        try:
            attrs[key] = value
        except (TypeError, ValueError) as exc:
            raise MeasurementError(file, record, f"metadata '{key}' = {value!r} cannot be stored "
                                                 f"as an HDF5 attribute: {exc}") from None


def import_csv(csv_path: str | os.PathLike[str], out_h5: str | os.PathLike[str], *,
               sidecar: str | os.PathLike[str] | None = None, fmu: str | os.PathLike[str] | None = None,
               channels: Iterable[str] | None = None) -> Path:
    """Validate a CSV measurement (+ sidecar) and write it as an HDF5 measurement file.

    Parameters
    ----------
    csv_path : path
        ``.csv`` file with a ``time`` column [s] and one column per channel.
    out_h5 : path
        Target ``.h5``/``.hdf5`` file (written atomically).
    sidecar : path, optional
        YAML/JSON sidecar; by default ``<file>.yaml``/``.yml``/``.json`` next to the CSV.
    fmu : path, optional
        The FMU that produced the CSV (e.g. ``fmpy simulate ... --output-file``): the unit of each
        column the sidecar does not give is that of the FMU variable of its name, and no sidecar is
        needed (the sample rate comes from the time column). A column that names no variable of the
        FMU is an error naming it.
    channels : names, optional
        Keep only these channels (default: every column but ``time``).

    Returns
    -------
    Path
        The written HDF5 file. Units are canonical there (``g`` was converted to ``m/s2``).

    Raises
    ------
    MeasurementError
        Every problem of the CSV and its sidecar (see :func:`load_measurements`).
    OutputPathError
        ``out_h5`` cannot be written (checked before the CSV is read).
    """
    target = _check_h5_path(out_h5)
    src = Path(csv_path)
    if src.suffix.lower() not in CSV_SUFFIXES:
        raise MeasurementError(str(src), None, f"not a CSV file (suffix must be {', '.join(CSV_SUFFIXES)})")
    keep = list(channels) if channels is not None else None
    if fmu is None:
        return write_measurements(load_measurements(src, sidecar=sidecar, channels=keep), target)
    import json
    import tempfile

    with tempfile.TemporaryDirectory(prefix="twin_import_") as tmp:
        merged = Path(tmp) / f"{src.name}.json"
        merged.write_text(json.dumps(_sidecar_with_fmu_units(src, sidecar, Path(fmu), keep)), encoding="utf-8")
        return write_measurements(load_measurements(src, sidecar=merged, channels=keep), target)


def _sidecar_with_fmu_units(src: Path, sidecar, fmu: Path, keep: list[str] | None) -> dict:
    """The sidecar (given, found next to the CSV, or empty) with the FMU's unit for every other column."""
    import csv

    from twin.measurements.format import sidecar_candidates
    from twin.measurements.csv_read import read_sidecar

    found = [Path(sidecar)] if sidecar is not None else [c for c in sidecar_candidates(src) if c.is_file()][:1]
    try:
        side = dict(read_sidecar(found[0])) if found else {}
    except ValueError as exc:
        raise MeasurementError(str(src), None, str(exc)) from None
    with src.open(newline="", encoding="utf-8-sig") as fh:
        header = [h.strip() for h in next(csv.reader(fh), [])]
    from twin.fmu import FMU
    with FMU(fmu) as f:
        variables = f.variables
    units = dict(side.get("units") or {})
    wanted = [c for c in header if c != "time" and (keep is None or c in keep) and c not in units]
    unknown = [c for c in wanted if c not in variables]
    if unknown:
        raise MeasurementError(str(src), None, f"column(s) {', '.join(map(repr, unknown))} name no variable of "
                                               f"{fmu.name}, so their units are unknown")
    units.update({c: variables[c].unit or "1" for c in wanted})
    side["units"] = units
    return side
