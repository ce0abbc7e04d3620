"""GearTwin.Gearbox21Overhangs: the parts carried outside the bearings on overhung shaft ends."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.calibration.mode_classes import mass_values
from twin.calibration.sensitivity import candidate_parameters, model_modes
from twin.fmu import FMU

KW = dict(speed_hz=20.0, load_nm=20.0, channels=("accel_pinion_casing", "accel_gear_casing"))
ENDS = ("input shaft ends x", "input shaft ends y", "output shaft ends x", "output shaft ends y")


def _get(path, parameters, names):
    with FMU(path) as fmu:
        fmu.setup(parameters=parameters)
        return dict(zip(names, fmu.get(list(names))))


def test_an_end_hangs_on_its_stub_and_both_bearings_levered(overhangs_fmu):
    # a force F at the end of a stub c beyond a bearing of a span L deflects it by
    # F c^2 (L + c) / (3 E I) on rigid bearings; the bearing beside it takes F (L + c) / L and the
    # other F c / L, each moving the end by its own deflection times the same lever
    E, rho, d, L, c = 2.1e11, 7850.0, 0.024, 0.16, 0.08
    p = {"d_shaft_input": d, "span_input": L, "overhang6": c, "kx_bearing6": 1.0e8, "kx_bearing4": 3.0e8,
         "end_mass6": 0.5}
    v = _get(overhangs_fmu, p, ("k_end6_x", "m_end6", "k_end4_x"))
    EI = E * math.pi * d ** 4 / 64
    compliance = c * c * (L + c) / (3 * EI) + ((L + c) / L) ** 2 / 1.0e8 + (c / L) ** 2 / 3.0e8
    assert v["k_end6_x"] == pytest.approx(1 / compliance, rel=1e-9)
    # the stub's own mass moves with the end by the cantilever's Rayleigh share 33/140
    assert v["m_end6"] == pytest.approx(0.5 + 33 / 140 * rho * math.pi * d * d / 4 * c, rel=1e-9)
    # the mode classes weigh the ends with these masses
    assert mass_values(overhangs_fmu, p)["m_end6"] == pytest.approx(v["m_end6"], rel=1e-9)
    # the end beside bearing 4 is levered the other way round (bearing 4 beside it)
    c4 = 0.06
    compliance4 = c4 * c4 * (L + c4) / (3 * EI) + ((L + c4) / L) ** 2 / 3.0e8 + (c4 / L) ** 2 / 1.0e8
    assert v["k_end4_x"] == pytest.approx(1 / compliance4, rel=1e-9)


def test_the_ends_add_their_own_modes_below_a_few_khz(overhangs_fmu, shafts_fmu):
    base = model_modes(shafts_fmu, {}, **KW)
    mm = model_modes(overhangs_fmu, {}, **KW)
    assert np.all(mm.damping > 0)
    assert len(mm.frequency) >= len(base.frequency) + 8 - 2     # eight DOFs; a pair may pass fmax
    for cls in ENDS:
        k = max(range(len(mm.classes)), key=lambda i: mm.classes[i].shares.get(cls, 0.0))
        # a 0.35-0.6 kg part on a 25 mm stub of 60-90 mm: a few hundred Hz to about 1 kHz
        assert 250.0 < mm.frequency[k] < 1500.0 and mm.classes[k].shares[cls] > 0.3
    # the mesh reaches some of them through the pedestals (visible at the casing sensors)
    visible_end = [c.name for c, vis in zip(mm.classes, mm.visible) if vis and c.name in ENDS]
    assert visible_end


def test_light_short_ends_leave_the_shafts_model(overhangs_fmu, shafts_fmu):
    # parts of a gram on 5 mm stubs: their modes move far above 5 kHz and the rest of the gearbox is
    # Gearbox21Shafts again; a wrong sign of the reaction on the pedestals would show here
    tiny = {f"end_mass{n}": 1e-3 for n in (4, 6, 9, 11)}
    tiny.update({f"overhang{n}": 5e-3 for n in (4, 6, 9, 11)})
    tiny.update(k_coupling_radial_input=1.0, k_coupling_radial_output=1.0)
    base = model_modes(shafts_fmu, {}, fmax=5000.0, **KW)
    mm = model_modes(overhangs_fmu, tiny, fmax=5000.0, **KW)
    assert not any(c.name in ENDS for c in mm.classes)
    f0 = np.sort(base.frequency)
    f1 = np.sort(mm.frequency)
    assert f1.shape == f0.shape
    np.testing.assert_allclose(f1, f0, rtol=2e-3)


def test_the_ends_are_calibratable_within_physical_bounds(overhangs_fmu):
    cands = {c.name: c for c in candidate_parameters(overhangs_fmu)}
    assert cands["overhang6"].lower == pytest.approx(0.8 * 0.09)
    assert cands["overhang6"].upper == pytest.approx(1.25 * 0.09)
    assert cands["end_mass4"].reason.startswith("mass")
    assert cands["k_coupling_radial_input"].reason.startswith("elastomer coupling")
    assert not {"k_end4_x", "m_end9", "c_end11_y"} & set(cands)      # computed, not free
