"""Simulation results: the in-memory container and its HDF5 / CSV files.

HDF5 layout (``format="gear-twin-result"``, ``format_version=1``)
-----------------------------------------------------------------
``/`` attributes
    ``model_name`` (str), ``guid`` (str, FMU GUID), ``fmu_sha256`` (str, hex
    digest of the FMU file), ``sample_rate`` (float, Hz), ``format`` (str),
    ``format_version`` (int), ``ended_by_fmu`` (bool: the FMU ended the run
    itself before the requested stop time) and ``end_reason`` (str, how).
``/time``
    1-D float64 dataset of sample times, attribute ``unit="s"``.  Samples are
    on the output grid; only the last sample of a run the FMU ended itself may
    fall between grid points (the FMU's last valid time).
``/signals/<name>``
    One 1-D dataset per channel, same length as ``/time``, in the variable's
    own type: float64 (FMI Real/Float64), float32, int8 ... uint64, bool, int32
    (FMI 2.0 Integer and Enumeration) or int64 (FMI 3.0 Enumeration), or UTF-8
    strings.  Numbers are gzip level 4, byte-shuffled and chunked.  Attributes
    ``name`` (the channel name, which is authoritative because ``/`` and ``%``
    are percent-escaped in the dataset key), ``unit`` (str, ``''`` if
    dimensionless or unknown; from the variable or its declared type),
    ``sample_rate`` (float, Hz), ``fmi_type`` (the FMI type name, when known)
    and, for an enumeration, ``items`` (JSON object item name -> value).
    Channel order is preserved.
``/parameters``
    Group whose attributes map parameter name -> value (float, int, bool or
    str; an enumeration's integer value), as they were right after the FMU's
    initialisation.

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

Every file is written atomically (see :mod:`twin._atomic`).
"""
from __future__ import annotations

import csv
import io
import json
import os
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from twin._atomic import atomic_path, check_parent
from twin.errors import OutputPathError

if TYPE_CHECKING:
    import pandas

FORMAT = "gear-twin-result"
FORMAT_VERSION = 1
HDF5_SUFFIXES = (".h5", ".hdf5")
CSV_SUFFIXES = (".csv",)
_GZIP_LEVEL = 4


