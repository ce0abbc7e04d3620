"""Run-up and hammer surveys on synthetic records with known modes, orders and drive lines."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as sps

from twin.signals import SignalError
from twin.signals.impact import analyse_impacts
from twin.signals.runup import analyse_runup

FS = 12800.0
MODES = ((87.0, 0.02), (218.0, 0.02), (430.0, 0.015), (512.0, 0.025), (767.0, 0.02), (1248.0, 0.02),
         (1927.0, 0.03))


def _nearest(freqs, f0):
    freqs = np.asarray(freqs, float)
    return float(freqs[np.argmin(np.abs(freqs - f0))]) if freqs.size else np.inf


@pytest.fixture(scope="module")
def survey(runup_factory):
    x, angle, truth = runup_factory(fs=FS, seed=0)
    return analyse_runup(x, FS, angle), truth


def test_every_mode_found_within_one_and_a_half_percent(survey):
    s, truth = survey
    for fn, _ in truth["modes"]:
        assert abs(_nearest(s.frequencies(), fn) - fn) / fn < 0.015, (fn, s.frequencies())
    # nothing else: every reported mode is one of the structure's
    for m in s.modes:
        assert min(abs(m.frequency - fn) / fn for fn, _ in truth["modes"]) < 0.015, m


def test_orders_are_found_and_are_not_modes(survey):
    s, _ = survey
    found = [o.order for o in s.orders]
    for order in (19.0, 38.0, 57.0):
        assert abs(_nearest(found, order) - order) < 0.05, found
    assert all(m.evidence["orders_crossing"] is not None for m in s.modes)
    assert any(19.0 - 0.05 < o < 19.05 for o in s.modes[0].evidence["orders_crossing"])   # 19 x 2..20 Hz crosses 87 Hz


def test_damping_and_confidence_are_reported(survey):
    s, truth = survey
    by_f = {fn: z for fn, z in truth["modes"]}
    for m in s.modes[:5]:
        fn = min(by_f, key=lambda f: abs(f - m.frequency))
        assert 0.4 * by_f[fn] < m.damping < 2.0 * by_f[fn], (m.frequency, m.damping)
        assert 0.3 < m.confidence <= 1.0
        assert m.evidence["frequency_sd_hz"] > 0


@pytest.mark.parametrize("seed, line_hz, amplitude", [(1, 300.0, 3.0), (2, 150.0, 1.0), (3, 1000.0, 0.3),
                                                      (4, 640.0, 2.0), (5, 97.0, 1.0)])
def test_a_non_synchronous_drive_line_is_never_a_mode(runup_factory, seed, line_hz, amplitude):
    x, angle, truth = runup_factory(fs=FS, seed=seed, lines=((line_hz, amplitude),))
    s = analyse_runup(x, FS, angle)
    assert abs(_nearest([ln.frequency for ln in s.lines], line_hz) - line_hz) < 0.5
    assert all(abs(m.frequency - line_hz) > 2.0 for m in s.modes), [m.frequency for m in s.modes]
    ln = min(s.lines, key=lambda ln: abs(ln.frequency - line_hz))
    assert ln.evidence["slice_level_sd_db"] < 2.0


def test_a_mode_under_a_drive_line_is_still_found(runup_factory):
    modes = MODES[:4] + ((640.0, 0.02),) + MODES[4:]
    x, angle, _ = runup_factory(fs=FS, seed=7, modes=modes, lines=((641.0, 2.0),))
    s = analyse_runup(x, FS, angle)
    assert abs(_nearest([ln.frequency for ln in s.lines], 641.0) - 641.0) < 0.5
    near = [m for m in s.modes if abs(m.frequency - 640.0) < 10.0]
    assert len(near) == 1 and abs(near[0].frequency - 640.0) < 6.4
    assert near[0].evidence["line_on_top_hz"]


def test_modes_inside_the_band_do_not_depend_on_its_upper_edge(runup_factory):
    x, angle, _ = runup_factory(fs=FS, seed=0)
    wide = analyse_runup(x, FS, angle, fmax=5000.0)
    narrow = analyse_runup(x, FS, angle, fmax=1600.0)
    a = wide.frequencies()[wide.frequencies() < 1500.0]
    b = narrow.frequencies()[narrow.frequencies() < 1500.0]
    assert a.size == b.size == 6
    np.testing.assert_allclose(a, b, rtol=2e-3)


def test_without_a_shaft_angle_the_survey_says_so(runup_factory):
    x, _, _ = runup_factory(fs=FS, seed=0)
    s = analyse_runup(x, FS)
    assert s.orders == () and any("no shaft angle" in n for n in s.notes)


def test_a_steady_record_reports_shaft_harmonics_as_orders_not_lines(runup_factory):
    x, angle, _ = runup_factory(fs=FS, seed=0, speeds=(20.0, 20.0), lines=((301.3, 3.0),))
    s = analyse_runup(x, FS, angle)
    assert any("cannot be told apart" in n for n in s.notes)
    assert all(abs(ln.frequency / 20.0 - round(ln.frequency / 20.0)) > 0.03 for ln in s.lines)


@pytest.mark.parametrize("kwargs, match", [({"fmax": 7000.0}, "fs/2"), ({"resolution": 0.05}, "fewer than 4"),
                                           ({"fmin": 900.0, "fmax": 905.0}, "fewer than 8 bins")])
def test_bad_arguments_are_refused_by_name(runup_factory, kwargs, match):
    x, angle, _ = runup_factory(fs=FS, duration=2.0, seed=0)
    with pytest.raises(SignalError, match=match):
        analyse_runup(x, FS, angle, **kwargs)


def test_a_shaft_turning_backwards_is_refused(runup_factory):
    x, angle, _ = runup_factory(fs=FS, duration=2.0, seed=0)
    with pytest.raises(SignalError, match="must increase"):
        analyse_runup(x, FS, -angle)


def _hammer_record(seed=0, fs=8192.0, hits=6, spacing=1.0, modes=((87.0, 0.02), (218.0, 0.015), (512.0, 0.02))):
    rng = np.random.default_rng(seed)
    n = int(hits * spacing * fs)
    force = np.zeros(n)
    for i in range(hits):
        k = int((i + 0.1) * spacing * fs)
        force[k:k + 8] = (1.0 + 0.2 * rng.standard_normal()) * np.hanning(8)
    t = np.arange(n) / fs
    response = np.zeros(n)
    for fn, zeta in modes:
        wn = 2 * np.pi * fn
        sys = sps.TransferFunction([1.0, 0.0, 0.0], [1.0, 2 * zeta * wn, wn * wn])
        response += sps.lsim(sys, force, t)[1]
    response += 1e-3 * np.std(response) * rng.standard_normal(n)
    return force, response, fs


def test_hammer_modes_and_damping():
    force, response, fs = _hammer_record()
    s = analyse_impacts(force, response, fs, fmax=1000.0)
    assert s.method == "hammer"
    for fn, zeta in ((87.0, 0.02), (218.0, 0.015), (512.0, 0.02)):
        m = min(s.modes, key=lambda m: abs(m.frequency - fn))
        assert abs(m.frequency - fn) / fn < 0.01
        assert abs(m.damping - zeta) / zeta < 0.35
        assert m.evidence["hits"] >= 5 and m.confidence > 0.5


def test_hammer_record_with_one_hit_is_refused():
    force, response, fs = _hammer_record(hits=1)
    with pytest.raises(SignalError, match="impact"):
        analyse_impacts(force, response, fs)


def test_hammer_on_a_running_structure_reads_the_frf_by_h1():
    """Loud response noise between the blows (a rolling gearbox): the auto estimator takes H1,
    which the noise does not bias, and finds the three modes within 1 %; H2, biased high wherever
    the noise outweighs the blows' response, puts its peaks elsewhere or loses a mode."""
    force, response, fs = _hammer_record(hits=24, spacing=0.25)
    rng = np.random.default_rng(5)
    noisy = response + 4.0 * np.std(response) * rng.standard_normal(response.size)
    auto = analyse_impacts(force, noisy, fs, fmax=1000.0)
    assert "FRF by H1, the response channel is the noisier" in auto.notes[0]
    assert {m.evidence["estimator"] for m in auto.modes} == {"H1"}
    h2 = analyse_impacts(force, noisy, fs, fmax=1000.0, estimator="H2")

    def found(s):
        return sum(any(abs(m.frequency - fn) / fn < 0.01 and m.confidence >= 0.3 for m in s.modes)
                   for fn in (87.0, 218.0, 512.0))
    assert found(auto) == 3 and found(h2) < 3
    quiet = analyse_impacts(force, response, fs, fmax=1000.0)
    assert found(quiet) == 3
    with pytest.raises(SignalError, match="unknown FRF estimator 'H3'"):
        analyse_impacts(force, response, fs, estimator="H3")


def test_double_hits_are_dropped_not_allowed_to_set_the_resolution():
    """Two blows 60 ms apart among blows 0.25 s apart: the pair's first segment is dropped and the
    resolution follows the usual interval, not the closest pair's."""
    force, response, fs = _hammer_record(hits=12, spacing=0.25)
    extra = int(0.085 * fs)          # a second blow 60 ms after the third one
    k = int(2.1 * 0.25 * fs)
    force2 = force.copy()
    force2[k + extra - int(0.025 * fs):k + extra - int(0.025 * fs) + 8] += np.hanning(8)
    s = analyse_impacts(force2, response, fs, fmax=1000.0)
    assert s.resolution < 1 / 0.15 and s.modes[0].evidence["hits"] < 13
