"""Tiny synthetic vibration records for the transfer tests (no FMU, seconds to train).

Stage k of the source is a 60 Hz "mesh" tone with a harmonic whose amplitude grows with k, plus
noise, sampled at 1 kHz; windows are 64 samples.  The "rig" (target) sees the same stages through
a different transfer path: a strong 170 Hz hum the twin does not have, a 3x sensor gain and more
noise.
"""
from __future__ import annotations

import numpy as np
import pytest

from twin.measurements import Record
from twin.transfer import Augmentation, Preprocessing

FS = 1000.0
CH = "accel_pinion_casing"


def make_records(n_per_stage: int, stages: int = 3, *, shifted: bool = False, seed: int = 0,
                 duration: float = 0.384, labelled: bool = True, channel: str = CH) -> list[Record]:
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * FS)) / FS
    out = []
    for k in range(stages):
        for i in range(n_per_stage):
            ph = rng.uniform(0, 2 * np.pi, 3)
            x = np.sin(2 * np.pi * 60 * t + ph[0]) + 0.6 * k * np.sin(2 * np.pi * 180 * t + ph[1])
            x = x * (1 + 0.5 * k)
            x = x + rng.normal(0, 0.3, t.size)
            if shifted:
                x = 3.0 * (x + 2.0 * np.sin(2 * np.pi * 170 * t + ph[2])) + rng.normal(0, 0.5, t.size)
            out.append(Record(f"s{k}r{i}", {channel: x}, {channel: "m/s2"}, FS,
                              label=k if labelled else None))
    return out


@pytest.fixture(scope="session")
def tiny_pre() -> Preprocessing:
    return Preprocessing(sample_rate=FS, window=64, hop=32)


@pytest.fixture(scope="session")
def tiny_data():
    """(source, target adaptation (unlabelled), target test (labelled))."""
    return (make_records(10, seed=1), make_records(8, shifted=True, seed=2, labelled=False),
            make_records(8, shifted=True, seed=3))


def tiny_assessor(method: str, pre: Preprocessing, seed: int = 0, epochs: int = 6, **kw):
    from twin.transfer import Assessor
    return Assessor(method, preprocessing=pre, epochs=epochs, seed=seed, batch_size=20, progress=False,
                    augmentation=Augmentation(noise=0.05, gain=0.05, speed_jitter=0.0), warmup_epochs=2, **kw)


# ---- archives for the ensemble: the settings follow from the archive's test (2048-sample windows) ----
ARCHIVE_FS = 20480.0        # the lubricated test's rate: 1024 x 20 Hz, so nothing is resampled


def stage_signal(k: int, n: int, rng, *, fs: float = ARCHIVE_FS, gain: float = 1.0, mesh: float = 380.0):
    """A 'mesh' tone and harmonic growing with stage k, plus noise."""
    t = np.arange(n) / fs
    x = (1 + 0.5 * k) * np.sin(2 * np.pi * mesh * t) + 0.4 * k * np.sin(2 * np.pi * 2 * mesh * t + 0.3)
    return gain * (x + rng.normal(0, 0.2, n))


def write_tiny_archive(path, stages: int = 3, per_stage: int = 4, n: int = 6144, seed: int = 0,
                       scenario: str = "lubricated.yaml"):
    """A gear-twin archive of the shipped scenario's test with synthetic signals; returns its path."""
    from pathlib import Path

    from twin.archive import Archive, write_archive
    from twin.scenario import load_scenario
    sc = load_scenario(Path(__file__).resolve().parents[3] / "scenarios" / scenario)
    rng = np.random.default_rng(seed)
    labels = np.repeat(np.arange(stages), per_stage)
    bounds = tuple(float(b) for b in np.linspace(0.0, 0.03 * stages, stages + 1))
    sig = np.stack([stage_signal(int(k), n, rng) for k in labels]).astype(np.float32)
    speed = 20.0 if scenario == "lubricated.yaml" else 10.0
    arc = Archive(labels, labels * 0.03 + 0.01, np.full(labels.size, speed), np.full(labels.size, 20.0),
                  {CH: sig}, ARCHIVE_FS, bounds, "pitting_density" if scenario == "lubricated.yaml" else "wear_depth")
    write_archive(arc, Path(path), sc)
    return Path(path)


def rig_records(stages: int = 3, per_stage: int = 3, n: int = 12500, seed: int = 1, *, fs: float = 25000.0,
                speed: float = 20.0, load: float = 20.0, timed: bool = False, labelled: bool = True,
                order=None) -> list[Record]:
    """A rig's records of the same stages at another rate, gain and mesh frequency (1 % off)."""
    rng = np.random.default_rng(seed)
    ks = np.repeat(np.arange(stages), per_stage) if order is None else np.asarray(order)
    return [Record(f"rec{i:02d}", {CH: stage_signal(int(k), n, rng, fs=fs, gain=2.5, mesh=383.8)}, {CH: "m/s2"}, fs,
                   nominal_speed=speed, load=load, label=int(k) if labelled else None,
                   time_start=float(3600 * i) if timed else 0.0) for i, k in enumerate(ks)]
