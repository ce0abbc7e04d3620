"""The pedestal rig's physics: geometry, linearisation against its own time response, effects,
damage trends. Records are short (0.6-2 s) to keep the file fast."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from rigs.pedestal import Damage, Rig
from rigs.pedestal.effects import ball_pass_outer
from rigs.pedestal.geometry import GearPair

FS = 50_000.0


@pytest.fixture(scope="module")
def rig():
    return Rig()


def _spectrum(x):
    w = np.hanning(x.size)
    return np.fft.rfftfreq(x.size, 1 / FS), np.abs(np.fft.rfft(x * w)) * 2 / w.sum()


def _peak(f, X, f0, half=1.0):
    """Largest amplitude within +-half [Hz] of f0 (at least the nearest bin and its neighbours)."""
    i = int(round(f0 / f[1]))
    k = max(1, int(half / f[1]))
    return X[max(0, i - k):i + k + 1].max()


def _floor(f, X, f0, half):
    m = (f > f0 - half) & (f < f0 + half)
    return np.median(X[m])


def test_iso_stiffness_law_reproduces_the_iso_mean_mesh_stiffness():
    g = GearPair()
    assert 1.6 < g.contact_ratio < 1.7
    # the pair law summed over the pairs in contact, averaged over a mesh cycle = c_gamma b
    u = np.linspace(0, g.base_pitch, 4001)[:-1]
    total = sum(g.pair_stiffness_shape(u + j * g.base_pitch) for j in range(3))
    k = g.pair_stiffness_max(20.0)
    assert np.mean(total) * k == pytest.approx(g.mesh_stiffness_iso(20.0), rel=2e-3)
    # lighter load, softer mesh (ISO line-load correction)
    assert g.single_stiffness(5.0) < g.single_stiffness(20.0)


def test_modes_span_tens_of_hertz_to_kilohertz_with_observability(rig):
    modes = rig.modes(20.0, 20.0)
    f = np.array([m.frequency for m in modes])
    assert np.all(np.diff(f) >= 0)
    assert 10 < f[0] < 60 and f[-1] > 3000
    obs = np.array([m.observability for m in modes])
    assert obs.max() == pytest.approx(1.0) and np.all((obs >= 0) & (obs <= 1))
    assert any("mesh" in m.label for m in modes)
    assert all(0 < m.damping_ratio < 0.5 for m in modes)


def test_linearised_modes_agree_with_an_impact_test_of_the_time_simulation(rig):
    """The FRF hammer -> casing sensor of the nonlinear time simulation (turning slowly under
    a light load, as in a rig's hammer test) peaks at the modes of the linearisation."""
    rec = rig.impact(speed=1.0, load=5.0, duration=2.0, impacts_per_second=6.0, seed=1)
    modes = rig.modes(1.0, 5.0)
    f, pxy = signal.csd(rec["hammer"], rec["accel_pinion_casing"], FS, nperseg=8192)
    _, pxx = signal.welch(rec["hammer"], FS, nperseg=8192)
    frf = np.abs(pxy / pxx)
    band = (f > 500) & (f < 5000)
    peaks, _ = signal.find_peaks(np.log(frf[band]), prominence=0.5)
    peak_f = f[band][peaks]
    mode_f = np.array([m.frequency for m in modes])
    assert peak_f.size >= 5
    # every resonance of the response is a mode of the linearisation (modes that involve the
    # mesh move with its time-varying stiffness, hence 4 %)
    for pf in peak_f:
        assert np.min(np.abs(mode_f - pf) / pf) < 0.04, pf
    mesh_f = [m.frequency for m in modes if "mesh" in m.label]
    for m in modes:       # the panel modes away from the mesh mode are found to 1.5 %
        near_mesh = any(abs(m.frequency / fm - 1) < 0.15 for fm in mesh_f)
        if m.label.startswith("panel") and 500 < m.frequency < 5000 and not near_mesh:
            assert np.min(np.abs(peak_f - m.frequency)) / m.frequency < 0.015, m


def test_a_blow_from_the_side_pushes_the_pedestal_along_x(rig):
    """A horizontal blow pushes the struck pedestal's x DOF (-x) where a vertical one pushes y,
    with the same blows; the sensor along x answers more to it. Unknown directions are named."""
    from rigs.pedestal import simulate
    from rigs.pedestal.excitation import hammer_input
    from rigs.pedestal.structure import I_XA, I_YA
    struct = simulate.build_case(rig, 5.0, None, None).struct
    up = hammer_input(5000, 50000.0, struct, "pinion_pedestal", 4.0, 1)
    side = hammer_input(5000, 50000.0, struct, "pinion_pedestal", 4.0, 1, "horizontal")
    assert np.array_equal(up["force"], side["force"])
    assert up["direction"][I_YA] == -1.0 and side["direction"][I_XA] == -1.0
    assert np.count_nonzero(up["direction"]) == np.count_nonzero(side["direction"]) == 1
    rec = rig.impact(1.0, 5.0, 0.05, location="gear_pedestal", direction="horizontal", seed=2)
    assert rec.attributes["impact_location"] == "gear_pedestal"
    assert rec.attributes["impact_direction"] == "horizontal"
    assert rec.truth["hammer"] == {"impact_location": "gear_pedestal", "impact_direction": "horizontal"}
    with pytest.raises(ValueError, match="diagonal"):
        rig.impact(1.0, 5.0, 0.2, direction="diagonal")
    with pytest.raises(ValueError, match="nowhere"):
        rig.impact(1.0, 5.0, 0.2, location="nowhere")


@pytest.fixture(scope="module")
def steady_set(rig):
    names = (None, "pinion_runout", "gear_runout", "drive_ripple", "casing_resonance",
             "local_tooth_fault", "bearing_outer_race")
    return {n: rig.steady(20.0, 20.0, duration=0.8, effect=n, seed=4) for n in names}


def _sidebands(rec, spacing):
    x = rec["accel_pinion_casing"]
    fp = rec.truth["mean_speed"]
    f, X = _spectrum(x)
    fm = 19 * fp
    return sum(_peak(f, X, k * fm + s * spacing(fp), 0.6) ** 2
               for k in range(1, 9) for s in (-2, -1, 1, 2))


def test_runouts_raise_their_own_shaft_order_sidebands(steady_set):
    base = steady_set[None]
    pin = steady_set["pinion_runout"]
    gear = steady_set["gear_runout"]

    def fpin(fp):
        return fp

    def fgear(fp):
        return fp * 19 / 52

    assert _sidebands(pin, fpin) > 3 * _sidebands(base, fpin)
    assert _sidebands(gear, fgear) > 3 * _sidebands(base, fgear)
    # each raises its own shaft's sidebands more than the other shaft's
    assert (_sidebands(pin, fpin) / _sidebands(base, fpin)
            > 2 * _sidebands(pin, fgear) / _sidebands(base, fgear))
    assert (_sidebands(gear, fgear) / _sidebands(base, fgear)
            > 2 * _sidebands(gear, fpin) / _sidebands(base, fpin))


def test_drive_ripple_is_a_line_at_the_drive_frequency(steady_set, rig):
    fr = rig.identity.ripple_frequency
    f, X = _spectrum(steady_set["drive_ripple"]["accel_pinion_casing"])
    f0, X0 = _spectrum(steady_set[None]["accel_pinion_casing"])
    assert _peak(f, X, fr) > 5 * _floor(f, X, fr, 6)
    assert _peak(f0, X0, fr) < 3 * _floor(f0, X0, fr, 6)


def test_casing_resonance_is_a_hump_at_its_frequency(steady_set):
    def band(rec):
        f, p = signal.welch(rec["accel_pinion_casing"], FS, nperseg=4096)
        return p[(f > 3600) & (f < 3800)].sum()

    assert band(steady_set["casing_resonance"]) > 4 * band(steady_set[None])


def test_local_tooth_fault_is_impulsive_once_per_pinion_turn(steady_set):
    def kurt(x):
        x = x - x.mean()
        return np.mean(x ** 4) / np.var(x) ** 2

    base, fault = steady_set[None], steady_set["local_tooth_fault"]
    assert kurt(fault["accel_pinion_casing"]) > 2 * kurt(base["accel_pinion_casing"])

    def fpin(fp):
        return fp

    assert _sidebands(fault, fpin) > 1.5 * _sidebands(base, fpin)


def test_outer_race_defect_shows_at_the_ball_pass_frequency_in_the_envelope(steady_set):
    def ratio(rec):
        sos = signal.butter(4, [4000, 10000], "bandpass", fs=FS, output="sos")
        env = np.abs(signal.hilbert(signal.sosfilt(sos, rec["accel_pinion_casing"])))
        f, E = _spectrum(env - env.mean())
        bp = ball_pass_outer(rec.truth["mean_speed"])
        return _peak(f, E, bp, 1.5) / _floor(f, E, bp, 12)

    assert ratio(steady_set["bearing_outer_race"]) > 6
    assert ratio(steady_set[None]) < 4


def test_drive_ripple_stays_at_one_frequency_through_a_runup(rig):
    rec = rig.runup((4.0, 20.0), 20.0, duration=2.0, effect="drive_ripple", seed=2)
    x = rec["accel_pinion_casing"]
    fr = rig.identity.ripple_frequency
    for part in np.array_split(x, 3):
        f, X = _spectrum(part)
        assert _peak(f, X, fr, 2.0) > 3 * _floor(f, X, fr, 15), "ripple line lost"
    # while the mesh frequency sweeps: the encoder speed rises 4 -> 20 Hz
    speed = np.diff(rec["encoder"]) * FS / (2 * np.pi)
    n = speed.size // 10
    assert speed[:n].mean() < 7 and speed[-n:].mean() > 17


def test_casing_resonance_stays_at_one_frequency_through_a_runup(rig):
    rec = rig.runup((4.0, 20.0), 20.0, duration=2.0, effect="casing_resonance", seed=2)
    for part in np.array_split(rec["accel_pinion_casing"], 2):
        f, p = signal.welch(part, FS, nperseg=2048)
        m = (f > 3350) & (f < 4100)
        assert f[m][np.argmax(p[m])] == pytest.approx(3700, rel=0.03)


def test_pitting_raises_mesh_harmonics_monotonically_with_stage(rig):
    energies = []
    for st in rig.pitting_stages():
        rec = rig.steady(st.speed, st.load, duration=0.6, damage=Damage("pitting", st.centre),
                         seed=3)
        f, X = _spectrum(rec["accel_pinion_casing"])
        fm = 19 * rec.truth["mean_speed"]
        energies.append(sum(_peak(f, X, k * fm, 1.5) ** 2 for k in range(1, 11)))
    assert np.all(np.diff(energies) > 0), energies
    assert energies[-1] > 3 * energies[0]


def test_wear_raises_vibration_monotonically_with_stage(rig):
    levels = []
    healthy = rig.steady(10.0, 5.0, duration=0.6, seed=3, lubricated=False)
    levels.append(np.std(healthy["accel_pinion_casing"]))
    for st in rig.wear_stages():
        assert not st.lubricated and st.speed == 10.0 and st.load == 5.0
        rec = rig.steady(st.speed, st.load, duration=0.6, damage=Damage("wear", st.centre),
                         seed=3, lubricated=False)
        levels.append(np.std(rec["accel_pinion_casing"]))
    assert np.all(np.diff(levels) > 0), levels


def test_levels_are_those_of_a_small_test_rig(steady_set):
    rms = np.std(steady_set[None]["accel_pinion_casing"])
    assert 1.0 < rms < 50.0
