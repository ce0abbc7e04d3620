"""The archive diagnostics' energy split: mesh lines, their shaft-order sidebands, and the rest."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parents[2] / "bench"
sys.path.insert(0, str(BENCH))
_spec = importlib.util.spec_from_file_location("archive_diagnostics", BENCH / "archive_diagnostics.py")
ad = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ad)


def test_energy_split_by_hand():
    fs, f0 = 10240.0, 10.0
    t = np.arange(int(2 * fs)) / fs
    rng = np.random.default_rng(0)
    # two mesh harmonics (190, 380 Hz), a sideband 2 orders off the first, a line at 1234.5 Hz
    # that is neither, and a little noise
    x = (1.0 * np.cos(2 * np.pi * 190 * t) + 0.5 * np.cos(2 * np.pi * 380 * t)
         + 0.1 * np.cos(2 * np.pi * 210 * t) + 0.3 * np.cos(2 * np.pi * 1234.5 * t)
         + 1e-4 * rng.standard_normal(t.size))
    line, side, rest = ad.energy_split(x, fs, f0)
    # powers add: lines 1 + 0.25, sideband 0.01, the stray line 0.09 (equal windows, equal factor)
    np.testing.assert_allclose(line - side, 10 * np.log10(1.25 / 0.01), atol=0.3)
    np.testing.assert_allclose(line - rest, 10 * np.log10(1.25 / 0.09), atol=0.3)
