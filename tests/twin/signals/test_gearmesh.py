"""Known-answer tests of gear-mesh harmonic and sideband reading.

Rig of the paper: pinion z=19 on the input shaft at 20 Hz (GMF 380 Hz), wheel z=52 on the output
shaft at 380/52 = 7.3077 Hz. A 13 s record puts every line (multiples of 20 Hz and of 95/13 Hz)
exactly on a bin of the 1/13 Hz grid, so the Hann amplitude spectrum reads them without loss.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.special import jv

from twin.signals import SignalError, amplitude_spectrum, mesh_harmonics, sideband_energy_ratio

FS = 5120.0
SHAFT_HZ = 20.0
Z = 19
GMF = Z * SHAFT_HZ
OTHER_HZ = GMF / 52
HARMONIC_AMPS = (1.0, 0.5, 0.25)
SHAFT_AM = (0.2, 0.1, 0.05)  # modulation depth at 1x, 2x, 3x input shaft
OTHER_AM = 0.1               # modulation depth at 1x output shaft


def am_gear_signal(duration=13.0, seed=30):
    t = np.arange(int(duration * FS)) / FS
    rng = np.random.default_rng(seed)
    envelope = 1.0 + sum(a * np.cos(2 * np.pi * (m + 1) * SHAFT_HZ * t + rng.uniform(0, 2 * np.pi))
                         for m, a in enumerate(SHAFT_AM))
    envelope *= 1.0 + OTHER_AM * np.cos(2 * np.pi * OTHER_HZ * t + 0.7)
    carrier = sum(a * np.cos(2 * np.pi * (k + 1) * GMF * t + rng.uniform(0, 2 * np.pi))
                  for k, a in enumerate(HARMONIC_AMPS))
    return envelope * carrier + 0.01 * rng.normal(size=t.size)


def test_am_sidebands_have_the_known_amplitudes():
    f, amp = amplitude_spectrum(am_gear_signal(), FS)
    lines = mesh_harmonics(f, amp, shaft_hz=SHAFT_HZ, z=Z, n_harmonics=3, n_sidebands=3, other_shaft_hz=OTHER_HZ)
    assert [h["harmonic"] for h in lines] == [1, 2, 3]
    worst = 0.0
    for h, carrier in zip(lines, HARMONIC_AMPS):
        assert h["frequency"] == pytest.approx(h["harmonic"] * GMF, abs=1e-9)
        assert h["amplitude"] == pytest.approx(carrier, rel=0.01)
        assert h["level_db"] == pytest.approx(20 * np.log10(carrier), abs=0.1)
        for sb in h["sidebands"]:
            depth = SHAFT_AM[abs(sb["order"]) - 1] if sb["family"] == "shaft" else (
                OTHER_AM if abs(sb["order"]) == 1 else 0.0)
            expected = carrier * depth / 2  # AM: each side carries half the depth
            worst = max(worst, abs(sb["amplitude"] - expected) / carrier)
            if depth:
                assert sb["amplitude"] == pytest.approx(expected, rel=0.02)
                assert sb["relative_db"] == pytest.approx(20 * np.log10(depth / 2), abs=0.2)
            else:
                assert sb["amplitude"] < 0.005 * carrier
    assert worst < 0.005  # measured 1.1e-3 of the carrier (the 0.01 noise floor)


def test_fm_sidebands_follow_bessel_functions():
    t = np.arange(int(13 * FS)) / FS
    beta = 0.3  # phase-modulation index at the shaft rate
    x = np.cos(2 * np.pi * GMF * t + beta * np.sin(2 * np.pi * SHAFT_HZ * t))
    f, amp = amplitude_spectrum(x, FS)
    h = mesh_harmonics(f, amp, shaft_hz=SHAFT_HZ, z=Z, n_harmonics=1, n_sidebands=3)[0]
    assert h["amplitude"] == pytest.approx(jv(0, beta), rel=1e-6)
    for sb in h["sidebands"]:
        assert sb["amplitude"] == pytest.approx(abs(jv(abs(sb["order"]), beta)), rel=1e-4, abs=1e-9)
    ser = sideband_energy_ratio(f, amp, shaft_hz=SHAFT_HZ, z=Z, n_sidebands=3)
    assert ser == pytest.approx(2 * sum(jv(m, beta) for m in (1, 2, 3)) / jv(0, beta), rel=1e-4)


def test_sideband_energy_ratio_of_the_am_signal():
    f, amp = amplitude_spectrum(am_gear_signal(), FS)
    ser = sideband_energy_ratio(f, amp, shaft_hz=SHAFT_HZ, z=Z, n_sidebands=3)
    assert ser == pytest.approx(sum(SHAFT_AM), rel=0.02)  # 2 sides x depth/2 each
    both = sideband_energy_ratio(f, amp, shaft_hz=SHAFT_HZ, z=Z, n_sidebands=3, other_shaft_hz=OTHER_HZ)
    # The output shaft adds its +-1 pair (0.05 each); its 2nd and 3rd orders are noise.
    assert both == pytest.approx(sum(SHAFT_AM) + OTHER_AM, rel=0.03)
    second = sideband_energy_ratio(f, amp, shaft_hz=SHAFT_HZ, z=Z, harmonic=2, n_sidebands=3)
    assert second == pytest.approx(sum(SHAFT_AM), rel=0.02)


def test_off_bin_lines_read_with_a_flattop_window():
    # 12.3 s: the lines fall between bins; the flat-top window keeps the reading within 1 %.
    f, amp = amplitude_spectrum(am_gear_signal(duration=12.3), FS, window="flattop")
    h = mesh_harmonics(f, amp, shaft_hz=SHAFT_HZ, z=Z, n_harmonics=1, n_sidebands=2)[0]
    assert h["amplitude"] == pytest.approx(1.0, rel=0.01)
    shaft = {sb["order"]: sb["amplitude"] for sb in h["sidebands"] if sb["family"] == "shaft"}
    assert shaft[1] == pytest.approx(0.1, rel=0.02) and shaft[-2] == pytest.approx(0.05, rel=0.02)


def test_power_spectrum_levels_and_out_of_range_lines():
    f, amp = amplitude_spectrum(am_gear_signal(), FS)
    power = amp**2
    h = mesh_harmonics(f, power, shaft_hz=SHAFT_HZ, z=Z, n_harmonics=1, quantity="power")[0]
    assert h["level_db"] == pytest.approx(0.0, abs=0.1)
    ser = sideband_energy_ratio(f, power, shaft_hz=SHAFT_HZ, z=Z, n_sidebands=3, quantity="power")
    assert ser == pytest.approx(sum(SHAFT_AM), rel=0.02)
    beyond = mesh_harmonics(f, amp, shaft_hz=SHAFT_HZ, z=Z, n_harmonics=7)  # 7 x 380 > 2560 Hz
    assert np.isnan(beyond[-1]["amplitude"]) and np.isfinite(beyond[5]["amplitude"])


def test_bad_arguments():
    f = np.linspace(0, 100, 101)
    with pytest.raises(SignalError, match="z"):
        mesh_harmonics(f, np.ones(101), shaft_hz=20.0, z=0)
    with pytest.raises(SignalError, match="shaft_hz"):
        mesh_harmonics(f, np.ones(101), shaft_hz=-1.0, z=19)
    with pytest.raises(SignalError, match="same shape"):
        mesh_harmonics(f, np.ones(100), shaft_hz=20.0, z=19)
