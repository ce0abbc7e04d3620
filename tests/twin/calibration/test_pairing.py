"""Pairing measured modes with model modes: by frequency among the visible modes (default), or by
frequency, shape at the sensors and reach (opt-in), refusing a well-measured shape unlike the model mode's."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from twin.calibration.modal_fit import mode_errors
from twin.calibration.pairing import (MATCH_REACH, PAIRINGS, REFUSE_COHERENCE, REFUSE_MISMATCH, SHAFTS, SIDE_DB,
                                      MeasuredShapes, Pairing, mac, mode_reach, pair_modes, refused, shape_mismatch,
                                      shape_refusals, side_refused, struck_sides)
from twin.calibration.model_modes import ModelModes
from twin.calibration.sensitivity import Candidate, Sensitivity, match_measured
from twin.scenario_schema import CALIBRATION_SCHEMA
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
    # the lateral mode 80 dB down is no candidate, and the torsional one's shape is refused (1 - MAC 0.78)
    assert pair_modes(quiet, [1000.0], shapes=_measured([[1.0, -0.3]], [0.95]), reach=REACH).tolist() == [-1]
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
    assert z0 == pytest.approx([0.0])
    # a shape measured with coherence 0.7 is not trusted enough to refuse: paired, charged 0.7 of a missing mode
    z, matched = mode_errors(model, np.array([1000.0]), sd, _measured([[1.0, -1.0]], [0.7]), pairing="shape")
    assert matched.tolist() == [1000.0] and abs(z[0]) == pytest.approx(0.7 * MATCH_REACH / 0.01)
    # well measured: the pairing is refused and the mode charged as missing
    z, matched = mode_errors(model, np.array([1000.0]), sd, _measured([[1.0, -1.0]], [1.0]), pairing="shape")
    assert np.isnan(matched[0]) and abs(z[0]) == pytest.approx(MATCH_REACH / 0.01)


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


#: one torsional model mode at 1340 Hz, both sensors in phase; the measured mode at 1790 Hz is out
#: of phase at the sensors (a casing panel's shape), 29 % away but within the mode's reach
TORSION_ONLY = dict(freqs=[1340.0], sensor=[[1.0], [1.0]], gain_db=[0.0], visible=[True])
WIDE = np.array([[0.4, 0.4]])


def test_a_well_measured_shape_unlike_the_model_modes_is_refused_and_reported():
    model = _model(**TORSION_ONLY)
    panel = _measured([[1.0, -1.0]], [0.95])
    assert pair_modes(model, [1790.0], reach=WIDE).tolist() == [0]          # without the shape: paired
    index = pair_modes(model, [1790.0], shapes=panel, reach=WIDE)
    assert index.tolist() == [-1]
    (refusal,) = shape_refusals(model, [1790.0], index, shapes=panel, reach=WIDE)
    assert refusal["measured_hz"] == 1790.0 and refusal["model_hz"] == 1340.0
    assert refusal["shape_mismatch"] == pytest.approx(1.0) and refusal["coherence"] == 0.95
    # a mode out of reach is unpaired for its frequency, not refused for its shape
    narrow = np.array([[0.1, 0.1]])
    assert shape_refusals(model, [1790.0], pair_modes(model, [1790.0], shapes=panel, reach=narrow),
                          shapes=panel, reach=narrow) == []
    # refused by the least-cost pairing too, with no reach given (15 % either way)
    assert pair_modes(model, [1300.0], shapes=panel).tolist() == [-1]


def test_a_refused_mode_takes_a_model_mode_of_its_shape_when_one_is_within_reach():
    model = _model(**TORSION_AND_LATERAL)                                  # lateral: gear sensor at -0.3
    out_of_phase = _measured([[1.0, -0.5]], [0.95])
    assert refused(model, out_of_phase, np.array([0, 1])).tolist() == [[True, False]]
    assert pair_modes(model, [1020.0], shapes=out_of_phase, reach=REACH).tolist() == [1]
    assert shape_refusals(model, [1020.0], np.array([1]), shapes=out_of_phase, reach=REACH) == []


def test_a_poorly_measured_or_moderately_unlike_shape_is_not_refused():
    model = _model(**TORSION_ONLY)
    # coherence below REFUSE_COHERENCE: the shape may be bent by a neighbour or the noise; it only costs
    weak = _measured([[1.0, -1.0]], [REFUSE_COHERENCE - 0.05])
    assert pair_modes(model, [1400.0], shapes=weak, reach=WIDE).tolist() == [0]
    assert shape_refusals(model, [1400.0], np.array([-1]), shapes=weak, reach=WIDE) == []
    # well measured, but 1 - MAC at most REFUSE_MISMATCH: a phase of 90 deg at equal levels is exactly 0.5
    quarter = _measured([[1.0, 1j]], [0.99])
    assert 1 - mac(np.array([1.0, 1j]), np.array([1.0, 1.0])) == pytest.approx(REFUSE_MISMATCH)
    assert pair_modes(model, [1400.0], shapes=quarter, reach=WIDE).tolist() == [0]
    assert pair_modes(model, [1400.0], shapes=_measured([[1.0, np.exp(1.7j)]], [0.99]), reach=WIDE).tolist() == [-1]


def test_pairing_by_frequency_alone_ignores_the_refusal():
    model = _model(**TORSION_ONLY)
    panel = _measured([[1.0, -1.0]], [1.0])
    assert match_measured(model, [1300.0], shapes=panel).tolist() == [0]
    assert match_measured(model, [1300.0], shapes=panel, pairing="frequency").tolist() == [0]
    z, matched = mode_errors(model, np.array([1300.0]), np.array([0.01]), panel)
    assert matched.tolist() == [1340.0] and z[0] == pytest.approx(math.log(1340 / 1300) / 0.01)
    # the shape rule charges the refused mode as a missing one
    z, matched = mode_errors(model, np.array([1300.0]), np.array([0.01]), panel, pairing="shape")
    assert np.isnan(matched[0]) and z[0] == pytest.approx(MATCH_REACH / 0.01)


def test_the_sensitivity_json_says_where_each_refused_mode_went():
    refusals = ({"measured_hz": 1790.0, "model_hz": 1340.0, "model_gain_db": -44.0, "shape_mismatch": 0.99,
                 "coherence": 0.95},
                {"measured_hz": 13.2, "model_hz": 15.0, "model_gain_db": -10.0, "shape_mismatch": 0.8,
                 "coherence": 0.9})
    sens = Sensitivity(np.array([1000.0]), np.array([1010.0]), np.array([0.01]), (Candidate("k", 1.0, 0.5, 2.0, ""),),
                       np.array([[0.5]]), ("k",), {}, {"k": 9.0}, 1.0, (1790.0, 13.2), (), pairing_rule="shape",
                       refused=refusals)
    assert "refused for their shape" in sens.table() and "1790.0 Hz (model 1340.0 Hz, 0.99)" in sens.table()
    plain = sens.to_dict()
    assert [r["measured_hz"] for r in plain["refused_by_shape"]] == [1790.0, 13.2]
    assert "goes_to" not in plain["refused_by_shape"][0] and "sensor_path_hz" not in plain
    out = sens.to_dict(sensor_path_hz=[1790.0])
    assert [r["goes_to"] for r in out["refused_by_shape"]] == ["sensor_path", "unpaired"]
    assert [r["goes_to"] for r in sens.to_dict(sensor_path_hz=[])["refused_by_shape"]] == ["unpaired"] * 2
    assert sens.refused[0].get("goes_to") is None                             # the record itself is not changed


#: a model mode on each shaft: 1000 Hz on the input shaft (+20 dB), 1100 Hz on the output shaft (-20 dB),
#: 1300 Hz on both (+2 dB)
TWO_SHAFTS = dict(freqs=[1000.0, 1100.0, 1300.0], sensor=[[1.0, 1.0, 1.0], [1.0, 1.0, 1.0]], gain_db=[0.0, 0.0, 0.0],
                  visible=[True, True, True])
STRUCK = {"hammer_pinion": "input", "hammer_gear": "output"}


def _sided(side_db):
    return replace(_model(**TWO_SHAFTS), side_db=np.array(side_db, float))


def test_a_modes_shaft_from_its_levels_per_struck_point():
    evidence = [{"struck_db": {"hammer_pinion": 0.0, "hammer_gear": -9.5}},
                {"struck_db": {"hammer_pinion": -12.0, "hammer_gear": 0.0, "hammer_other": 3.0}},
                {"struck_db": {"hammer_pinion": 0.0}}, {}]
    assert np.allclose(struck_sides(evidence, STRUCK)[:2], [9.5, -12.0])
    assert np.isnan(struck_sides(evidence, STRUCK)[2:]).all()
    # two records on one shaft: the louder counts
    both = {**STRUCK, "hammer_pinion_side": "input"}
    assert struck_sides([{"struck_db": {"hammer_pinion": -8.0, "hammer_pinion_side": -1.0, "hammer_gear": 0.0}}],
                        both).tolist() == [-1.0]
    assert struck_sides(evidence, {}) is None and struck_sides([{}], STRUCK) is None
    # from one channel's evidence (no shapes) the struck levels alone make the record
    shapes = MeasuredShapes.from_evidence(evidence, STRUCK)
    assert shapes.channels == () and shapes.vectors.shape == (4, 0) and shapes.side_db[0] == pytest.approx(9.5)
    assert MeasuredShapes.from_evidence(evidence) is None
    # measured modes dropped (the foundation's) take their side levels with them
    kept = shapes.subset(np.array([False, True, True, False]))
    assert kept.side_db[0] == pytest.approx(-12.0) and kept.vectors.shape == (2, 0) and kept.coherence.size == 2


@pytest.mark.parametrize("pairing", PAIRINGS)
def test_a_mode_struck_on_one_shaft_is_never_paired_with_a_model_mode_on_the_other(pairing):
    model = _sided([20.0, -20.0, 2.0])
    measured = np.array([1010.0])
    # by frequency, 1010 Hz goes to the input shaft's 1000 Hz mode
    assert match_measured(model, measured, pairing=pairing).tolist() == [0]
    # struck 10 dB louder on the output shaft: the output shaft's mode at 1100 Hz (9 % off) instead
    gear = MeasuredShapes((), np.zeros((1, 0), complex), np.zeros(1), np.array([-10.0]))
    assert match_measured(model, measured, pairing=pairing, shapes=gear).tolist() == [1]
    # struck on the input shaft: unchanged; alike on both (within SIDE_DB): unchanged
    for side in (10.0, SIDE_DB - 0.5, -(SIDE_DB - 0.5)):
        shapes = MeasuredShapes((), np.zeros((1, 0), complex), np.zeros(1), np.array([side]))
        assert match_measured(model, measured, pairing=pairing, shapes=shapes).tolist() == [0]
    # a model mode that lives on both shafts takes a mode struck on either
    assert match_measured(model, np.array([1290.0]), pairing=pairing, shapes=gear).tolist() == [2]
    # a model without side levels (another naming) pairs by frequency alone
    assert match_measured(_model(**TWO_SHAFTS), measured, pairing=pairing, shapes=gear).tolist() == [0]


def test_the_refusal_needs_both_sides_clear():
    model = _sided([20.0, -SIDE_DB + 0.5, np.nan])
    gear = MeasuredShapes((), np.zeros((2, 0), complex), np.zeros(2), np.array([-10.0, np.nan]))
    assert side_refused(model, gear, np.arange(3)).tolist() == [[True, False, False], [False, False, False]]
    assert side_refused(model, None, np.arange(3)).shape == (1, 3)
    assert SHAFTS == ("input", "output")
    assert set(CALIBRATION_SCHEMA["properties"]["struck_shafts"]["additionalProperties"]["enum"]) == set(SHAFTS)


def test_a_mode_left_unpaired_for_its_shaft_is_a_note():
    from twin.calibration.sensitivity import side_notes

    model = replace(_sided([20.0, -20.0, 2.0]), visible=np.array([True, False, True]))
    gear = MeasuredShapes((), np.zeros((2, 0), complex), np.zeros(2), np.array([-10.0, -10.0]))
    measured = np.array([1010.0, 1295.0])
    match = match_measured(model, measured, shapes=gear)
    assert match.tolist() == [-1, 2]
    (note,) = side_notes(model, measured, match, gear)
    assert note.startswith("measured 1010 Hz (struck -10.0 dB input over output shaft) not paired with the "
                           "model's 1000 Hz mode (+20.0 dB)")
    assert side_notes(model, measured, match_measured(model, measured), None) == []
