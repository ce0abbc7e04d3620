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
               sidecar: str | os.PathLike[str] | None = None) -> Path:
    """Validate a CSV measurement (+ sidecar) and write it as an HDF5 measurement file.

    Parameters
    ----------
    csv_path : path
        ``.csv`` file with a ``time`` column [s] and one column per channel.
    out_h5 : path
        Target ``.h5``/``.hdf5`` file (written atomically).
    sidecar : path, optional
        YAML/JSON sidecar; by default ``<file>.yaml``/``.yml``/``.json`` next to the CSV.

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
    return write_measurements(load_measurements(src, sidecar=sidecar), target)
