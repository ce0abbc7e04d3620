"""Simulation results: the in-memory container and its HDF5 / CSV files.

HDF5 layout (``format="gear-twin-result"``, ``format_version=1``)
-----------------------------------------------------------------
``/`` attributes
    ``model_name`` (str), ``guid`` (str, FMU GUID), ``fmu_sha256`` (str, hex
    digest of the FMU file), ``sample_rate`` (float, Hz), ``format`` (str),
    ``format_version`` (int).
``/time``
    1-D float64 dataset of sample times, attribute ``unit="s"``.
``/signals/<name>``
    One 1-D float64 dataset per channel, same length as ``/time``, gzip level 4,
    byte-shuffled and chunked; attributes ``name`` (the channel name, which is
    authoritative because ``/`` and ``%`` are percent-escaped in the dataset
    key), ``unit`` (str, ``''`` if dimensionless or unknown) and
    ``sample_rate`` (float, Hz). Channel order is preserved.
``/parameters``
    Group whose attributes map parameter name -> value (float).

CSV layout
----------
``<path>``
    Header ``time,<channel>,...`` (plain names, as fmpy writes and reads them;
    units are in the sidecar), then one row per sample, values printed with 17
    significant digits so a round trip is exact.
``<path>.json``
    Sidecar with ``format``, ``format_version``, ``model_name``, ``guid``,
    ``fmu_sha256``, ``sample_rate`` (Hz), ``channels`` (ordered names),
    ``units`` and ``parameters``.

Every file is written atomically (see :mod:`twin._atomic`).
"""
from __future__ import annotations

import csv
import io
import json
import os
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
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


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Sampled outputs of one simulation run.

    Attributes
    ----------
    time : numpy.ndarray, shape (n,)
        Sample times [s], float64.
    signals : Mapping[str, numpy.ndarray]
        Channel name -> samples, each shape (n,), float64, in output order.
    units : Mapping[str, str]
        Channel name -> unit string (``''`` if none).
    sample_rate : float
        Output sample rate [Hz] (1 / output interval).
    parameters : Mapping[str, float]
        Parameter values the run used, name -> value.
    model_name, guid, fmu_sha256 : str
        Provenance of the FMU that produced the data.

    Equality is identity (arrays have no single truth value); compare fields
    explicitly instead.
    """

    time: np.ndarray
    signals: Mapping[str, np.ndarray]
    units: Mapping[str, str]
    sample_rate: float
    parameters: Mapping[str, float]
    model_name: str = ""
    guid: str = ""
    fmu_sha256: str = ""

    def __post_init__(self) -> None:
        time = np.asarray(self.time, dtype=np.float64)
        if time.ndim != 1:
            raise ValueError(f"time must be 1-D, got shape {time.shape}")
        signals: dict[str, np.ndarray] = {}
        for name, values in self.signals.items():
            arr = np.asarray(values, dtype=np.float64)
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


def write_result(result: SimulationResult, path: str | os.PathLike[str]) -> Path:
    """Write ``result`` as HDF5 (``.h5``/``.hdf5``) or CSV (``.csv``), chosen by suffix.

    Returns the written path. Raises :class:`OutputPathError` for any other suffix.
    """
    target = check_output_path(path)
    if _suffix_kind(target) == "hdf5":
        return write_hdf5(result, target)
    return write_csv(result, target)


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
    return value.item() if isinstance(value, np.generic) else value


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
    with atomic_path(target) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["model_name"] = result.model_name
            f.attrs["guid"] = result.guid
            f.attrs["fmu_sha256"] = result.fmu_sha256
            f.attrs["sample_rate"] = result.sample_rate
            time = f.create_dataset("time", data=result.time, dtype="f8", **filters)
            time.attrs["unit"] = "s"
            group = f.create_group("signals", track_order=True)
            for name, values in result.signals.items():
                ds = group.create_dataset(_dataset_key(name), data=values, dtype="f8", **filters)
                ds.attrs["name"] = name
                ds.attrs["unit"] = result.units.get(name, "")
                ds.attrs["sample_rate"] = result.sample_rate
            params = f.create_group("parameters", track_order=True)
            for name, value in result.parameters.items():
                params.attrs[name] = _param_value(value)
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
        for key, ds in f["signals"].items():
            name = _attr_str(ds.attrs.get("name", key))
            signals[name] = ds[()]
            units[name] = _attr_str(ds.attrs.get("unit", ""))
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
        )


def _sidecar_path(path: Path) -> Path:
    return path.with_name(path.name + ".json")


def write_csv(result: SimulationResult, path: str | os.PathLike[str]) -> Path:
    """Write ``result`` as CSV plus a ``<path>.json`` metadata sidecar.

    Both files are written atomically, the CSV first, so a sidecar never
    describes data that are not there yet. Returns the CSV path.
    """
    target = Path(path)
    names = list(result.signals)
    header = io.StringIO()
    # Plain names, as fmpy writes and reads them (units are in the sidecar); csv.writer quotes
    # channel names containing commas or quotes.
    csv.writer(header, lineterminator="").writerow(["time", *names])
    table = np.column_stack([result.time, *(result.signals[n] for n in names)])
    with atomic_path(target) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            np.savetxt(fh, table, fmt="%.17g", delimiter=",", header=header.getvalue(),
                       comments="")
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "model_name": result.model_name,
        "guid": result.guid,
        "fmu_sha256": result.fmu_sha256,
        "sample_rate": result.sample_rate,
        "channels": names,
        "units": {n: result.units.get(n, "") for n in names},
        "parameters": {k: _param_value(v) for k, v in result.parameters.items()},
    }
    with atomic_path(_sidecar_path(target)) as tmp:
        tmp.write_text(json.dumps(meta, indent=2) + "\n", encoding="utf-8")
    return target


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
    return SimulationResult(
        time=table[:, 0],
        signals={n: table[:, i + 1] for i, n in enumerate(names)},
        units=meta.get("units", {}),
        sample_rate=meta["sample_rate"],
        parameters=meta.get("parameters", {}),
        model_name=meta.get("model_name", ""),
        guid=meta.get("guid", ""),
        fmu_sha256=meta.get("fmu_sha256", ""),
    )
