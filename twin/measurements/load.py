"""Loading and validating measurement files (HDF5, or CSV with a YAML/JSON sidecar).

:func:`load_measurements` reads a whole file, checks everything the format
(``twin/measurements/README.md``) demands, and either returns a :class:`MeasurementSet` of
records in canonical units or raises one :class:`twin.errors.MeasurementError` that lists
*every* problem of the file (``err.problems``), so a bad rig export is fixed in one round
instead of one error at a time.
"""
from __future__ import annotations

import logging
import os
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from twin.errors import MeasurementError, ParameterError
from twin.measurements._raw import _number, _Problems, _RawRecord
# the CSV reader; read_sidecar stays importable from here (part of this module's API)
from twin.measurements.csv_read import _read_csv, read_sidecar  # noqa: F401
from twin.measurements.format import (CSV_SUFFIXES, FORMAT_VERSION, READABLE_FORMATS, RESERVED_CHANNELS,
                                      _as_int, canonical_unit, clipping_problems, nonfinite_problem,
                                      parse_record_attributes, plain_value, tachometer_problems,
                                      unknown_unit_problem)
from twin.measurements.record import MeasurementSet, Record
from twin.measurements.resample import resample_record

__all__ = ["MeasurementSet", "Record", "iter_measurements", "load_measurements", "read_sidecar"]

log = logging.getLogger("twin.measurements")


def load_measurements(path: str | os.PathLike[str], *, min_duration: float | None = None,
                      channels: Iterable[str] | None = None, resample_to: float | None = None,
                      sidecar: str | os.PathLike[str] | None = None,
                      check_clipping: bool = True, tachometer: bool = True) -> MeasurementSet:
    """Load and validate every record of a measurement file.

    Parameters
    ----------
    path : path
        HDF5 file (``format`` ``gear-twin-measurements`` or ``gear-twin-archive``; detected by
        the HDF5 signature) or ``.csv`` file with a sidecar.
    min_duration : float, optional
        Shortest acceptable record [s]; shorter records are problems.
    channels : iterable of str, optional
        Channels to load; each must exist in every record. Others are not read (nor checked).
        A record's tachometer channel is kept too (unless ``tachometer=False``), so order
        analysis stays possible.
    resample_to : float, optional
        Target sampling rate [Hz]. Records at another rate are resampled (see
        :mod:`twin.measurements.resample`); each carries its original rate in
        ``Record.resampled_from`` and ``MeasurementSet.notes`` says what was done (the notes
        are also logged at INFO on the ``twin.measurements`` logger).
    sidecar : path, optional
        CSV only: the sidecar to use instead of looking for ``<file>.yaml``/``.yml``/``.json``.
    check_clipping : bool
        Report clipped channels (default). The test (runs of equal extreme samples) cannot tell
        saturation from a coarsely quantised or noise-free periodic signal; switch it off only
        for such data.
    tachometer : bool
        With ``channels``: False reads (and checks) only those channels, and the records carry
        no tachometer, for work that does not use it (the wear assessors: a compressed
        tachometer channel costs as much to read as the vibration channel).

    Returns
    -------
    MeasurementSet
        Records in stored order, samples as float64 in canonical units (``g`` -> ``m/s2``).

    Raises
    ------
    MeasurementError
        Listing every problem of the file: missing file, not HDF5/CSV, unknown format,
        non-finite samples, bad CSV time axis, missing sample rate, unknown units, clipping,
        records shorter than ``min_duration``, requested channels missing, empty records, ...
    ParameterError
        For invalid arguments (e.g. a negative ``resample_to``).
    """
    wanted = _check_arguments(min_duration, channels, resample_to)
    problems, file_metadata = _Problems(str(Path(path))), {}
    records = list(_records(path, problems, wanted, min_duration, check_clipping, tachometer, sidecar, file_metadata))
    file = problems.file
    problems.raise_if_any()
    notes = []
    if resample_to is not None:
        for i, rec in enumerate(records):
            try:
                records[i], note = resample_record(rec, resample_to)
            except MeasurementError as exc:
                problems.extend(rec.name, [p for _, _, p in exc.problems])
                continue
            if note is not None:
                notes.append(note)
                log.info("%s: %s", file, note)
        problems.raise_if_any()
    return MeasurementSet(tuple(records), file, tuple(notes), file_metadata)


