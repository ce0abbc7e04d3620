"""MeshLoad: binning of co-simulated samples, quasi-static load sharing."""
from __future__ import annotations

import numpy as np
import pytest

from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad
from twin.degradation.mapping import HEALTHY_K_PAIR
from twin.errors import ParameterError

GEOMETRY = GearPair()
CR = GEOMETRY.contact_ratio


def _fmu_like_samples(force_of_xi, n_samples=20000, cr=CR):
    """roll[1..3] and pair_force[1..3] as GearTwin.Gearbox21 produces them over a steady run."""
    q = (np.arange(n_samples) * 0.013) % 1.0 + 1e-6                # mesh phase, irrational-ish stride
    roll = np.stack([(q + 1) / cr, q / cr, (q - 1) / cr], axis=1)
    force = np.where((roll >= 0) & (roll <= 1), force_of_xi(np.clip(roll, 0, 1)), 0.0)
    return roll, force


def test_from_samples_recovers_a_known_force_profile():
    profile = lambda x: 100.0 + 50.0 * x                           # noqa: E731
    roll, force = _fmu_like_samples(profile)
    load = MeshLoad.from_samples(roll, force, n_grid=51)
    assert load.xi.shape == (51,) and load.covers_path
    # Bin averages of a linear function: exact up to the bin's sampling asymmetry.
    assert np.allclose(load.force, profile(load.xi), atol=0.3)


def test_from_samples_averages_repeated_samples_and_interpolates_empty_bins():
    roll = np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [-0.2, 1.3]])
    force = np.array([[10.0, 30.0], [40.0, 60.0], [100.0, 100.0], [999.0, 999.0]])
    load = MeshLoad.from_samples(roll, force, n_grid=5, max_gap=0.5)
    # Bins 0, 2, 4 hold the means 20, 50, 100; bins 1 and 3 are interpolated; out-of-contact ignored.
    assert np.allclose(load.force, [20.0, 35.0, 50.0, 75.0, 100.0])


def test_from_samples_rejects_a_recording_that_misses_part_of_the_path():
    roll = np.linspace(0.0, 0.6, 500)[:, None]
    with pytest.raises(ParameterError, match=r"never covers xi in \(0\.6"):
        MeshLoad.from_samples(roll, np.ones_like(roll))
    with pytest.raises(ParameterError, match="no sample on the path"):
        MeshLoad.from_samples(np.full((5, 3), 2.0), np.ones((5, 3)))


@pytest.mark.parametrize("roll, force, pattern", [
    (np.zeros((4, 3)), np.zeros((4, 2)), "same shape"),
    (np.zeros((4, 3)), np.full((4, 3), np.nan), "finite"),
    (np.zeros((4, 3)), -np.ones((4, 3)), "-1.0"),
])
def test_from_samples_invalid_inputs(roll, force, pattern):
    with pytest.raises(ParameterError, match=pattern):
        MeshLoad.from_samples(roll, force)


def test_mesh_load_validates_its_arrays():
    with pytest.raises(ParameterError, match="strictly increasing"):
        MeshLoad([0.0, 0.5, 0.5, 1.0], [1.0, 1.0, 1.0, 1.0])
    with pytest.raises(ParameterError, match="-3.0"):
        MeshLoad([0.0, 1.0], [1.0, -3.0])
    load = MeshLoad([0.0, 1.0], [1.0, 3.0])
    assert load.force_at(0.5) == pytest.approx(2.0)
    with pytest.raises(ValueError):
        load.force[0] = 5.0                                          # read-only: states are immutable


def test_static_load_single_and_double_pair_zones():
    torque = 20.0 * 19 / 52                                          # 20 N.m brake -> pinion torque
    load = MeshLoad.static(GEOMETRY, torque, n_grid=201)
    total = torque / GEOMETRY.base_radius_pinion
    assert total == pytest.approx(272.87, abs=0.01)                  # the FMU's mesh_force_static
    single = (load.xi > (CR - 1) / CR + 1e-9) & (load.xi < 1 / CR - 1e-9)
    assert np.allclose(load.force[single], total)
    # Double zone: the pair at xi and its partner one base pitch later share the force by stiffness.
    xi = 0.1
    k = np.interp([xi, xi + 1 / CR], np.linspace(0, 1, 11), HEALTHY_K_PAIR)
    assert load.force_at(xi) == pytest.approx(total * k[0] / k.sum(), rel=1e-3)
    partner = load.force_at(xi + 1 / CR)
    assert load.force_at(xi) + partner == pytest.approx(total, rel=1e-3)


def test_static_load_with_profile_deviation_unloads_the_worn_pair():
    torque = 5.0 * 19 / 52
    total = torque / GEOMETRY.base_radius_pinion
    # 10 um missing at the pinion root: far more than the elastic approach (~0.2 um), so the
    # partner pair carries the whole load while the root is in contact.
    deviation = {f"profile_deviation[{i}]": (10e-6 if i == 1 else 0.0) for i in range(1, 12)}
    load = MeshLoad.static(GEOMETRY, torque, parameters=deviation)
    assert load.force[0] == 0.0
    assert load.force_at(1 / CR) == pytest.approx(total, rel=1e-6)
    # A uniform deviation (thinner teeth, more backlash) does not change the sharing.
    uniform = {f"profile_deviation[{i}]": 20e-6 for i in range(1, 12)}
    assert np.allclose(MeshLoad.static(GEOMETRY, torque, parameters=uniform).force,
                       MeshLoad.static(GEOMETRY, torque).force)


def test_static_load_invalid_inputs():
    with pytest.raises(ParameterError, match="-1.0"):
        MeshLoad.static(GEOMETRY, -1.0)
    with pytest.raises(ParameterError, match=r"k_pair\[3\] is missing"):
        MeshLoad.static(GEOMETRY, 1.0, parameters={"k_pair[1]": 1e8, "k_pair[2]": 1e8, "k_pair[4]": 1e8})
    zero = {f"k_pair[{i}]": 0.0 for i in range(1, 12)}
    with pytest.raises(ParameterError, match="no pair stiffness"):
        MeshLoad.static(GEOMETRY, 1.0, parameters=zero)
