"""Poly-reference LSCF: close modes one FRF hump hides, hammer FRF matrices, bad input."""
from __future__ import annotations

import numpy as np
import pytest

from twin.signals import SignalError, modal_peaks
from twin.signals.impact import hammer_frf_matrix
from twin.signals.lscf import BAND_OVERLAP, lscf_modes, sub_bands

#: Two lateral modes of one shaft 2.2 % apart (their half-power bands overlap) and two more.
MODES = ((584.0, 0.015), (597.0, 0.012), (900.0, 0.02), (1200.0, 0.01))


def frf_matrix(f, shapes, participation, noise: float, seed: int):
    """Displacement FRFs (n_f, n_out, n_ref) [m/N] of MODES, ``shapes`` (n_modes, n_out) at the
    sensors, ``participation`` (n_modes, n_ref) at the struck points, plus complex noise of
    ``noise`` x the median magnitude."""
    w = 2 * np.pi * np.asarray(f)[:, None, None]
    H = np.zeros((len(f), shapes.shape[1], participation.shape[1]), complex)
    for (fn, zeta), phi, ell in zip(MODES, shapes, participation):
        wn = 2 * np.pi * fn
        H += np.outer(phi, ell)[None] / (wn**2 - w**2 + 2j * zeta * wn * w)
    rng = np.random.default_rng(seed)
    scale = noise * np.median(np.abs(H))
    return H + scale * (rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape))


def test_two_references_separate_the_close_pair_one_peak_hides():
    rng = np.random.default_rng(0)
    f = np.arange(1.0, 2000.0, 1.0)
    H = frf_matrix(f, rng.standard_normal((4, 2)), rng.standard_normal((4, 2)), 0.02, seed=1)
    found = lscf_modes(f, H, None, 300.0, 1600.0)
    for fn, zeta in MODES:
        near = [m for m in found if abs(m.frequency - fn) < 0.003 * fn]
        assert len(near) == 1, (fn, [m.frequency for m in found])
        assert abs(near[0].damping - zeta) < 0.15 * zeta
    assert len(found) == len(MODES)
    # what peak picking reads in any one of the four FRFs: at most one mode for the pair
    for o in range(2):
        for r in range(2):
            peaks, _ = modal_peaks(f, H[:, o, r], n=20, fmin=300.0, fmax=1600.0)
            assert np.sum((peaks > 570) & (peaks < 610)) <= 1


def test_noise_alone_gives_no_mode():
    rng = np.random.default_rng(2)
    f = np.arange(1.0, 2000.0, 1.0)
    H = rng.standard_normal((f.size, 2, 2)) + 1j * rng.standard_normal((f.size, 2, 2))
    assert lscf_modes(f, H, None, 100.0, 1800.0) == []


def test_sub_bands_cover_the_band_with_overlap():
    bands = sub_bands(20.0, 5000.0)
    assert bands[0][0] == 20.0 and bands[-1][1] == 5000.0
    for fq in np.geomspace(40.0, 2500.0, 25):
        assert sum(lo <= fq <= hi for lo, hi in bands) >= BAND_OVERLAP
    with pytest.raises(SignalError, match="0 < fmin < fmax"):
        sub_bands(100.0, 50.0)


def test_frf_shape_mismatch_is_named():
    with pytest.raises(SignalError, match="the FRFs have 3 frequencies, f has 4"):
        lscf_modes(np.arange(1.0, 5.0), np.ones((3, 1, 1)), None, 1.0, 4.0)


def test_hammer_frf_matrix_of_two_struck_points(hammer_factory):
    rng = np.random.default_rng(4)
    shapes, part = rng.standard_normal((4, 2)), rng.standard_normal((4, 2))
    fs = 10_000.0
    tests = [hammer_factory(MODES, [shapes[:, o] * part[:, r] for o in range(2)], fs, 4.0, seed=r) for r in range(2)]
    f, H, coh, top = hammer_frf_matrix(tests, fs)
    assert H.shape == (f.size, 2, 2) and coh.shape == H.shape and top > 1600.0
    found = lscf_modes(f, H, coh, 300.0, 1600.0)
    assert all(any(abs(m.frequency - fn) < 0.005 * fn for m in found) for fn, _ in MODES)
    with pytest.raises(SignalError, match="same response channels"):
        hammer_frf_matrix([tests[0], (tests[1][0], tests[1][1][:1])], fs)
    with pytest.raises(SignalError, match="unknown FRF estimator 'H3'"):
        hammer_frf_matrix(tests, fs, estimator="H3")
