"""Windowing, normalisation, record splitting, augmentation, the target-domain filters, t-SNE."""
from __future__ import annotations

import numpy as np
import pytest

from twin.errors import ParameterError
from twin.transfer.domain import TargetShift, resonator, runout_offsets
from twin.transfer.preprocess import (Augmentation, Preprocessing, apply_normalisation, augmented_windows,
                                      domain_normaliser, domain_scale, prepare, represent, split_records,
                                      window_signal, windows_of)
from twin.transfer.tsne import tsne

from .conftest import make_records


def test_window_signal_counts_and_content():
    x = np.arange(10.0)
    w = window_signal(x, 4, 3)
    assert w.tolist() == [[0, 1, 2, 3], [3, 4, 5, 6], [6, 7, 8, 9]]
    assert window_signal(x, 11, 1).shape == (0, 11)


def test_window_normalisation_cancels_gain_and_domain_keeps_relative_level():
    rng = np.random.default_rng(0)
    w = rng.normal(size=(3, 64))
    np.testing.assert_allclose(apply_normalisation(7.0 * w, "window"), apply_normalisation(w, "window"))
    big = np.vstack([w, 4 * w])
    d = apply_normalisation(big, "domain") / domain_scale(big)
    d7 = apply_normalisation(7 * big, "domain") / domain_scale(7 * big)
    np.testing.assert_allclose(d, d7, rtol=1e-12)              # a constant gain cancels ...
    assert d[3:].std() == pytest.approx(4 * d[:3].std())       # ... the level between records stays


def test_log_spectrum_cancels_gain_and_domain_centring_cancels_a_transfer_path():
    """A rig that sees the same vibration through another linear path (a mount resonance and a
    3x gain) gives, after the domain centring, nearly the features of the twin."""
    from twin.transfer.domain import resonator
    rng = np.random.default_rng(0)
    fs, n = 20000.0, 256
    t = np.arange(40 * n) / fs
    # stages: the amplitude of a 2 kHz line relative to a 1 kHz one; broadband noise underneath
    stage_amp = rng.choice([0.2, 0.6, 1.2], size=40)
    x = np.concatenate([np.sin(2 * np.pi * 1000 * t[:n] + rng.uniform(0, 6)) +
                        a * np.sin(2 * np.pi * 2000 * t[:n] + rng.uniform(0, 6)) for a in stage_amp])
    x = x + rng.normal(0, 0.05, x.size)
    y = 3.0 * resonator(x, fs, 3000.0, 5.0)
    pre = Preprocessing(sample_rate=fs, window=n, hop=n)
    ws, wt = window_signal(x, n, n)[1:], window_signal(y, n, n)[1:]     # skip the filter's transient
    # a constant gain: the domain centring cancels it; the per-window level removal does too
    f1, f7 = represent(ws, pre), represent(7.0 * ws, pre)
    np.testing.assert_allclose(f7 - f1, np.log(7.0), atol=1e-9)
    np.testing.assert_allclose(domain_normaliser(f7, pre)(f7), domain_normaliser(f1, pre)(f1), atol=1e-5)
    flat = Preprocessing(sample_rate=fs, window=n, hop=n, remove_level=True)
    np.testing.assert_allclose(represent(7.0 * ws, flat), represent(ws, flat), atol=1e-9)
    fs_, ft = represent(ws, pre), represent(wt, pre)
    src = domain_normaliser(fs_, pre)
    tgt = domain_normaliser(ft, pre, reference=src)
    assert tgt.scale == src.scale
    gap_raw = np.abs(fs_ - ft).mean()
    gap = np.abs(src(fs_) - tgt(ft)).mean() * src.scale             # in log units, like gap_raw
    assert gap < 0.2 * gap_raw, (gap, gap_raw)
    # ... while the stage information (the 2 kHz line) is still there
    line = round(2000 / (fs / (2 * n)))
    assert np.corrcoef(tgt(ft)[:, line], stage_amp[1:])[0, 1] > 0.9


@pytest.mark.parametrize("time_bandwidth, tapers", [(0.0, 1), (4.0, 5), (3.0, 3)])
def test_log_spectrum_scatter_of_white_noise_matches_the_tapers_degrees_of_freedom(time_bandwidth, tapers):
    """The log of an average of K independent chi-squared(2) powers has variance trigamma(K); the
    value returned is half the log power, so its scatter over windows is sqrt(trigamma(K)) / 2
    (0.641 for one Hann taper, 0.235 for NW = 4, whose five tapers leak at most 0.1 %)."""
    from scipy.special import polygamma

    from twin.transfer.preprocess import log_spectrum
    w = np.random.default_rng(3).normal(size=(400, 512))
    scatter = log_spectrum(w, time_bandwidth)[:, 40:-40].std(axis=0).mean()     # away from DC and Nyquist
    assert scatter == pytest.approx(0.5 * np.sqrt(float(polygamma(1, tapers))), rel=0.05)


def test_domain_normalisation_keeps_the_level_between_records_and_remove_level_drops_it():
    """Two records of the same spectral shape, one 4x louder (a deeper wear): with the default the
    louder one sits log(4) higher after the domain centring; with remove_level they coincide."""
    rng = np.random.default_rng(1)
    w = rng.normal(size=(8, 256))
    both = np.vstack([w, 4.0 * w])
    for remove_level, step in ((False, np.log(4.0)), (True, 0.0)):
        pre = Preprocessing(sample_rate=1000.0, window=256, hop=256, remove_level=remove_level)
        f = represent(both, pre)
        g = domain_normaliser(f, pre)(f) * domain_normaliser(f, pre).scale
        assert g[8:].mean() - g[:8].mean() == pytest.approx(step, abs=1e-6)


