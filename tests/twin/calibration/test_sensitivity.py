"""Candidate parameters and their physical bounds, the identifiable subset, matching measured modes."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration.model_modes import model_modes
from twin.calibration.sensitivity import (Candidate, candidate_parameters, match_measured, mode_sensitivity,
                                          select_identifiable)


def _cands(n):
    return [Candidate(f"p{j}", 1.0, 0.5, 2.0, "test") for j in range(n)]


def test_candidates_are_physical_parameters_with_bounds_from_physics(gearbox_fmu):
    cands = {c.name: c for c in candidate_parameters(gearbox_fmu, {"kt12": 1800.0})}
    assert cands["kt12"].nominal == 1800.0
    assert cands["kt12"].lower == pytest.approx(600.0) and cands["kt12"].upper == pytest.approx(5400.0)
    assert cands["I1"].lower == pytest.approx(0.7 * 4.3e-3) and "inertia" in cands["I1"].reason
    assert cands["kt35"].upper == pytest.approx(1.6 * 1.5e4)                  # a shaft, not a coupling
    assert cands["ky4"].upper == pytest.approx(4 * 5e7)                       # a support
    assert cands["mesh_stiffness_scale"].lower == pytest.approx(0.6)
    for excluded in ("ct12", "cx4", "c_mesh", "module", "alpha", "sensor_angle_pinion", "load_start", "z2"):
        assert excluded not in cands
    assert not any("[" in n for n in cands)


def test_collinear_and_insensitive_parameters_are_left_out_by_name():
    rng = np.random.default_rng(0)
    S = rng.normal(0.0, 0.3, (6, 4))
    S = np.column_stack([S, -S[:, 1], 1e-4 * rng.normal(size=6)])     # p4 = -p1 exactly, p5 does nothing
    chosen, left_out, info, cond = select_identifiable(S, _cands(6), np.full(6, 0.01))
    assert set(chosen) >= {"p0", "p2", "p3"} and ("p1" in chosen) != ("p4" in chosen)
    dup = "p4" if "p1" in chosen else "p1"
    assert "cannot tell them apart" in left_out[dup] and ("p1" if dup == "p4" else "p4") in left_out[dup]
    assert "hardly depend" in left_out["p5"]
    assert np.isfinite(cond) and cond < 100


def test_never_more_parameters_than_modes():
    S = np.random.default_rng(1).normal(0.0, 0.5, (3, 8))
    chosen, left_out, _, _ = select_identifiable(S, _cands(8), np.full(3, 0.01))
    assert len(chosen) == 3 and len(left_out) == 5


def test_measured_modes_far_from_every_model_mode_stay_unmatched(gearbox_fmu):
    mm = model_modes(gearbox_fmu, {}, speed_hz=20.0, load_nm=20.0)
    visible = mm.frequency[mm.visible]
    measured = np.array([visible[2] * 1.02, visible[3] * 0.99, 0.5 * (visible[4] + visible[5]) * 1.6])
    idx = match_measured(mm, measured)
    assert mm.frequency[idx[0]] == pytest.approx(visible[2]) and mm.frequency[idx[1]] == pytest.approx(visible[3])
    assert idx[2] == -1 or abs(np.log(mm.frequency[idx[2]] / measured[2])) <= 0.15


def test_the_twins_own_modes_identify_one_parameter_per_mode_group(gearbox_fmu):
    mm = model_modes(gearbox_fmu, {}, speed_hz=20.0, load_nm=20.0)
    freqs = mm.frequency[mm.visible][:6]
    sens = mode_sensitivity(gearbox_fmu, {}, freqs, speed_hz=20.0, load_nm=20.0)
    assert 3 <= len(sens.chosen) <= 6
    assert sens.S.shape == (6, len(sens.candidates))
    # the brake inertia and coupling 4 set the lowest mode together: never both
    assert not {"I13", "kt1213"} <= set(sens.chosen)
    # the two input-shaft pedestals are mirror images: the modes cannot tell them apart
    assert not {"ky4", "ky6"} <= set(sens.chosen)
    assert set(sens.left_out) == {c.name for c in sens.candidates} - set(sens.chosen)
    bounds = sens.bounds()
    assert all(lo < hi for lo, hi in bounds.values()) and set(bounds) == set(sens.chosen)
    assert "not identifiable" in sens.table() and sens.to_dict()["chosen"] == list(sens.chosen)
    # by default the model's own modes pair with themselves by frequency: no reach, no pairing to follow
    assert np.allclose(sens.modes_hz, freqs) and "pairing: by frequency, among the visible" in sens.table()
    assert sens.reach is None and sens.pairing is None and sens.to_dict()["pairing_rule"] == "frequency"


def test_the_shape_pairing_gives_each_paired_mode_its_reach(gearbox_fmu):
    mm = model_modes(gearbox_fmu, {}, speed_hz=20.0, load_nm=20.0)
    freqs = mm.frequency[mm.visible][:6]
    sens = mode_sensitivity(gearbox_fmu, {}, freqs, speed_hz=20.0, load_nm=20.0, pairing="shape")
    # the model's own modes pair with themselves, each within its reach
    assert np.allclose(sens.modes_hz, freqs) and "pairing (measured -> model mode" in sens.table()
    assert np.all(sens.reach > 0) and [p["model_hz"] for p in sens.to_dict()["pairing"]] == sens.modes_hz.tolist()
    assert sens.pairing_rule == "shape" and sens.pairing.index.tolist() == np.flatnonzero(mm.visible)[:6].tolist()


def test_a_lateral_force_shows_a_mode_the_mesh_does_not(gearbox_fmu):
    # the pinion's horizontal mode moves across the line of action: the mesh hardly drives it, a
    # run-out force on the pinion does
    kw = dict(speed_hz=20.0, load_nm=20.0)
    mesh = model_modes(gearbox_fmu, {}, **kw)
    runup = model_modes(gearbox_fmu, {}, **kw, visibility="run-up")
    assert set(runup.visible_by) >= {"mesh", "drive torque", "load torque", "pinion x", "pinion y", "gear x",
                                     "gear y", "process force"}
    assert np.array_equal(mesh.visible, mesh.visible_by["mesh"])
    assert np.array_equal(runup.visible, np.any(list(runup.visible_by.values()), axis=0))
    horizontal = [i for i, c in enumerate(runup.classes) if c.name == "pinion lateral x" and c.shares[c.name] > 0.5]
    assert horizontal
    i = horizontal[0]
    assert not mesh.visible[i] and runup.visible_by["pinion x"][i] and runup.visible[i]
    np.testing.assert_allclose(runup.gain_db[mesh.visible] - mesh.gain_db[mesh.visible], 0.0, atol=1e-6)
    with pytest.raises(ValueError, match="visibility 'all'"):
        model_modes(gearbox_fmu, {}, **kw, visibility="all")


def test_a_calibration_that_pairs_few_of_the_measured_modes_says_so(gearbox_fmu):
    mm = model_modes(gearbox_fmu, {}, speed_hz=20.0, load_nm=20.0)
    visible = np.sort(mm.frequency[mm.visible])
    # two modes the twin has; three between its modes, more than 15 % from any of them
    gaps = [np.sqrt(a * b) for a, b in zip(visible[:-1], visible[1:]) if b / a > 1.45][:3]
    assert len(gaps) == 3
    measured = np.sort(np.r_[visible[2] * 1.01, visible[3] * 0.99, gaps])
    sens = mode_sensitivity(gearbox_fmu, {}, measured, speed_hz=20.0, load_nm=20.0)
    assert len(sens.measured_hz) == 2 and len(sens.unmatched_hz) == 3
    warning = sens.pairing_warning()
    assert warning.startswith("only 2 of 5 measured modes paired with a twin mode; 3 have no visible twin mode "
                              "within 15 %")
    assert f"{gaps[0]:.0f}" in warning and "calibration.visibility`: mesh" in warning
    # the modes given to the sensor path are accounted for: then fewer are left than were paired
    assert sens.pairing_warning(sensor_path_hz=list(sens.unmatched_hz[:2])) is None
    # a twin that pairs every mode gets no warning
    assert mode_sensitivity(gearbox_fmu, {}, visible[:4], speed_hz=20.0, load_nm=20.0).pairing_warning() is None
