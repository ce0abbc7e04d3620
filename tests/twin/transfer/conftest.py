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
