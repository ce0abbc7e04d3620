"""A synthetic run-up of a structure the twin does not model: a sum of modes driven by
broadband noise, speed-locked orders and a fixed, non-synchronous drive line, plus sensor noise.

Known answers for :mod:`twin.signals.runup`: every mode, order and line is set here.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as sps


def _mode_filter(fn: float, zeta: float, fs: float):
    """Acceleration per unit force of one mode, s^2 / (s^2 + 2 zeta wn s + wn^2), by the bilinear
    transform pre-warped at fn (so the resonance sits exactly at fn)."""
    wn = 2 * np.pi * fn
    k = wn / np.tan(wn / (2 * fs))              # pre-warped 2*fs
    a0 = k * k + 2 * zeta * wn * k + wn * wn
    b = np.array([k * k, -2 * k * k, k * k]) / a0
    a = np.array([1.0, (2 * wn * wn - 2 * k * k) / a0, (k * k - 2 * zeta * wn * k + wn * wn) / a0])
    return b, a


def synthetic_runup(*, fs=12800.0, duration=6.0, speeds=(2.0, 20.0),
                    modes=((87.0, 0.02), (218.0, 0.02), (430.0, 0.015), (512.0, 0.025), (767.0, 0.02),
                           (1248.0, 0.02), (1927.0, 0.03)),
                    orders=((1.0, 0.3), (2.0, 0.2), (19.0, 1.0), (38.0, 0.5), (57.0, 0.3), (19 / 52, 0.2)),
                    lines=((300.0, 3.0),), broadband=1.0, noise=0.02, seed=0, weights=None):
    """(x [m/s2], angle [rad], truth) of a run-up from speeds[0] to speeds[1] Hz.

    ``orders``: (shaft order, force amplitude at the top speed; grows with speed squared);
    ``lines``: (fixed frequency [Hz], force amplitude) of drive lines;
    ``broadband``: sd of the white force at the top speed (grows with speed);
    ``weights``: (channels, modes) weight of each mode at each channel; then x is (channels, n),
    each channel with its own noise.
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration * fs))
    t = np.arange(n) / fs
    speed = speeds[0] + (speeds[1] - speeds[0]) * t / duration
    angle = 2 * np.pi * np.cumsum(speed) / fs
    rel = speed / speeds[1]
    force = broadband * rel * rng.standard_normal(n)
    for order, amp in orders:
        force += amp * rel ** 2 * np.cos(order * angle + rng.uniform(0, 2 * np.pi))
    for f, amp in lines:
        force += amp * np.cos(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
    w = np.ones((1, len(modes))) if weights is None else np.asarray(weights, float)
    x = np.zeros((w.shape[0], n))
    for k, (fn, zeta) in enumerate(modes):
        b, a = _mode_filter(fn, zeta, fs)
        x += w[:, k:k + 1] * sps.lfilter(b, a, force)[None, :]
    x += noise * np.std(x, axis=1, keepdims=True) * rng.standard_normal(x.shape)
    x = x[0] if weights is None else x
    truth = {"modes": [m for m in modes], "orders": [o for o, _ in orders], "lines": [f for f, _ in lines]}
    return x, angle, truth


@pytest.fixture(scope="session")
def runup_factory():
    return synthetic_runup


def synthetic_hammer(modes, responses_per_force, fs: float, seconds: float, seed: int):
    """A hammer record: half-sine blows (0.3 ms, 100 N) every 0.25 s and the responses [m] to them,
    one per entry of ``responses_per_force`` (the residues of ``modes``, (fn [Hz], zeta) each), each a
    sum of damped modes plus 1 % noise. Returns (force (n,), [response (n,), ...])."""
    n = int(seconds * fs)
    t = np.arange(n) / fs
    force = np.zeros(n)
    pulse = np.sin(np.pi * np.arange(int(3e-4 * fs)) / int(3e-4 * fs))
    for start in range(int(0.02 * fs), n - pulse.size, int(0.25 * fs)):
        force[start:start + pulse.size] += 100.0 * pulse
    rng = np.random.default_rng(seed)
    out = []
    for residues in responses_per_force:
        h = np.zeros(n)
        for (fn, zeta), r in zip(modes, residues):
            wn = 2 * np.pi * fn
            wd = wn * np.sqrt(1 - zeta**2)
            h += r * np.exp(-zeta * wn * t) * np.sin(wd * t) / wd / fs
        y = np.fft.irfft(np.fft.rfft(force, 2 * n) * np.fft.rfft(h, 2 * n), 2 * n)[:n]
        out.append(y + 0.01 * np.std(y) * rng.standard_normal(n))
    return force, out


@pytest.fixture(scope="session")
def hammer_factory():
    return synthetic_hammer
