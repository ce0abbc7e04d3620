"""twin.linearize: Jacobian through Model Exchange and natural frequencies with known answers."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from twin.linearize import modes, natural_frequencies, state_jacobian


def test_two_mass_frequencies_match_closed_form(two_mass_fmu):
    m1, m2, k1, k12, d1 = 1.0, 0.5, 100.0, 50.0, 0.2
    M = np.diag([m1, m2])
    K = np.array([[k1 + k12, -k12], [-k12, k12]])
    undamped = np.sqrt(np.sort(scipy.linalg.eigvalsh(K, M))) / (2 * np.pi)
    # |lambda| of the damped state matrix, written out by hand (states x1, x2, v1, v2)
    C = np.array([[d1, 0.0], [0.0, 0.0]])
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam = np.linalg.eigvals(A)
    damped = np.sort(np.abs(lam[lam.imag > 0])) / (2 * np.pi)
    got = natural_frequencies(two_mass_fmu, n=2)
    np.testing.assert_allclose(got, damped, rtol=1e-7)
    np.testing.assert_allclose(got, undamped, rtol=1e-4)  # light damping


def test_two_mass_jacobian_is_the_state_matrix(two_mass_fmu):
    A, names = state_jacobian(two_mass_fmu, samples=1)
    assert names == ["x1", "v1", "x2", "v2"]
    np.testing.assert_allclose(A[1], [-150.0, -0.2, 50.0, 0.0], atol=1e-5)
    np.testing.assert_allclose(A[3], [100.0, 0.0, -100.0, 0.0], atol=1e-5)


def test_gearbox_has_twenty_oscillatory_modes(gearbox_fmu):
    """21 DOF minus the rigid-body rotation of the drive train: 20 modes."""
    A, names = state_jacobian(gearbox_fmu)
    assert A.shape == (42, 42)
    freqs, zeta = modes(A)
    assert freqs.size == 20
    assert np.all(np.diff(freqs) > 0)
    assert np.all((zeta > 0) & (zeta < 0.3))
    assert 10 < freqs[0] < 100


def test_stiffer_mesh_raises_mesh_modes(gearbox_fmu):
    base = natural_frequencies(gearbox_fmu, n=20)
    stiff = natural_frequencies(gearbox_fmu, n=20, parameters={"mesh_stiffness_scale": 2.0})
    assert stiff[-1] > base[-1] * 1.2
    assert stiff[0] == pytest.approx(base[0], rel=0.05)