def test_for_shaft_speed_gives_windows_of_two_pinion_revolutions():
    assert Preprocessing.for_shaft_speed(20.0).sample_rate == 20480.0
    pre = Preprocessing.for_shaft_speed(10.0, window=1024, hop=512)
    assert pre.sample_rate * 2 / 10.0 == pre.window and pre.hop == 512
    assert Preprocessing.for_shaft_speed(25.0, revolutions=1.0).sample_rate == 51200.0
    with pytest.raises(ParameterError, match="shaft speed.*-3"):
        Preprocessing.for_shaft_speed(-3.0)
    with pytest.raises(ParameterError, match="revolutions"):
        Preprocessing.for_shaft_speed(20.0, revolutions=0)


def test_preprocessing_validates():
    with pytest.raises(ParameterError, match="remove_level"):
        Preprocessing(remove_level="yes")
    with pytest.raises(ParameterError, match="time_bandwidth.*0.5"):
        Preprocessing(time_bandwidth=0.5)
    with pytest.raises(ParameterError, match="window"):
        Preprocessing(window=100)
    with pytest.raises(ParameterError, match="normalise"):
        Preprocessing(normalise="record")
    with pytest.raises(ParameterError, match="representation.*'cepstrum'"):
        Preprocessing(representation="cepstrum")


def test_prepare_resamples_to_the_preprocessing_rate():
    recs = make_records(1, 1, duration=0.4)                    # 1 kHz
    p = prepare(recs, Preprocessing(sample_rate=500.0, window=64, hop=64))
    assert p[0].signal.size == 200


def test_split_records_gives_disjoint_halves():
    recs = make_records(1, 2)
    first, second = split_records(recs)
    x = recs[0]["accel_pinion_casing"]
    np.testing.assert_array_equal(np.concatenate([first[0]["accel_pinion_casing"],
                                                  second[0]["accel_pinion_casing"]]), x)
    assert second[0].time_start == pytest.approx(first[0].duration)
    assert first[1].label == 1


def test_augmentation_is_seeded_and_keeps_counts():
    pre = Preprocessing(sample_rate=1000.0, window=64, hop=32)
    prep = prepare(make_records(2, 2), pre)
    a, la = augmented_windows(prep, pre, Augmentation(), np.random.default_rng(5))
    b, lb = augmented_windows(prep, pre, Augmentation(), np.random.default_rng(5))
    c, _ = augmented_windows(prep, pre, Augmentation(), np.random.default_rng(6))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert a.shape == windows_of(prep, pre)[0].shape and la.tolist() == lb.tolist()


def test_resonator_unity_at_dc_and_peak_near_f0():
    fs, f0, q = 100_000.0, 4000.0, 5.0
    n = 20000
    t = np.arange(n) / fs
    dc = resonator(np.ones(n), fs, f0, q)
    assert dc[-1] == pytest.approx(1.0, rel=1e-6)
    tone = resonator(np.sin(2 * np.pi * f0 * t), fs, f0, q)
    gain = tone[n // 2:].std() / np.sin(2 * np.pi * f0 * t[n // 2:]).std()
    assert gain == pytest.approx(np.sqrt(1 + q ** 2), rel=0.02)   # |H(j w0)| = sqrt(1 + Q^2)
    with pytest.raises(ParameterError, match="60000"):
        resonator(np.ones(4), fs, 60000.0, q)


def test_runout_offsets_are_a_non_negative_sinusoid():
    d = runout_offsets(4e-6, 0.3)
    v = np.array([d[f"tooth_deviation_offset[{i}]"] for i in range(1, 20)])
    assert v.min() >= 0 and v.max() <= 4e-6 and v.max() - v.min() > 3.9e-6
    with pytest.raises(ParameterError, match="noise"):
        TargetShift(noise=-1)


def test_tsne_separates_two_clusters():
    rng = np.random.default_rng(0)
    x = np.vstack([rng.normal(0, 1, (30, 10)), rng.normal(8, 1, (30, 10))])
    y = tsne(x, perplexity=10, n_iter=300, seed=1)
    assert y.shape == (60, 2)
    ca, cb = y[:30].mean(0), y[30:].mean(0)
    spread = max(np.linalg.norm(y[:30].std(0)), np.linalg.norm(y[30:].std(0)))
    assert np.linalg.norm(ca - cb) > 2 * spread
    d = np.linalg.norm(y[:, None] - y[None], axis=-1) + np.eye(60) * 1e9
    nn = d.argmin(1)
    assert np.all((nn < 30) == (np.arange(60) < 30))          # every nearest neighbour in its own cluster
    np.testing.assert_array_equal(y, tsne(x, perplexity=10, n_iter=300, seed=1))


def test_the_rig_channel_defaults_to_the_twins_and_is_checked():
    from twin.errors import ParameterError
    from twin.transfer import Preprocessing
    pre = Preprocessing()
    assert pre.channel_of("source") == pre.channel_of("target") == "accel_pinion_casing"
    rig = Preprocessing(target_channel="acc_x")
    assert (rig.channel_of("source"), rig.channel_of("target")) == ("accel_pinion_casing", "acc_x")
    with pytest.raises(ParameterError, match="target_channel must be a non-empty string or None, got ''"):
        Preprocessing(target_channel="")
    with pytest.raises(ParameterError, match="'rig'"):
        pre.channel_of("rig")