def _channel_array(values: Any) -> np.ndarray:
    """A channel's samples: a numpy array keeps its numeric or bool dtype, strings become an
    ``object`` array of ``str``, anything else float64."""
    if isinstance(values, np.ndarray) and values.dtype.kind in "biuf":
        return values
    arr = np.asarray(values)
    if arr.dtype.kind in "US" or (arr.dtype.kind == "O" and arr.size
                                  and all(isinstance(x, (str, bytes)) for x in arr.ravel())):
        flat = [x.decode("utf-8") if isinstance(x, bytes) else str(x) for x in arr.ravel()]
        out = np.empty(len(flat), dtype=object)
        out[:] = flat
        return out.reshape(arr.shape)
    return np.asarray(values, dtype=np.float64)


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Sampled outputs of one simulation run.

    Attributes
    ----------
    time : numpy.ndarray, shape (n,)
        Sample times [s], float64.
    signals : Mapping[str, numpy.ndarray]
        Channel name -> samples, each shape (n,), in output order.  numpy arrays
        keep their dtype (float64, float32, signed/unsigned integers, bool, or
        strings held as an ``object`` array of ``str``); anything else becomes
        float64.
    units : Mapping[str, str]
        Channel name -> unit string (``''`` if none).
    sample_rate : float
        Output sample rate [Hz] (1 / output interval).
    parameters : Mapping[str, Any]
        Parameter values of the run, name -> value (float, int, bool or str), as
        they were right after the FMU's initialisation.
    model_name, guid, fmu_sha256 : str
        Provenance of the FMU that produced the data.
    types : Mapping[str, str]
        Channel name -> FMI type name (``Real``, ``Int8``, ``Enumeration`` ...), where known.
    enumerations : Mapping[str, Mapping[str, int]]
        Enumeration channel -> item name -> value.
    ended_by_fmu : bool
        The FMU ended the run itself (FMI 2.0 ``fmi2Discard``/``fmi2Terminated``, FMI 3.0
        ``terminateSimulation``) before the requested stop time; ``end_reason`` says how.

    Equality is identity (arrays have no single truth value); compare fields
    explicitly instead.
    """

    time: np.ndarray
    signals: Mapping[str, np.ndarray]
    units: Mapping[str, str]
    sample_rate: float
    parameters: Mapping[str, Any]
    model_name: str = ""
    guid: str = ""
    fmu_sha256: str = ""
    types: Mapping[str, str] = field(default_factory=dict)
    enumerations: Mapping[str, Mapping[str, int]] = field(default_factory=dict)
    ended_by_fmu: bool = False
    end_reason: str = ""

    def __post_init__(self) -> None:
        time = np.asarray(self.time, dtype=np.float64)
        if time.ndim != 1:
            raise ValueError(f"time must be 1-D, got shape {time.shape}")
        signals: dict[str, np.ndarray] = {}
        for name, values in self.signals.items():
            arr = _channel_array(values)
            if arr.shape != time.shape:
                raise ValueError(
                    f"signal '{name}' has shape {arr.shape}, expected {time.shape} like time"
                )
            signals[name] = arr
        units = {name: str(self.units.get(name, "")) for name in signals}
        # Frozen dataclass: normalise the fields once, here, via object.__setattr__.
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "signals", signals)
        object.__setattr__(self, "units", units)
        object.__setattr__(self, "sample_rate", float(self.sample_rate))
        object.__setattr__(self, "parameters", dict(self.parameters))
        object.__setattr__(self, "types", {n: str(t) for n, t in self.types.items() if n in signals})
        object.__setattr__(self, "enumerations", {n: {str(k): int(v) for k, v in items.items()}
                                                  for n, items in self.enumerations.items() if n in signals})
        object.__setattr__(self, "ended_by_fmu", bool(self.ended_by_fmu))
        object.__setattr__(self, "end_reason", str(self.end_reason))

    @property
    def channels(self) -> tuple[str, ...]:
        """Channel names in output order."""
        return tuple(self.signals)

    def __getitem__(self, name: str) -> np.ndarray:
        """Samples of channel ``name``, shape (n,).

        Raises
        ------
        KeyError
            If there is no such channel; the message lists the available ones.
        """
        try:
            return self.signals[name]
        except KeyError:
            available = ", ".join(self.signals) or "(none)"
            raise KeyError(f"no channel '{name}'; available: {available}") from None

    def __len__(self) -> int:
        """Number of samples n."""
        return int(self.time.shape[0])

    def to_dataframe(self) -> pandas.DataFrame:
        """Return a DataFrame with a ``time`` column [s] followed by one column per channel."""
        import pandas as pd

        return pd.DataFrame({"time": self.time, **self.signals})


def _suffix_kind(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix in HDF5_SUFFIXES:
        return "hdf5"
    if suffix in CSV_SUFFIXES:
        return "csv"
    accepted = ", ".join(HDF5_SUFFIXES + CSV_SUFFIXES)
    raise OutputPathError(
        f"unsupported result file suffix '{path.suffix}' for '{path}'; accepted: {accepted}"
    )


def check_output_path(path: str | os.PathLike[str]) -> Path:
    """Validate a result path before an expensive run: known suffix and existing directory.

    Raises
    ------
    OutputPathError
        Unknown suffix (message names it and the accepted ones) or missing
        parent directory.
    """
    target = Path(path)
    _suffix_kind(target)
    return check_parent(target)


def check_hdf5_path(path: str | os.PathLike[str], what: str) -> Path:
    """Like :func:`check_output_path` for files that only exist as HDF5 (``what`` names them:
    "a degradation run", "an archive"): any other suffix, ``.csv`` included, is refused by name."""
    target = Path(path)
    if target.suffix.lower() not in HDF5_SUFFIXES:
        raise OutputPathError(f"{what} writes HDF5: '{target}' must end in {' or '.join(HDF5_SUFFIXES)} "
                              f"(not '{target.suffix}')")
    return check_parent(target)


def write_result(result: SimulationResult, path: str | os.PathLike[str], *,
                 hdf5_extra: "Callable[[Any], None] | None" = None,
                 csv_extra: Mapping[str, Any] | None = None) -> Path:
    """Write ``result`` as HDF5 (``.h5``/``.hdf5``) or CSV (``.csv``), chosen by suffix.

    ``hdf5_extra(h5file)`` adds groups to an HDF5 file; ``csv_extra`` adds keys to a CSV's
    sidecar (a scenario run stores its scenario and events either way).  Returns the written
    path.  Raises :class:`OutputPathError` for any other suffix.
    """
    target = check_output_path(path)
    if _suffix_kind(target) == "hdf5":
        return write_hdf5(result, target, extra=hdf5_extra)
    return write_csv(result, target, extra=csv_extra)


def read_result(path: str | os.PathLike[str]) -> SimulationResult:
    """Read a file written by :func:`write_result`, chosen by suffix."""
    source = Path(path)
    if _suffix_kind(source) == "hdf5":
        return read_hdf5(source)
    return read_csv(source)


def _dataset_key(name: str) -> str:
    # '/' would create nested groups in HDF5; escape '%' first so decoding is unambiguous.
    return name.replace("%", "%25").replace("/", "%2F")


def _param_value(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    return value.decode("utf-8") if isinstance(value, bytes) else value


def _hdf5_attr(value: Any) -> Any:
    """A parameter value as an HDF5 attribute (an integer beyond int64 as uint64)."""
    value = _param_value(value)
    if isinstance(value, bool):
        return np.bool_(value)
    if isinstance(value, int) and value > np.iinfo(np.int64).max:
        return np.uint64(value)
    return value


def _is_text(values: np.ndarray) -> bool:
    return values.dtype.kind == "O"


def write_hdf5(result: SimulationResult, path: str | os.PathLike[str], *,
               extra: "Callable[[Any], None] | None" = None) -> Path:
    """Write ``result`` to an HDF5 file with the layout in the module docstring.

    ``extra(h5file)``, if given, adds further groups inside the same atomic write (the
    orchestrator stores the scenario and degradation stages this way). Returns the written
    path; the write is atomic.
    """
    import h5py

    target = Path(path)
    n = len(result)
    # h5py refuses a chunk larger than a fixed-size dataset, and an empty one cannot be chunked.
    filters: dict[str, Any] = (
        {"chunks": (min(n, 65536),), "compression": "gzip", "compression_opts": _GZIP_LEVEL,
         "shuffle": True}
        if n > 0 else {}
    )
    text = h5py.string_dtype("utf-8")
    with atomic_path(target) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["model_name"] = result.model_name
            f.attrs["guid"] = result.guid
            f.attrs["fmu_sha256"] = result.fmu_sha256
            f.attrs["sample_rate"] = result.sample_rate
            f.attrs["ended_by_fmu"] = result.ended_by_fmu
            f.attrs["end_reason"] = result.end_reason
            time = f.create_dataset("time", data=result.time, dtype="f8", **filters)
            time.attrs["unit"] = "s"
            group = f.create_group("signals", track_order=True)
            for name, values in result.signals.items():
                if _is_text(values):
                    ds = group.create_dataset(_dataset_key(name), data=values.astype(object), dtype=text)
                else:
                    ds = group.create_dataset(_dataset_key(name), data=values, dtype=values.dtype, **filters)
                ds.attrs["name"] = name
                ds.attrs["unit"] = result.units.get(name, "")
                ds.attrs["sample_rate"] = result.sample_rate
                if name in result.types:
                    ds.attrs["fmi_type"] = result.types[name]
                if name in result.enumerations:
                    ds.attrs["items"] = json.dumps(result.enumerations[name])
            params = f.create_group("parameters", track_order=True)
            for name, value in result.parameters.items():
                params.attrs[name] = _hdf5_attr(value)
            if extra is not None:
                extra(f)
    return target


def _attr_str(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def read_hdf5(path: str | os.PathLike[str]) -> SimulationResult:
    """Read a result written by :func:`write_hdf5`.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    OutputPathError
        If the file is not a gear-twin result or has an unknown format version.
    """
    import h5py

    source = Path(path)
    if not source.is_file():
        raise FileNotFoundError(f"result file '{source}' does not exist")
    with h5py.File(source, "r") as f:
        fmt = _attr_str(f.attrs.get("format", ""))
        version = f.attrs.get("format_version")
        if fmt != FORMAT:
            raise OutputPathError(f"'{source}' is not a {FORMAT} file (format={fmt!r})")
        if version != FORMAT_VERSION:
            raise OutputPathError(
                f"'{source}' has {FORMAT} format_version {version!r}; "
                f"this reader understands {FORMAT_VERSION}"
            )
        signals: dict[str, np.ndarray] = {}
        units: dict[str, str] = {}
        types: dict[str, str] = {}
        enumerations: dict[str, dict[str, int]] = {}
        for key, ds in f["signals"].items():
            name = _attr_str(ds.attrs.get("name", key))
            signals[name] = ds.asstr()[()] if h5py.check_string_dtype(ds.dtype) else ds[()]
            units[name] = _attr_str(ds.attrs.get("unit", ""))
            if "fmi_type" in ds.attrs:
                types[name] = _attr_str(ds.attrs["fmi_type"])
            if "items" in ds.attrs:
                enumerations[name] = json.loads(_attr_str(ds.attrs["items"]))
        parameters = {k: _param_value(v) for k, v in f["parameters"].attrs.items()}
        return SimulationResult(
            time=f["time"][()],
            signals=signals,
            units=units,
            sample_rate=float(f.attrs["sample_rate"]),
            parameters=parameters,
            model_name=_attr_str(f.attrs.get("model_name", "")),
            guid=_attr_str(f.attrs.get("guid", "")),
            fmu_sha256=_attr_str(f.attrs.get("fmu_sha256", "")),
            types=types,
            enumerations=enumerations,
            ended_by_fmu=bool(f.attrs.get("ended_by_fmu", False)),
            end_reason=_attr_str(f.attrs.get("end_reason", "")),
        )


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