def iter_measurements(path: str | os.PathLike[str], *, min_duration: float | None = None,
                      channels: Iterable[str] | None = None, check_clipping: bool = True,
                      tachometer: bool = True) -> Iterator[Record]:
    """The records :func:`load_measurements` returns (without resampling), one at a time as they
    are read, so work on a record can run while the next one is read (HDF5: one record's
    datasets at a time; CSV: the whole file first).

    Raises
    ------
    MeasurementError
        As :func:`load_measurements`, listing every problem of the file, after the last record
        of a file with problems (no record is yielded after the first problem: the file is
        rejected, so whatever was computed from the records yielded must be discarded).
    ParameterError
        For invalid arguments, at the first ``next``.
    """
    wanted = _check_arguments(min_duration, channels, None)
    problems = _Problems(str(Path(path)))
    yield from _records(path, problems, wanted, min_duration, check_clipping, tachometer, None, {})
    problems.raise_if_any()


def _records(path, problems: _Problems, wanted, min_duration, check_clipping, tachometer, sidecar,
             metadata: dict) -> Iterator[Record]:
    """The valid records of a file as they are read; the file's problems go to ``problems``, its
    attributes to ``metadata``."""
    if not isinstance(tachometer, bool):
        raise ParameterError(f"tachometer must be True or False, got {tachometer!r}")
    p = Path(path)
    file = str(p)
    if not p.exists():
        raise MeasurementError(file, None, "file does not exist")
    if p.is_dir():
        raise MeasurementError(file, None, "is a directory, not a measurement file")
    import h5py
    if h5py.is_hdf5(p):
        if sidecar is not None:
            raise ParameterError(f"a sidecar only applies to CSV files, not to the HDF5 file {file}")
        raws = _read_hdf5(p, problems, wanted, tachometer, metadata)
    elif p.suffix.lower() in CSV_SUFFIXES:
        raws = _read_csv(p, problems, sidecar)
    else:
        raise MeasurementError(file, None, "neither an HDF5 file (no HDF5 signature) nor a CSV file "
                                           f"(suffix {', '.join(CSV_SUFFIXES)})")
    for raw in raws:
        rec = _validate(raw, problems, file, wanted, min_duration, check_clipping, tachometer)
        if rec is not None:
            yield rec


def _check_arguments(min_duration, channels, resample_to) -> tuple[str, ...] | None:
    if min_duration is not None and not (_number(min_duration) and min_duration >= 0):
        raise ParameterError(f"min_duration must be a finite number >= 0 [s], got {min_duration!r}")
    if resample_to is not None and not (_number(resample_to) and resample_to > 0):
        raise ParameterError(f"resample_to must be a finite number > 0 [Hz], got {resample_to!r}")
    if channels is None:
        return None
    # A bare string is one channel name, not an iterable of one-letter channels.
    wanted = (channels,) if isinstance(channels, str) else tuple(channels)
    if not wanted or not all(isinstance(c, str) and c for c in wanted):
        raise ParameterError(f"channels must be a non-empty list of channel names, got {channels!r}")
    return wanted


def _kept(channel: str, wanted: tuple[str, ...] | None, tachometer: Any) -> bool:
    return wanted is None or channel in wanted or channel == tachometer


# --------------------------------------------------------------------------- HDF5

def _read_hdf5(p: Path, problems: _Problems, wanted, keep_tachometer: bool, metadata: dict
               ) -> Iterator[_RawRecord]:
    """The file's records, one at a time (the file stays open until the last); its root
    attributes go to ``metadata``."""
    import h5py
    try:
        f = h5py.File(p, "r")
    except OSError as exc:
        raise MeasurementError(str(p), None, f"cannot be opened as HDF5: {exc}") from None
    with f:
        fmt = plain_value(f.attrs.get("format"))
        accepted = " or ".join(repr(x) for x in READABLE_FORMATS)
        if fmt is None:
            problems.add(None, f"no root attribute 'format' (expected {accepted})")
        elif fmt not in READABLE_FORMATS:
            problems.add(None, f"unknown format {fmt!r} (expected {accepted})")
        version = _as_int(f.attrs.get("format_version"))
        if version is None:
            problems.add(None, f"no integer root attribute 'format_version' (expected {FORMAT_VERSION})")
        elif version != FORMAT_VERSION:
            problems.add(None, f"format_version {version} is not supported (this reader reads {FORMAT_VERSION})")
        group = f.get("records")
        if not isinstance(group, h5py.Group):
            problems.add(None, "no '/records' group")
        elif len(group) == 0:
            problems.add(None, "empty file: '/records' holds no records")
        # Without a known format and a records group nothing below can be trusted.
        problems.raise_if_any()
        metadata.update((k, plain_value(v)) for k, v in f.attrs.items() if k not in ("format", "format_version"))
        for name in group:
            obj = group.get(name)
            if not isinstance(obj, h5py.Group):
                problems.add(name, "is not a group (records are groups of 1-D channel datasets)")
                continue
            try:
                attrs = {k: obj.attrs[k] for k in obj.attrs}
            except (OSError, TypeError, ValueError) as exc:
                problems.add(name, f"record attributes cannot be read: {exc}")
                continue
            tach = plain_value(attrs.get("tachometer"))
            all_channels, chans, units = [], {}, {}
            for cname in obj:
                ds = obj.get(cname)
                if not isinstance(ds, h5py.Dataset):
                    problems.add(name, f"member '{cname}' is not a dataset (channels are 1-D datasets)")
                    continue
                all_channels.append(cname)
                if not _kept(cname, wanted, tach if keep_tachometer else None):
                    continue
                if ds.ndim != 1:
                    problems.add(name, f"channel '{cname}' must be a 1-D dataset, got shape {ds.shape}")
                    continue
                if ds.dtype.kind not in "fiu":
                    problems.add(name, f"channel '{cname}' is not numeric (dtype {ds.dtype})")
                    continue
                chans[cname] = np.asarray(ds[()], dtype=np.float64)
                units[cname] = plain_value(ds.attrs["unit"]) if "unit" in ds.attrs else None
            yield _RawRecord(name, chans, units, all_channels, attrs)


