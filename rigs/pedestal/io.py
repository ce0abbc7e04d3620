"""The rig's own writer of the measurement format (``twin/measurements/README.md``, version 1).

Records go to ``/records/<name>`` with one float64 dataset per channel (attribute ``unit``) and
the record attributes; the root carries ``format = "gear-twin-measurements"``,
``format_version = 1`` and the simulator's name. What only the rig knows goes to
``<file>.truth.json`` beside it. Both files are written to a temporary name and moved into place,
so an interrupted write leaves any earlier file untouched.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import h5py
import numpy as np

from .rig import VERSION

FORMAT = "gear-twin-measurements"
FORMAT_VERSION = 1
UNITS = ("m/s2", "g", "m/s", "m", "rad", "rad/s", "N", "N.m", "V", "Hz", "1")


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj)
    if isinstance(obj, (np.integer, int)) and not isinstance(obj, bool):
        return int(obj)
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    return obj


def truth_path(path) -> Path:
    p = Path(path)
    return p.with_name(p.name + ".truth.json")


def write(path, records, metadata: dict | None = None) -> Path:
    """Write ``records`` (RigRecord objects) to ``path`` (.h5/.hdf5) and the truth file."""
    path = Path(path)
    if path.suffix.lower() not in (".h5", ".hdf5"):
        raise ValueError(f"measurement file must end in .h5 or .hdf5, got {str(path)!r}")
    records = list(records)
    if not records:
        raise ValueError("no records to write")
    names = [r.name for r in records]
    if len(set(names)) != len(names):
        raise ValueError(f"record names must be unique, got {names!r}")
    for r in records:
        if "/" in r.name or not r.name:
            raise ValueError(f"bad record name {r.name!r}")
        for ch, unit in r.units.items():
            if unit not in UNITS:
                raise ValueError(f"record {r.name!r} channel {ch!r}: unit {unit!r} not in {UNITS}")
    if not path.parent.is_dir():
        raise FileNotFoundError(f"output directory does not exist: {str(path.parent)!r}")
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp_truth = path.with_name(f".{path.name}.truth.{os.getpid()}.tmp")
    try:
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["simulator"] = VERSION
            for k, v in (metadata or {}).items():
                f.attrs[k] = v
            grp = f.create_group("records", track_order=True)
            for r in records:
                g = grp.create_group(r.name)
                g.attrs["sample_rate"] = float(r.sample_rate)
                for k, v in r.attributes.items():
                    g.attrs[k] = v
                for ch, data in r.channels.items():
                    d = g.create_dataset(ch, data=np.asarray(data, dtype=np.float64),
                                         compression="gzip", compression_opts=4, shuffle=True)
                    d.attrs["unit"] = r.units[ch]
        truth = {"simulator": VERSION, "file": path.name,
                 "records": {r.name: _jsonable(r.truth) for r in records}}
        tmp_truth.write_text(json.dumps(truth, indent=1))
        os.replace(tmp, path)
        os.replace(tmp_truth, truth_path(path))
    finally:
        for t in (tmp, tmp_truth):
            if t.exists():
                t.unlink()
    return path


def read_truth(path) -> dict:
    """The truth file written beside ``path``."""
    return json.loads(truth_path(path).read_text())
