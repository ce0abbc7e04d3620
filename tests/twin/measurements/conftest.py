"""Builders of small synthetic measurement files (HDF5 by hand, CSV + sidecar)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

FS = 10_000.0          # Hz, default rate of the synthetic records
N = 2_000              # samples, 0.2 s at FS


def noisy(seed: int = 0, n: int = N) -> np.ndarray:
    """Seeded float64 vibration-like signal, (n,): tone plus Gaussian noise (never clipped)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    return np.sin(2 * np.pi * 480.0 * t) + 0.3 * rng.standard_normal(n)


def _write_h5(path: Path, records: dict, *, fmt: str | None = "gear-twin-measurements", version=1,
              root: dict | None = None) -> Path:
    """records: name -> {"channels": {name: (data, unit or None)}, "attrs": {...}}."""
    import h5py
    with h5py.File(path, "w", track_order=True) as f:
        if fmt is not None:
            f.attrs["format"] = fmt
        if version is not None:
            f.attrs["format_version"] = version
        for k, v in (root or {}).items():
            f.attrs[k] = v
        grp = f.create_group("records", track_order=True)
        for name, spec in records.items():
            g = grp.create_group(name, track_order=True)
            for k, v in spec.get("attrs", {}).items():
                g.attrs[k] = v
            for c, (data, unit) in spec.get("channels", {}).items():
                ds = g.create_dataset(c, data=data)
                if unit is not None:
                    ds.attrs["unit"] = unit
    return path


def _write_csv(path: Path, columns: dict, sidecar: dict | None, *, kind: str = "yaml",
               time=None, fs: float = FS) -> Path:
    """CSV with a full-precision time column; sidecar written as <file>.<kind> unless None."""
    n = len(next(iter(columns.values())))
    t = np.arange(n) / fs if time is None else np.asarray(time)
    names = ["time", *columns]
    lines = [",".join(names)]
    for i in range(n):
        cells = [repr(float(t[i]))] + [c if isinstance(c, str) else repr(float(c))
                                       for c in (columns[k][i] for k in columns)]
        lines.append(",".join(cells))
    path.write_text("\n".join(lines) + "\n")
    if sidecar is not None:
        side = Path(f"{path}.{kind}")
        side.write_text(json.dumps(sidecar) if kind == "json" else yaml.safe_dump(sidecar))
    return path


@pytest.fixture
def write_h5():
    return _write_h5


@pytest.fixture
def write_csv():
    return _write_csv


@pytest.fixture
def good_h5(tmp_path) -> Path:
    """Two labelled records, one accelerometer in g, one in m/s2, plus a pulse tachometer."""
    tach = (np.arange(N) % 500 < 5).astype(float) * 5.0          # 20 Hz once-per-rev, 5 V pulses
    recs = {
        "run_a": {"channels": {"accel": (noisy(1), "g"), "tacho": (tach, "V")},
                  "attrs": {"sample_rate": FS, "nominal_speed": 20.0, "load": 20.0, "label": 0,
                            "damage": 0.01, "tachometer": "tacho", "tachometer_kind": "pulse",
                            "operator": "rig-2"}},
        "run_b": {"channels": {"accel": (noisy(2), "m/s2"), "tacho": (tach, "V")},
                  "attrs": {"sample_rate": FS, "nominal_speed": 20.5, "load": 19.0, "label": 1,
                            "damage": 0.05, "tachometer": "tacho", "tachometer_kind": "pulse",
                            "pulses_per_rev": 1, "time_start": 1.5}},
    }
    return _write_h5(tmp_path / "good.h5", recs, root={"rig": "FZG-like"})