def _validate(raw: _RawRecord, problems: _Problems, file: str, wanted, min_duration,
              check_clipping: bool, keep_tachometer: bool = True) -> Record | None:
    """Check one raw record; add its problems; return the Record if it has none."""
    name = raw.name
    if raw.attrs is not None:
        attrs, meta, attr_problems = parse_record_attributes(raw.attrs, raw.all_channels,
                                                             require_sample_rate=raw.require_sample_rate)
        problems.extend(name, attr_problems)
    else:
        attrs, meta = {}, {}
    meta.update(raw.metadata)
    fs = attrs.get("sample_rate")
    t0 = attrs.get("time_start") or 0.0
    tach, kind = attrs.get("tachometer"), attrs.get("tachometer_kind")
    pulses = attrs.get("pulses_per_rev")
    if not keep_tachometer and wanted is not None and tach not in wanted:
        tach, kind, pulses = None, None, None          # not read: the record has no tachometer

    if wanted is not None:
        missing = [c for c in wanted if c not in raw.all_channels]
        if missing:
            problems.add(name, f"requested channels missing: {', '.join(missing)} "
                               f"(record has: {', '.join(raw.all_channels) or 'none'})")
    if wanted is None:
        chans = dict(raw.channels)
    else:
        chans = {c: x for c, x in raw.channels.items() if _kept(c, wanted, tach)}
    if not raw.all_channels:
        problems.add(name, "empty record: no channels")
    lengths = {c: x.size for c, x in chans.items()}
    if len(set(lengths.values())) > 1:
        problems.add(name, "channels differ in length: " + ", ".join(f"{c}={k}" for c, k in lengths.items()))
    elif chans and next(iter(lengths.values())) == 0:
        problems.add(name, "empty record: 0 samples")

    converted: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    for c, x in chans.items():
        if c in RESERVED_CHANNELS:
            problems.add(name, f"channel name '{c}' is reserved (time is implicit: time_start + i / sample_rate)")
            continue
        stored = raw.units.get(c)
        unit = None
        if stored is None:
            problems.add(name, f"channel '{c}' has no unit ({raw.unit_hint})")
        else:
            unit = canonical_unit(stored)
            if unit is None:
                problems.add(name, unknown_unit_problem(c, stored))
        if c in raw.unchecked:
            continue
        bad = nonfinite_problem(c, x, fs, t0)
        if bad is not None:
            problems.add(name, bad)
            continue
        if unit is None:
            continue
        canon, factor = unit
        if c == tach and kind is not None:
            problems.extend(name, tachometer_problems(c, x, kind, canon))
        elif check_clipping:
            problems.extend(name, clipping_problems(c, x, stored if isinstance(stored, str) else canon))
        # Multiply only when converting so stored values stay bit-identical otherwise.
        converted[c] = x * factor if factor != 1.0 else x
        units[c] = canon
    if min_duration is not None and fs is not None and lengths:
        n = next(iter(lengths.values()))
        if n / fs < min_duration:
            problems.add(name, f"record is {n / fs:.6g} s long ({n} samples at {fs:g} Hz), "
                               f"shorter than min_duration {min_duration:g} s")
    if problems.items or raw.attrs is None:
        return None          # the file will be rejected; a Record would only repeat problems
    try:
        return Record(name=name, channels=converted, units=units, sample_rate=fs,
                      nominal_speed=attrs["nominal_speed"], load=attrs["load"], tachometer=tach,
                      tachometer_kind=kind, pulses_per_rev=pulses, label=attrs["label"],
                      damage=attrs["damage"], source=file, time_start=attrs["time_start"],
                      resampled_from=attrs["resampled_from"], metadata=meta)
    except MeasurementError as exc:
        problems.extend(name, [p for _, _, p in exc.problems])
        return None
