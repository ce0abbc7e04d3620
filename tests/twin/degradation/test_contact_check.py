"""The co-simulated contact against the LTCA at the same instantaneous load."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.degradation.base import WearState
from twin.degradation.contact_check import contact_check
from twin.degradation.geometry import GearPair
from twin.degradation.ltca import FlankDamage
from twin.degradation.mapping import mesh_parameters
from twin.errors import ParameterError

GEOMETRY = GearPair()          # the base model's 19/52 pair
XI = np.linspace(0.0, 1.0, 201)


def _worn():
    """Flanks worn like sliding wears them: most at the pinion root and tip, least at the pitch
    point; the gear flank a third as much (tens of um: far more than the elastic approach)."""
    pinion = 30e-6 * ((XI - 0.45) / 0.55) ** 2
    gear = 10e-6 * ((XI - 0.45) / 0.55) ** 2
    return WearState(1e6, XI, pinion, GEOMETRY, gear), FlankDamage.of(XI, pinion_depth=pinion, gear_depth=gear)


def _record(fmu_path, parameters, hz=20.0, torque=20.0):
    from twin.fmu import FMU
    from twin.operating import consistent_start
    inputs = {"motor_speed_ref": 2 * math.pi * hz, "load_torque": torque}
    names = [f"roll[{i}]" for i in (1, 2, 3)] + [f"pair_force[{i}]" for i in (1, 2, 3)]
    with FMU(fmu_path) as fmu:
        fmu.setup(0.0, parameters=consistent_start(parameters, inputs, [v.name for v in fmu.parameters]),
                  inputs=inputs)
        fmu.capture(0.1, 2e-5, ["mesh_force"])
        block = fmu.capture(0.2, 2e-5, names)
    return block[:, :3], block[:, 3:]


def test_the_fmu_unloads_the_pairs_the_ltca_unloads_and_a_sign_flip_is_caught(gearbox_fmu):
    wear, damage = _worn()
    force = 20.0 / GEOMETRY.base_radius_gear
    params = mesh_parameters(GEOMETRY, wear=wear, force=force).parameters
    roll, pair_force = _record(gearbox_fmu, params)
    right = contact_check(GEOMETRY, damage, roll, pair_force, n_samples=150)
    # the worn ends carry nothing for part of the double contact: there is contact loss to check
    assert right.fmu_unloaded > 0.05 and right.ltca_unloaded > 0.05
    assert right.unexplained < 0.05 and right.agreement > 0.9
    # the same wear entering the FMU with its sign flipped (material added, not removed)
    flipped = {k: (-v if k.startswith("profile_deviation") else v) for k, v in params.items()}
    roll, pair_force = _record(gearbox_fmu, flipped)
    wrong = contact_check(GEOMETRY, damage, roll, pair_force, n_samples=150)
    assert wrong.unexplained > 0.15 and wrong.agreement < 0.7


def test_bad_records_are_refused():
    _, damage = _worn()
    with pytest.raises(ParameterError, match="shape"):
        contact_check(GEOMETRY, damage, np.zeros((4, 3)), np.zeros((4, 2)))
    with pytest.raises(ParameterError, match="finite"):
        contact_check(GEOMETRY, damage, np.full((4, 3), np.nan), np.zeros((4, 3)))
