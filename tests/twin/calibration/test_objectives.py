"""Calibration objectives (paper Eq. 2) on signals with known answers."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration.objectives import (estimate_shaft_hz, frequency_mismatch, match_modes, spectrum_mismatch,
                                         waveform_mismatch)

FS = 20_000.0


def _gear_signal(shaft_hz, phase=0.0, n=40_000, noise=0.0, seed=0):
    """Mesh harmonics 19x, 38x and a 1x line; ``phase`` [rad] is a shift of the shaft angle."""
    t = np.arange(n) / FS
    x = (np.sin(2 * np.pi * 19 * shaft_hz * t + 19 * phase) + 0.3 * np.sin(2 * np.pi * 38 * shaft_hz * t + 38 * phase)
         + 0.2 * np.sin(2 * np.pi * shaft_hz * t + phase))
    return x + noise * np.random.default_rng(seed).standard_normal(n)


def test_waveform_mismatch_ignores_phase_and_sees_shape():
    a = _gear_signal(20.0)
    assert waveform_mismatch(a, _gear_signal(20.0, phase=1.3), FS, 20.0) < 1e-3
    t = np.arange(a.size) / FS
    other = np.sin(2 * np.pi * 7 * 20.0 * t)
    assert waveform_mismatch(a, other, FS, 20.0) > 0.5


def test_spectrum_mismatch_zero_for_same_spectrum_large_for_other():
    a = _gear_signal(20.0, noise=0.01)
    assert spectrum_mismatch(a, _gear_signal(20.0, phase=0.7, noise=0.01, seed=1), FS, fmax=2000) < 0.05
    assert spectrum_mismatch(a, _gear_signal(27.0, noise=0.01), FS, fmax=2000) > 0.3


def test_mode_matching_survives_a_missing_model_mode():
    measured = np.array([22.0, 87.0, 218.0, 430.0])
    model = np.array([21.0, 60.0, 88.0, 215.0, 433.0, 600.0])   # 60 Hz has no measured partner
    idx = match_modes(model, measured)
    assert list(model[idx]) == [21.0, 88.0, 215.0, 433.0]
    assert frequency_mismatch(model, measured) == pytest.approx(1 + 1 + 9 + 9)
    with pytest.raises(ValueError):
        match_modes(model[:2], measured)


def test_shaft_speed_from_the_mesh_line_sees_motor_slip():
    x = _gear_signal(19.61, n=60_000)
    assert estimate_shaft_hz(x, FS, 20.0, 19) == pytest.approx(19.61, abs=0.01)
