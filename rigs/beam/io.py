"""Writer of the measurement-format HDF5 file (twin/measurements/README.md, version 1) and
of the truth file beside it. Written here from the format description, atomically."""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import h5py
import numpy as np

from .params import VERSION


class WriteError(ValueError):
    """Records that cannot be written, or a bad output path."""


def _atomic(path: Path, writer):
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        writer(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    return x


def write(path, records) -> Path:
    """Write records to `path` (.h5/.hdf5) and their truth to `path` + '.truth.json'."""
    path = Path(path)
    if path.suffix not in (".h5", ".hdf5"):
        raise WriteError(f"output {str(path)!r} must end in .h5 or .hdf5")
    records = list(records)
    if not records:
        raise WriteError("no records to write")
    names = [r.name for r in records]
    if len(set(names)) != len(names):
        raise WriteError(f"duplicate record name {next(n for n in names if names.count(n) > 1)!r}")
    for n in names:
        if "/" in n or not n:
            raise WriteError(f"record name {n!r} is empty or contains '/'")

    def h5(tmp):
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = "gear-twin-measurements"
            f.attrs["format_version"] = 1
            f.attrs["source"] = VERSION
            grp = f.create_group("records")
            for r in records:
                g = grp.create_group(r.name)
                g.attrs["sample_rate"] = float(r.sample_rate)
                g.attrs["nominal_speed"] = float(r.nominal_speed)
                g.attrs["load"] = float(r.load)
                g.attrs["tachometer"] = r.tachometer
                g.attrs["tachometer_kind"] = "angle"
                for k, v in r.attributes.items():
                    g.attrs[k] = v
                for c, x in r.channels.items():
                    d = g.create_dataset(c, data=np.asarray(x, np.float64), compression="gzip",
                                         compression_opts=4, shuffle=True)
                    d.attrs["unit"] = r.units[c]

    def truth(tmp):
        with open(tmp, "w") as f:
            json.dump(_jsonable({"rig": VERSION, "file": path.name,
                                 "records": {r.name: r.truth for r in records}}), f, indent=1)

    _atomic(path, h5)
    os.chmod(path, 0o644)
    _atomic(Path(str(path) + ".truth.json"), truth)
    return path
