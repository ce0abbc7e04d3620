"""GearTwin.Gearbox21's per-tooth pit field: pits at different places on different teeth make
shaft-order sidebands of the mesh harmonics that one shape times a scale per tooth cannot make."""
from __future__ import annotations

import fmpy
import numpy as np
import pytest

Z1, N_PROFILE = 19, 11


def _sidebands(fmu, field: np.ndarray) -> np.ndarray:
    """Amplitudes [N] of the mesh force at GMF 1-3 -2, -1, +1, +2 shaft orders, (12,), from 0.25 s
    of steady running at 20 Hz with ``field`` (z1, n_profile) [m] as tooth_pit_field."""
    start = {f"tooth_pit_field[{k}]": float(v) for k, v in enumerate(field.ravel(), start=1)}
    res = fmpy.simulate_fmu(str(fmu), stop_time=0.3, output_interval=1e-4, fmi_type="CoSimulation",
                            start_values=start, output=["mesh_force", "motor_speed"])
    keep = res["time"] >= 0.05
    x = res["mesh_force"][keep]
    w = np.hanning(x.size)
    spec = np.abs(np.fft.rfft((x - x.mean()) * w)) * 2 / w.sum()
    freq = np.fft.rfftfreq(x.size, 1e-4)
    shaft = float(np.mean(res["motor_speed"][keep])) / (2 * np.pi)
    return np.array([spec[np.abs(freq - (h * Z1 + s) * shaft) < 0.6 * shaft].max()
                     for h in (1, 2, 3) for s in (-2, -1, 1, 2)])


@pytest.mark.needs_gcc
def test_teeth_pitted_at_different_places_make_sidebands_a_rank_one_field_does_not(gearbox_fmu):
    rng = np.random.default_rng(0)
    field = np.zeros((Z1, N_PROFILE))
    for j in range(Z1):                      # one pit per tooth, at a node and depth of its own
        field[j, rng.integers(1, N_PROFILE - 1)] = rng.uniform(0.5e-6, 1.5e-6)
    field -= field.mean(axis=0)              # the typical tooth is k_pair's: only differences remain
    u, s, vt = np.linalg.svd(field, full_matrices=False)
    rank_one = s[0] * np.outer(u[:, 0], vt[0])
    assert np.linalg.norm(field - rank_one) > 0.5 * np.linalg.norm(field)
    healthy = _sidebands(gearbox_fmu, np.zeros_like(field))
    full = _sidebands(gearbox_fmu, field)
    one = _sidebands(gearbox_fmu, rank_one)
    rss = lambda a: float(np.sqrt(np.sum(a ** 2)))
    # identical teeth: no shaft orders; the whole field: sidebands well above the rank-1 form's
    assert rss(full) > 10 * rss(healthy)
    assert rss(full) > 1.4 * rss(one)
