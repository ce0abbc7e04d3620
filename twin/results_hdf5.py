"""Simulation results as HDF5 files (:func:`write_hdf5`, :func:`read_hdf5`).

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

The file is written atomically (see :mod:`twin._atomic`).  :mod:`twin.results` holds the container
and chooses between this format and CSV (:mod:`twin.results_csv`) by suffix.
"""
from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from twin._atomic import atomic_path
from twin.errors import OutputPathError
from twin.results import FORMAT, FORMAT_VERSION, SimulationResult, _is_text, _param_value

__all__ = ["read_hdf5", "write_hdf5"]

_GZIP_LEVEL = 4


def _dataset_key(name: str) -> str:
    # '/' would create nested groups in HDF5; escape '%' first so decoding is unambiguous.
    return name.replace("%", "%25").replace("/", "%2F")


def _hdf5_attr(value: Any) -> Any:
    """A parameter value as an HDF5 attribute (an integer beyond int64 as uint64)."""
    value = _param_value(value)
    if isinstance(value, bool):
        return np.bool_(value)
    if isinstance(value, int) and value > np.iinfo(np.int64).max:
        return np.uint64(value)
    return value


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
