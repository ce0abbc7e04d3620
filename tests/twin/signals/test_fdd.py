"""Close modes of different shapes from two channels (frequency-domain decomposition), on synthetic
run-ups with orders and a fixed drive line."""
from __future__ import annotations

import numpy as np
import pytest

from twin.measurements import Record
from twin.modes import FDD, MIN_CONFIDENCE, survey_record
from twin.signals import SignalError
from twin.signals.fdd import fdd_modes

FS = 4096.0
LINE = 300.0
CHANNELS = ("accel_pinion_casing", "accel_gear_casing")


def _record(runup_factory, modes, weights, seed):
    x, angle, _ = runup_factory(fs=FS, seed=seed, modes=modes, weights=weights, noise=0.05, lines=((LINE, 3.0),))
    return Record("runup", {CHANNELS[0]: x[0], CHANNELS[1]: x[1], "encoder": angle},
                  {CHANNELS[0]: "m/s2", CHANNELS[1]: "m/s2", "encoder": "rad"}, FS,
                  tachometer="encoder", tachometer_kind="angle")


def _pair(runup_factory, f1, sep, seed):
    """A pair f1, f1 (1 + sep), 2 % damping, of different shapes at the two channels, between two
    well separated modes."""
    modes = ((87.0, 0.02), (f1, 0.02), (f1 * (1 + sep), 0.02), (430.0, 0.015))
    weights = [[1.0, 1.0, 0.5, 1.0], [0.5, 0.6, -1.0, 0.7]]
    return _record(runup_factory, modes, weights, seed), (f1, f1 * (1 + sep))


def _found(survey, f0):
    freqs = survey.frequencies(MIN_CONFIDENCE)
    return freqs.size > 0 and float(np.min(np.abs(freqs - f0)) / f0) <= 0.02


@pytest.mark.parametrize("f1, sep, seed", [(180.0, 0.04, 0), (260.0, 0.06, 1), (150.0, 0.08, 0)])
def test_a_close_pair_of_different_shapes_is_split_with_two_channels_only(runup_factory, f1, sep, seed):
    rec, pair = _pair(runup_factory, f1, sep, seed)
    one = survey_record(rec, channels=[CHANNELS[0]], fdd=True)
    assert not all(_found(one, f) for f in pair), one.frequencies(MIN_CONFIDENCE)
    per_channel = survey_record(rec, fdd=False)
    both = survey_record(rec, fdd=True)
    assert all(_found(both, f) for f in pair), (pair, both.frequencies(MIN_CONFIDENCE))
    assert not all(_found(per_channel, f) for f in pair), per_channel.frequencies(MIN_CONFIDENCE)
    new = [m for m in both.modes if m.evidence.get("found_by") == "close mode" and m.confidence >= MIN_CONFIDENCE]
    assert new and all(0.0 <= m.evidence["flank_mac"] < 0.9 and np.isfinite(m.damping) for m in new)
    assert all(abs(m.frequency - LINE) > 2.0 for m in both.modes)
    assert all("shape" in m.evidence for m in both.modes)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_single_mode_is_not_split(runup_factory, seed):
    modes = ((87.0, 0.02), (180.0, 0.02), (640.0, 0.02))
    rec = _record(runup_factory, modes, [[1.0, 1.0, 1.0], [0.5, 0.6, -0.7]], seed)
    per_channel = survey_record(rec, fdd=False)
    both = survey_record(rec, fdd=True)
    assert [m.frequency for m in both.modes] == [m.frequency for m in per_channel.modes]
    for fn, _ in modes:
        assert sum(abs(f - fn) / fn < 0.05 for f in both.frequencies(MIN_CONFIDENCE)) == 1, both.frequencies()


def test_one_channel_survey_is_unchanged_and_fdd_needs_two(runup_factory):
    rec, _ = _pair(runup_factory, 180.0, 0.04, 0)
    assert FDD and [m.frequency for m in survey_record(rec).modes] == [m.frequency for m in survey_record(rec, fdd=True).modes]
    a = survey_record(rec, channels=[CHANNELS[0]], fdd=True)
    b = survey_record(rec, channels=[CHANNELS[0]], fdd=False)
    assert [m.frequency for m in a.modes] == [m.frequency for m in b.modes]
    with pytest.raises(SignalError, match="at least two channels"):
        fdd_modes([np.asarray(rec[CHANNELS[0]])], FS, None, b)
