"""Which model modes a sensor shows: the dominance rule beside the peak search (synthetic modes)."""
from __future__ import annotations

import numpy as np
from scipy.signal import find_peaks

from twin.calibration.model_modes import DOMINANT_FLOOR, dominant_modes
from twin.linearize import ModalModel, frequency_response


def _modal(freqs, zetas, residues) -> ModalModel:
    """One output, one excitation; residue r_j of mode j (the response is r/(s - lam) + c.c.)."""
    f, z = np.asarray(freqs, float), np.asarray(zetas, float)
    wn = 2 * np.pi * f
    lam = -z * wn + 1j * wn * np.sqrt(1 - z ** 2)
    res = np.asarray(residues, complex)[None, None, :]
    gain = np.abs(res) / np.abs(lam.real)
    return ModalModel(f, z, np.eye(f.size, dtype=complex), gain, lam, res)


def test_two_modes_sharing_one_peak_are_both_seen():
    """1000 and 1015 Hz at 2 % damping with equal residues make one peak of the FRF; each mode
    still carries at least half of the response at its own frequency."""
    mm = _modal([1000.0, 1015.0, 3000.0], [0.02, 0.02, 0.02], [-1j, -1j, -1j])
    grid = np.linspace(500.0, 4000.0, 20000)
    level = 20 * np.log10(np.abs(frequency_response(mm, grid)[0, 0]))
    peaks, _ = find_peaks(level, prominence=3.0)
    assert sum(abs(grid[p] / 1007.5 - 1) < 0.02 for p in peaks) == 1      # one peak for the pair
    assert dominant_modes(mm, 0).tolist() == [True, True, True]


def test_a_weak_mode_beside_a_strong_one_or_below_the_floor_is_not_seen():
    """A mode 3 % from one 30 dB stronger is swamped there; an isolated mode 46 dB below the
    strongest dominates its own frequency but lies under DOMINANT_FLOOR. ``within`` sets the floor
    from the band's modes only: without the strong ones the isolated mode counts."""
    mm = _modal([1000.0, 1030.0, 10000.0], [0.02, 0.02, 0.001], [-1j, -0.03j, -2.5e-3j])
    assert dominant_modes(mm, 0).tolist() == [True, False, False]
    assert dominant_modes(mm, 0, within=np.array([False, False, True])).tolist() == [True, False, True]
    own = mm.gain[0, 0]
    assert own[2] < DOMINANT_FLOOR * own[0]        # the isolated mode's peak: about -46 dB


def test_dominant_visibility_is_an_opt_in_that_only_adds_modes(gearbox_fmu):
    """``+dominant`` keeps every mode the peak search shows and may add modes; the default and
    ``run-up`` are unchanged by it; an unknown rule is refused by name."""
    import pytest

    from twin.calibration.model_modes import VISIBILITY, model_modes
    kw = dict(speed_hz=20.0, load_nm=20.0)
    assert VISIBILITY == ("mesh", "run-up", "mesh+dominant", "run-up+dominant")
    for base in ("mesh", "run-up"):
        peaks = model_modes(gearbox_fmu, {}, **kw, visibility=base)
        both = model_modes(gearbox_fmu, {}, **kw, visibility=base + "+dominant")
        assert np.array_equal(peaks.frequency, both.frequency)
        assert np.all(both.visible[peaks.visible]) and both.visibility == base + "+dominant"
        assert set(both.visible_by) == set(peaks.visible_by)
    with pytest.raises(ValueError, match="dominant-ish"):
        model_modes(gearbox_fmu, {}, **kw, visibility="dominant-ish")
