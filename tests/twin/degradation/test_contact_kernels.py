"""The compiled LTCA loops give the NumPy formulation's numbers."""
from __future__ import annotations

import math

import numpy as np

from twin.degradation import GearPair
from twin.degradation.ltca import FlankDamage, _active_set, _active_set_numpy, contact_for

G = GearPair()
XI = np.linspace(0.0, 1.0, 201)
RNG = np.random.default_rng(3)
DAMAGE = FlankDamage.of(XI, pinion_depth=1e-5 * (1 + np.sin(7 * XI)) + RNG.uniform(0, 1e-7, XI.size),
                        gear_depth=RNG.uniform(0, 2e-6, XI.size), pinion_pitted=RNG.uniform(0, 0.5, XI.size))


def test_the_pair_gap_is_the_numpy_formula_bit_for_bit():
    contact = contact_for(G)
    x = np.linspace(-4e-3, 4e-3, 1501)
    for xc in (0.0, 0.31, 0.77, 1.0):
        sep, pitted = contact.gap(xc, x, DAMAGE)
        r = contact._radius(xc)
        xi1, xi2, ok = contact._flank_points(xc, x)
        ref = np.where(ok, x * x / (2.0 * r) + np.interp(xi1, XI, DAMAGE.pinion_depth)
                       + np.interp(xi2, XI, DAMAGE.gear_depth), np.inf)
        ref_pitted = 1.0 - (1.0 - np.interp(xi1, XI, DAMAGE.pinion_pitted)) * (
            1.0 - np.interp(xi2, XI, DAMAGE.gear_pitted))
        np.testing.assert_array_equal(sep, ref)
        np.testing.assert_array_equal(pitted, ref_pitted)
        assert np.isinf(sep).any() and np.isfinite(sep).any()


def test_the_half_plane_kernel_is_the_closed_form_bit_for_bit():
    contact = contact_for(G)
    n, w, depth = 40, 3e-6, 2e-3
    intact = np.linspace(0.5, 1.0, n)
    d = w * np.arange(-(n - 1), n)

    def prim(t):
        at = np.abs(t)
        return np.where(at > 0, t * np.log(np.where(at > 0, at, 1.0)) - t, 0.0)
    row = w * math.log(depth) - (prim(d + w / 2) - prim(d - w / 2))
    idx = np.arange(n)
    scale = 2.0 / (math.pi * G.contact_modulus * G.face_width * w)
    ref = scale * row[idx[:, None] - idx[None, :] + n - 1] / intact[None, :]
    np.testing.assert_array_equal(contact._kernel(np.zeros(n), w, depth, intact), ref)


def test_the_active_set_solves_the_contact_problem_as_numpy_does():
    """Every contact problem of a worn mesh cycle: the compiled active set and the NumPy loop
    agree to rounding (forces to 1e-12 of the total, the approach to 1e-14 relative)."""
    import twin.degradation.ltca as ltca
    seen = []
    original = ltca._active_set

    def both(c, sep, force):
        q, delta = original(c, sep, force)
        q_ref, delta_ref = _active_set_numpy(c, sep, force)
        seen.append((np.max(np.abs(q - q_ref)) / force, abs(delta - delta_ref) / abs(delta_ref)))
        return q, delta
    ltca._active_set = both
    try:
        contact_for(G).mesh_cycle(200.0, DAMAGE, n_positions=12)
    finally:
        ltca._active_set = original
    worst = np.max(np.array(seen), axis=0)
    assert len(seen) == 12 and worst[0] < 1e-12 and worst[1] < 1e-14
    assert _active_set is original
