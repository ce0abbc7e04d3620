"""Pairing measured modes with model modes: by frequency among the visible modes (default), or by
frequency, shape at the sensors and reach (opt-in)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.calibration.modal_fit import mode_errors
from twin.calibration.pairing import (MATCH_REACH, PAIRINGS, MeasuredShapes, Pairing, mac, mode_reach, pair_modes,
                                      shape_mismatch)
from twin.calibration.sensitivity import Candidate, ModelModes, match_measured
from twin.scenario import CALIBRATION_SCHEMA
from twin.signals.shapes import ChannelShape

CHANNELS = ("accel_pinion_casing", "accel_gear_casing")


def _model(freqs, sensor, gain_db, visible):
    """ModelModes of len(freqs) modes with the given (2, m) sensor residues; state shapes distinct."""
    m = len(freqs)
    return ModelModes(np.array(freqs, float), np.full(m, 0.02), np.array(visible, bool), np.eye(m, dtype=complex),
                      np.array(gain_db, float), (), np.array(sensor, complex), CHANNELS)


def _measured(vectors, coherence):
    return MeasuredShapes(CHANNELS, np.array(vectors, complex), np.array(coherence, float))


#: torsional mode at 1020 Hz, both sensors in phase and alike; the pinion's lateral mode at 1100 Hz,
#: 50 dB down, the gear-side sensor at -0.3 of the pinion-side one
TORSION_AND_LATERAL = dict(freqs=[1020.0, 1100.0], sensor=[[1.0, 3e-3], [1.0, -0.9e-3]], gain_db=[0.0, -50.0],
                           visible=[True, False])
REACH = np.array([[0.3, 0.3], [0.3, 0.3]])


def test_a_lateral_measured_shape_picks_the_lateral_mode_over_a_closer_torsional_one():
    model = _model(**TORSION_AND_LATERAL)
    lateral = _measured([[1.0, -0.3]], [0.95])
    assert pair_modes(model, [1000.0], shapes=lateral, reach=REACH).tolist() == [1]
    # by frequency alone, or with a shape no one trusts, the closer torsional mode wins
    assert pair_modes(model, [1000.0], reach=REACH).tolist() == [0]
    assert pair_modes(model, [1000.0], shapes=_measured([[1.0, -0.3]], [0.0]), reach=REACH).tolist() == [0]
    # an in-phase measured shape stays with the torsional mode
    assert pair_modes(model, [1000.0], shapes=_measured([[1.0, 0.9]], [0.95]), reach=REACH).tolist() == [0]


def test_weakly_visible_modes_count_down_to_the_stated_level_only():
    quiet = _model(**{**TORSION_AND_LATERAL, "gain_db": [0.0, -80.0]})
    assert pair_modes(quiet, [1000.0], shapes=_measured([[1.0, -0.3]], [0.95]), reach=REACH).tolist() == [0]
    assert pair_modes(quiet, [1000.0], shapes=_measured([[1.0, -0.3]], [0.95]), reach=REACH,
                      min_level_db=-90.0).tolist() == [1]


def test_a_mode_out_of_every_parameters_reach_stays_unpaired():
    model = _model([1500.0], [[1.0], [0.5]], [0.0], [True])
    # 1000 Hz is ln(1.5) = 0.41 below the model mode: it can come down 0.1 only
    assert pair_modes(model, [1000.0], reach=np.array([[0.1, 0.5]])).tolist() == [-1]
    assert pair_modes(model, [1000.0], reach=np.array([[0.5, 0.1]])).tolist() == [0]
    # without sensitivities the reach is 15 % either way
    assert pair_modes(model, [1000.0]).tolist() == [-1]
    assert pair_modes(model, [1400.0]).tolist() == [0]


def test_each_mode_has_its_own_reach_one_to_one():
    # two measured modes, two model modes: the one that can reach the far measured mode takes it
    model = _model([1000.0, 1050.0], [[1.0, 1.0], [1.0, 1.0]], [0.0, 0.0], [True, True])
    reach = np.array([[0.05, 0.05], [0.05, 0.6]])
    assert pair_modes(model, [1010.0, 1500.0], reach=reach).tolist() == [0, 1]
    assert pair_modes(model, [1010.0, 1500.0], reach=np.full((2, 2), 0.05)).tolist() == [0, -1]


def test_reach_from_first_order_sensitivities_and_the_bounds():
    cands = [Candidate("k", 1.0, 1 / 3, 3.0, ""), Candidate("m", 1.0, 0.7, 1.4, "")]
    S = np.array([[0.5, -0.25], [0.0, 0.0]])
    (down, up), still = mode_reach(S, cands)
    assert up == pytest.approx(0.5 * math.log(3) - 0.25 * math.log(0.7))
    assert down == pytest.approx(0.5 * math.log(3) + 0.25 * math.log(1.4))
    assert still.tolist() == [0.0, 0.0]


def test_shapes_from_the_twin_modes_evidence():
    one = ChannelShape(CHANNELS[0], CHANNELS, (0.0, -6.0206), (0.0, 180.0), (1.0, 0.9), 40)
    shapes = MeasuredShapes.from_evidence([{"shape": one.to_dict()}, {}])
    assert shapes.channels == CHANNELS
    assert np.allclose(shapes.vectors[0], [1.0, -0.5], atol=1e-3) and np.isnan(shapes.vectors[1]).all()
    assert shapes.coherence.tolist() == [0.9, 0.0]
    assert MeasuredShapes.from_evidence([{}, {"reason": "x"}]) is None
    assert mac(np.array([1, -0.5]), np.array([2, -1.0])) == pytest.approx(1.0)
    # a mode without a shape costs nothing for its shape
    model = _model(**TORSION_AND_LATERAL)
    m = shape_mismatch(model, shapes, np.array([0, 1]))
    assert m[1].tolist() == [0.0, 0.0] and m[0, 0] > 0.5 and m[0, 1] < 0.05


def test_the_objective_charges_a_wrong_shape_like_a_missing_mode():
    model = _model([1000.0, 1400.0], [[1.0, 1.0], [1.0, 1.0]], [0.0, 0.0], [True, True])
    sd = np.array([0.01])
    z0, _ = mode_errors(model, np.array([1000.0]), sd, pairing="shape")
    z, matched = mode_errors(model, np.array([1000.0]), sd, _measured([[1.0, -1.0]], [1.0]), pairing="shape")
    assert z0 == pytest.approx([0.0]) and matched.tolist() == [1000.0]
    assert abs(z[0]) == pytest.approx(MATCH_REACH / 0.01)


def test_a_pairing_is_followed_to_a_nearby_parameter_set():
    base = _model(**TORSION_AND_LATERAL)
    moved = ModelModes(np.array([1080.0, 1030.0]), np.full(2, 0.02), np.array([False, True]),
                       np.eye(2, dtype=complex)[:, ::-1], np.array([-50.0, 0.0]), (),
                       np.array([[3e-3, 1.0], [-0.9e-3, 1.0]], complex), CHANNELS)
    assert Pairing(base, np.array([1, -1])).at(moved).tolist() == [0, -1]


#: visible modes at 1000, 1300 and 2000 Hz; a mode at 1040 Hz 50 dB down that makes no peak
FOUR = dict(freqs=[1000.0, 1040.0, 1300.0, 2000.0], sensor=[[1.0, 1e-3, 1.0, 1.0], [1.0, -1e-3, -1.0, 1.0]],
            gain_db=[0.0, -50.0, -3.0, -6.0], visible=[True, False, True, True])


def test_by_default_each_measured_mode_pairs_with_the_nearest_visible_mode_within_the_reach():
    model = _model(**FOUR)
    measured = np.array([1035.0, 1290.0, 1500.0, 2250.0])
    # 1035 Hz: the visible 1000 Hz mode, not the closer one that makes no peak; 1500 Hz: 1300 Hz is
    # within 15 % but taken by the closer 1290 Hz (one-to-one), 2000 Hz is 29 % off; 2250 Hz: 12 % off
    assert match_measured(model, measured).tolist() == [0, 2, -1, 3]
    assert match_measured(model, measured, np.full(4, 0.01), pairing="frequency").tolist() == [0, 2, -1, 3]
    # nothing further than MATCH_REACH, whatever the uncertainty
    assert match_measured(model, [2000.0 * math.exp(MATCH_REACH + 0.01)], [0.5]).tolist() == [-1]
    # a measured shape changes nothing by default: neither the pairing nor the objective
    wrong = _measured([[1.0, 1.0]] * 4, [1.0] * 4)
    assert match_measured(model, measured, shapes=wrong).tolist() == [0, 2, -1, 3]
    in_phase = _measured([[1.0, 1.0]], [1.0])          # the 1300 Hz mode is out of phase at the sensors
    z, matched = mode_errors(model, np.array([1300.0]), np.array([0.01]), in_phase)
    assert z.tolist() == [0.0] and matched.tolist() == [1300.0]
    assert mode_errors(model, np.array([1300.0]), np.array([0.01]), in_phase, pairing="shape")[0][0] != 0.0
    # the opt-in shape rule takes the weakly visible mode at 1040 Hz
    assert match_measured(model, measured, pairing="shape").tolist() == pair_modes(model, measured).tolist()
    assert pair_modes(model, measured).tolist()[0] == 1


def test_an_unknown_pairing_is_refused_by_name():
    assert PAIRINGS == ("frequency", "shape")
    assert tuple(CALIBRATION_SCHEMA["properties"]["pairing"]["enum"]) == PAIRINGS
    with pytest.raises(ValueError, match="unknown pairing 'nearest'"):
        match_measured(_model(**FOUR), [1000.0], pairing="nearest")
