"""twin.signals.envelope: the squared-envelope spectrum and the harmonic series it holds."""
from __future__ import annotations

import numpy as np
import pytest

from twin.signals import SignalError
from twin.signals.envelope import envelope_series, octave_bands, squared_envelope_spectrum

FS = 50000.0
SHAFT = 20.0                  # pinion [Hz]
RATIO = 19 / 52
BPFO = 3.585 * SHAFT          # a non-integer order, as an outer race's passage


def _gears(n, rng):
    """A gear signal: mesh harmonics with first pinion and gear sidebands, and broadband noise."""
    t = np.arange(n) / FS
    x = np.zeros(n)
    for k in range(1, 12):
        fk = 19 * SHAFT * k
        x += np.sin(2 * np.pi * fk * t + rng.uniform(0, 6.3)) / k
        for fs_ in (SHAFT, SHAFT * RATIO):
            for s in (-1, 1):
                x += 0.1 / k * np.sin(2 * np.pi * (fk + s * fs_) * t + rng.uniform(0, 6.3))
    return x + 0.3 * rng.standard_normal(n)


def _impacts(n, rate_hz, rng, *, jitter=0.01, mode_hz=9000.0, size=3.0):
    """Decaying 9 kHz ring-downs at ``rate_hz`` with a 1 % random slip of the spacing."""
    x = np.zeros(n)
    ring = np.exp(-np.arange(200) / 30.0) * np.sin(2 * np.pi * mode_hz * np.arange(200) / FS)
    t = 0.0
    while True:
        t += (1.0 + jitter * rng.standard_normal()) / rate_hz
        i = int(t * FS)
        if i + ring.size >= n:
            return x
        x[i:i + ring.size] += size * ring


def test_a_modulated_carrier_gives_the_known_envelope_line():
    """(1 + m cos(w t))^2 holds 2 m at the modulation frequency: the line's amplitude is 2 m A^2."""
    t = np.arange(int(FS)) / FS
    a, m = 2.0, 0.2
    x = a * (1 + m * np.cos(2 * np.pi * 37.0 * t)) * np.sin(2 * np.pi * 5000.0 * t)
    f, amp = squared_envelope_spectrum(x, FS, (4000.0, 6000.0), fmax=200.0)
    j = np.argmax(amp[f > 5])
    assert f[f > 5][j] == pytest.approx(37.0, abs=0.1)
    assert amp[f > 5][j] == pytest.approx(2 * m * a ** 2, rel=0.02)
    assert f[-1] <= 200.0


def test_a_bearing_series_is_found_unlocked_and_a_tooth_fault_locked():
    rng = np.random.default_rng(3)
    n = int(2 * FS)
    healthy = _gears(n, rng)
    assert [s for s in envelope_series(healthy, FS, SHAFT, gear_ratio=RATIO) if s.locked_to is None] == []

    bearing = envelope_series(healthy + _impacts(n, BPFO, rng), FS, SHAFT, gear_ratio=RATIO)
    top = bearing[0]
    assert top.locked_to is None and top.order == pytest.approx(3.585, abs=0.01)
    assert top.harmonics >= 3 and top.band_hz[0] <= 9000.0 <= top.band_hz[1]

    tooth = envelope_series(healthy + _impacts(n, SHAFT, rng, jitter=0.0), FS, SHAFT, gear_ratio=RATIO)
    assert tooth[0].locked_to == "pinion" and tooth[0].order == pytest.approx(1.0, abs=0.01)
    assert all(s.locked_to is not None for s in tooth)


def test_bands_and_bad_input():
    assert octave_bands(20480.0) == ((1000.0, 2000.0), (2000.0, 4000.0), (4000.0, 8000.0), (8000.0, 9216.0))
    x = np.random.default_rng(0).standard_normal(4096)
    with pytest.raises(SignalError, match="Nyquist"):
        squared_envelope_spectrum(x, 10000.0, (4000.0, 6000.0))
    with pytest.raises(SignalError, match="fmin=3000"):
        squared_envelope_spectrum(x, 10000.0, (3000.0, 2000.0))
    with pytest.raises(SignalError, match="fmax"):
        squared_envelope_spectrum(x, 10000.0, (2000.0, 3000.0), fmax=0.0)
    with pytest.raises(SignalError, match="shaft_hz"):
        envelope_series(x, 10000.0, -20.0)
    x[7] = np.nan
    with pytest.raises(SignalError, match="sample 7"):
        envelope_series(x, 10000.0, 20.0)
