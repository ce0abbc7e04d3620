"""Simulation results: the in-memory container, and the choice of file format by suffix.

:class:`SimulationResult` holds one run's sampled outputs; :func:`write_result` and
:func:`read_result` write and read it as HDF5 (``.h5``/``.hdf5``, :mod:`twin.results_hdf5`) or as
CSV with a JSON sidecar (``.csv``, :mod:`twin.results_csv`), whose modules give the file layouts
(``format="gear-twin-result"``, ``format_version=1``).  ``write_hdf5``, ``read_hdf5``,
``write_csv`` and ``read_csv`` are importable from here too; they are loaded on first use, so this
module imports neither format's code.

Every file is written atomically (see :mod:`twin._atomic`).
"""
from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from twin._atomic import check_parent
from twin.errors import OutputPathError

if TYPE_CHECKING:
    import pandas

FORMAT = "gear-twin-result"
FORMAT_VERSION = 1
HDF5_SUFFIXES = (".h5", ".hdf5")
CSV_SUFFIXES = (".csv",)


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


def _param_value(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    return value.decode("utf-8") if isinstance(value, bytes) else value


def _is_text(values: np.ndarray) -> bool:
    return values.dtype.kind == "O"


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
        from twin.results_hdf5 import write_hdf5
        return write_hdf5(result, target, extra=hdf5_extra)
    from twin.results_csv import write_csv
    return write_csv(result, target, extra=csv_extra)


def read_result(path: str | os.PathLike[str]) -> SimulationResult:
    """Read a file written by :func:`write_result`, chosen by suffix."""
    source = Path(path)
    if _suffix_kind(source) == "hdf5":
        from twin.results_hdf5 import read_hdf5
        return read_hdf5(source)
    from twin.results_csv import read_csv
    return read_csv(source)


# The writers and readers of each format, importable from here (``from twin.results import
# read_hdf5``) but loaded on first use: their modules import this one for the container.
_FILE_FUNCTIONS = {"write_hdf5": "twin.results_hdf5", "read_hdf5": "twin.results_hdf5",
                   "write_csv": "twin.results_csv", "read_csv": "twin.results_csv"}


def __getattr__(name: str):
    if name in _FILE_FUNCTIONS:
        return getattr(importlib.import_module(_FILE_FUNCTIONS[name]), name)
    raise AttributeError(f"module 'twin.results' has no attribute {name!r}")

