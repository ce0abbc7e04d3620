"""The hand-written numpy gearbox model against the compiled FMU and against closed forms.

Relative error everywhere is ``max|a - b| / max|b|`` over the compared samples, ``b`` being
the reference (compiled FMU or closed form).
"""
from __future__ import annotations

import dataclasses
import math

import fmpy
import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy import extract

from twin.reference import gearbox_numpy as gn
from twin.reference.gearbox_numpy import GearboxParams

ACCEL_FORCE = ("accel_pinion_casing", "accel_gear_casing", "mesh_force")
ALL_DAMPERS = tuple(f.name for f in dataclasses.fields(GearboxParams)
                    if f.name[0] == "c" and f.name[1] in "txy") + ("c_mesh",)


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(np.asarray(b))))


def simulate_compiled(fmu, stop_time, output_interval, start_values=None):
    return fmpy.simulate_fmu(str(fmu), stop_time=stop_time, output_interval=output_interval,
                             fmi_type="CoSimulation", start_values=start_values or {})


def degraded_params() -> tuple[GearboxParams, dict[str, float]]:
    """Non-default parameters that exercise every branch of the mesh model, plus inputs.

    A weak tooth (factor 0.6), a tooth with 2 um extra material loss, tip relief on the
    profile, pits on teeth 3-5 (and a tooth pitted less than the mean) and a per-tooth pit field
    that differs along the profile on teeth 2, 5, 6 make pairs lose
    contact part of the time; rotated sensors, a mesh phase offset,
    and inputs that differ from the pre-load complete the set.
    """
    factor = [1.0] * 19
    factor[3] = 0.6
    offset = [0.0] * 19
    offset[7] = 2e-6
    # per-tooth pit field: pits at different places on teeth 2, 5 and 6, and one shape at three
    # scales on teeth 3-5 (tooth 5 has both; a negative scale: pitted less than k_pair describes)
    field = np.zeros((19, 11))
    field[1, 2:6] = (0.3e-6, 1.2e-6, 0.9e-6, 0.2e-6)
    field[4, 6:9] = (0.5e-6, 1.4e-6, 0.4e-6)
    field[5, :] = -0.2e-6
    field[2:5] += np.outer((1.0, 0.4, -0.3), (0, 0, 0.2e-6, 0.8e-6, 1.5e-6, 0.6e-6, 0, 0, 0, 0, 0))
    p = GearboxParams(tooth_stiffness_factor=factor, tooth_deviation_offset=offset,
                      tooth_pit_field=field.ravel(),
                      profile_deviation=(0, 0, 0, 0, 0, 0, 0, 0, 0.5e-6, 1.5e-6, 3e-6),
                      sensor_angle_pinion=math.pi / 2, sensor_angle_gear=0.7, mesh_phase0=0.3,
                      c_mesh=800.0, mesh_stiffness_scale=0.9, load_start=30.0, I5=2.8e-4, m5=0.7)
    u = {"motor_speed_ref": 2 * math.pi * 25, "drive_torque": 1.5, "load_torque": 35.0}
    return p, u


# ---- numpy model vs compiled FMU ------------------------------------------------------------
@pytest.mark.parametrize("case", ["default", "degraded", "gear errors", "misaligned"])
def test_matches_compiled_fmu(gearbox_fmu, wheel_fmu, case):
    """20 ms at 1e-5 s output: accelerations and mesh force agree with the FMU to 1e-3 relative.

    Both integrate the same equations with RK4 at 5e-6 s (two sub-steps per output
    interval), so the measured agreement is ~1e-10; the stated tolerance, relative error
    ``max|numpy - fmu| / max|fmu| < 1e-3``, leaves room for compiler-level reordering.  The
    other six outputs are held to the same bound.
    """
    if case == "default":
        p, u = GearboxParams(), {}
    else:
        p, u = degraded_params()
    fmu = gearbox_fmu
    if case == "gear errors":
        # the variant: a gear with run-out and gear tooth 6 (the runs pass gear teeth 1-10) 1.5 um short
        wheel = 0.5e-6 * (1 - np.cos(2 * np.pi * np.arange(52) / 52 + 0.4))
        wheel[5] += 1.5e-6
        p, fmu = p.replace(wheel_tooth_deviation_offset=wheel), wheel_fmu
    if case == "misaligned":
        p = p.replace(lead_mismatch=15e-6)          # a few um of approach: the face partly in contact
    t, out = gn.simulate_rk4(p, u, stop_time=0.02, step=5e-6, output_interval=1e-5)
    ref = simulate_compiled(fmu, 0.02, 1e-5, {**p.fmu_start_values(), **u})
    assert ref["time"].shape == t.shape
    np.testing.assert_allclose(ref["time"], t, rtol=0, atol=1e-12)
    for name in gn.OUTPUT_NAMES:
        assert rel_err(out[name], ref[name]) < 1e-3, name
    for name in ACCEL_FORCE:
        assert np.max(np.abs(ref[name])) > 0, name   # a zero reference would make the check vacuous


def test_parameters_and_start_state_match_fmu(gearbox_fmu, tmp_path):
    """Every FMU parameter has a GearboxParams field with the same default; the derived
    (calculated) parameters and the state after initialisation agree to 1e-12 relative."""
    md = read_model_description(str(gearbox_fmu))
    p = GearboxParams()
    by_name = {v.name: v for v in md.modelVariables}
    fields = set(p.fmu_start_values(only_changed=False))
    fmu_params = {v.name for v in md.modelVariables
                  if v.causality == "parameter" and not v.name.startswith("solver.")}
    assert fmu_params == fields
    for name in fields:
        base, _, index = name.partition("[")
        value = getattr(p, base)[int(index[:-1]) - 1] if index else getattr(p, base)
        assert float(by_name[name].start) == pytest.approx(value, rel=1e-15, abs=0), name
    assert int(by_name["z1"].start) == p.z1 and int(by_name["n_profile"].start) == p.n_profile
    assert int(by_name["z2"].start) == p.z2

    derived = [v.name for v in md.modelVariables if v.causality == "calculatedParameter"]
    names = derived + list(gn.STATE_NAMES)
    unzipdir = extract(str(gearbox_fmu), unzipdir=str(tmp_path / "fmu"))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="params")
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        values = dict(zip(names, fmu.getReal([by_name[n].valueReference for n in names])))
        fmu.terminate()
    finally:
        fmu.freeInstance()
    assert set(derived) == {"rb1", "rb2", "contact_ratio", "torque_out", "torque_in",
                            "mesh_force_static", "speed_start", "k_mesh_mean", "line_of_action_length",
                            "contact_path_length", "contact_start_radius", "roll_pitch",
                            "pitch_curvature_pinion", "pitch_curvature_gear", "hertz_half_width"}
    for name in derived:
        assert values[name] == pytest.approx(getattr(p, name), rel=1e-12), name
    x0 = gn.initial_state(p)
    np.testing.assert_allclose([values[n] for n in gn.STATE_NAMES], x0, rtol=1e-12, atol=1e-15)


def test_solve_ivp_agrees_with_rk4():
    """The adaptive scipy route (DOP853, rtol 1e-8) and fixed-step RK4 agree to 1e-3 over 3 ms."""
    p = GearboxParams()
    _, a = gn.simulate_solve_ivp(p, None, stop_time=0.003, output_interval=1e-5)
    _, b = gn.simulate_rk4(p, None, stop_time=0.003, step=5e-6, output_interval=1e-5)
    for name in ACCEL_FORCE:
        assert rel_err(a[name], b[name]) < 1e-3, name


# ---- reduced, hand-checkable case -----------------------------------------------------------
K_PAIR = 2.5e8   # N/m, constant pair stiffness of the reduced mesh


def reduced_params(**changes) -> GearboxParams:
    """Constant pair stiffness, near-sharp contact windows, gearbox at standstill in the middle
    of the single-tooth-contact zone.

    At a cycle fraction c in (0, 1] the pairs at roll (c+1)/CR, c/CR, (c-1)/CR are in contact
    when their roll is in [0, 1]: two pairs for c < CR - 1, one pair for c > CR - 1.  The
    mesh phase is chosen so that the pre-loaded pinion angle sits at c = CR/2 (mid single
    contact), where the mesh stiffness is exactly K_PAIR.  ``speed_ref_start`` is set so that
    the motor holds the input torque at zero speed (``speed_start = 0``).
    """
    p = GearboxParams(k_pair=(K_PAIR,) * 11, contact_smoothing=1e-4).replace(**changes)
    theta5 = gn.initial_state(p)[gn.STATE_NAMES.index("theta5")]
    return p.replace(mesh_phase0=math.pi * p.contact_ratio - p.z1 * theta5,
                     speed_ref_start=p.torque_in / p.c_motor)


def standstill_inputs(p: GearboxParams) -> dict[str, float]:
    return {"motor_speed_ref": p.torque_in / p.c_motor, "drive_torque": 0.0, "load_torque": p.load_start}


def series(a: float, b: float) -> float:
    return a * b / (a + b)


def hand_static_state(p: GearboxParams) -> tuple[np.ndarray, float, float]:
    """Static equilibrium at standstill worked out by hand: (state (42,), mesh force [N], TE [m]).

    Torque balance on the gear gives F = T_load / rb2; the input chain carries F*rb1.  The
    pinion sits on two legs per axis (shaft spring in series with a pedestal spring), so it
    yields by -F*(sin a, cos a)/K_leg_sum; the gear yields the opposite way.  The flank
    approach is F/K_PAIR (one pair in contact), and the transmission error is that approach
    minus the lateral yield projected on the line of action.
    """
    F = p.load_start / p.rb2
    Ti = F * p.rb1
    sa, ca = math.sin(p.alpha), math.cos(p.alpha)
    kxp = series(p.kx45, p.kx4) + series(p.kx56, p.kx6)
    kyp = series(p.ky45, p.ky4) + series(p.ky56, p.ky6)
    kxg = series(p.kx910, p.kx9) + series(p.kx1011, p.kx11)
    kyg = series(p.ky910, p.ky9) + series(p.ky1011, p.ky11)
    x5, y5 = -F * sa / kxp, -F * ca / kyp
    x10, y10 = F * sa / kxg, F * ca / kyg
    lateral = {
        "x5": x5, "y5": y5, "x10": x10, "y10": y10,
        "x4": x5 * p.kx45 / (p.kx45 + p.kx4), "y4": y5 * p.ky45 / (p.ky45 + p.ky4),
        "x6": x5 * p.kx56 / (p.kx56 + p.kx6), "y6": y5 * p.ky56 / (p.ky56 + p.ky6),
        "x9": x10 * p.kx910 / (p.kx910 + p.kx9), "y9": y10 * p.ky910 / (p.ky910 + p.ky9),
        "x11": x10 * p.kx1011 / (p.kx1011 + p.kx11), "y11": y10 * p.ky1011 / (p.ky1011 + p.ky11),
    }
    te = F / K_PAIR - ((x5 - x10) * sa + (y5 - y10) * ca)
    th5 = -Ti / p.kt12 - Ti / p.kt23 - Ti / p.kt35
    th10 = (p.rb1 * th5 - te) / p.rb2
    th12 = th10 - p.load_start / p.kt1012
    angles = {"theta1": 0.0, "theta2": -Ti / p.kt12, "theta3": -Ti / p.kt12 - Ti / p.kt23,
              "theta5": th5, "theta7": th5, "theta10": th10, "theta8": th10, "theta12": th12,
              "theta13": th12 - p.load_start / p.kt1213}
    x = np.zeros(gn.N_STATES)
    for name, value in {**angles, **lateral}.items():
        x[gn.STATE_NAMES.index(name)] = value
    return x, F, te


def test_reduced_mesh_stiffness_is_piecewise_constant():
    """Over one mesh cycle the reduced mesh stiffness is K_PAIR (one pair) or 2*K_PAIR (two
    pairs), and the double-contact share of the cycle is CR - 1 (hand value 0.65258 for
    z = 19/52, m = 3 mm, 20 deg, full-depth addendum), to the ramp width 2*smoothing*CR."""
    p = GearboxParams(k_pair=(K_PAIR,) * 11, contact_smoothing=1e-4)
    assert p.contact_ratio == pytest.approx(1.65258, abs=1e-5)
    n = 20000
    x = np.zeros((gn.N_STATES, n))
    x[gn.STATE_NAMES.index("theta5")] = (np.arange(n) + 0.5) / n * 2 * math.pi / p.z1
    k = gn.outputs(0.0, x, p)["mesh_stiffness"]
    flat = np.isclose(k, K_PAIR, rtol=1e-12) | np.isclose(k, 2 * K_PAIR, rtol=1e-12)
    assert np.mean(~flat) <= 2 * 2 * p.contact_smoothing * p.contact_ratio + 2 / n
    assert np.mean(k > 1.5 * K_PAIR) == pytest.approx(p.contact_ratio - 1, abs=1e-3)


def test_static_equilibrium_by_hand():
    """At the hand-built standstill equilibrium every acceleration vanishes (to 1e-9 of the
    mesh-force scale), the mesh force is T_load/rb2 = 272.866 N and the motor holds
    T_load*rb1/rb2 = 7.308 N.m, both to 1e-12 relative."""
    p = reduced_params()
    u = standstill_inputs(p)
    x, F, te = hand_static_state(p)
    assert F == pytest.approx(20.0 / (0.5 * 3e-3 * 52 * math.cos(math.radians(20))), rel=1e-14)
    out = gn.outputs(0.0, x, p, u, internals=True)
    assert float(out["mesh_stiffness"]) == pytest.approx(K_PAIR, rel=1e-12)
    assert float(out["mesh_force"]) == pytest.approx(F, rel=1e-12)
    assert float(out["motor_torque"]) == pytest.approx(F * p.rb1, rel=1e-12)
    assert float(out["transmission_error"]) == pytest.approx(te, rel=1e-12)
    xdot = gn.rhs(0.0, x, p, u)
    inertia = np.array([p.I1, p.I2, p.I3, p.I5, p.I7, p.I8, p.I10, p.I12, p.I13])
    masses = np.array([p.m4, p.m4, p.m5, p.m5, p.m6, p.m6, p.m9, p.m9, p.m10, p.m10, p.m11, p.m11])
    # Residual generalised forces, compared with the mesh torque / force they balance.
    assert np.max(np.abs(xdot[9:18] * inertia)) < 1e-9 * F * p.rb2
    assert np.max(np.abs(xdot[30:42] * masses)) < 1e-9 * F
    assert np.all(xdot[:9] == 0.0) and np.all(xdot[18:30] == 0.0)   # at rest: positions do not move


def test_static_mesh_force_settles_to_load_over_base_radius():
    """From the model's own (approximate) pre-loaded start at standstill the mesh force
    settles to T_load/rb2 and the transmission error to the hand value (F/k plus the lateral
    yield), both within 1e-3 relative over 45-50 ms.  Every damper is x30 so that the slowest
    mode (brake on coupling 4, ~35 Hz) decays within the span (time constant ~12 ms)."""
    p0 = reduced_params()
    p = p0.replace(**{n: 30 * getattr(p0, n) for n in ALL_DAMPERS})
    _, F, te = hand_static_state(p)
    t, out = gn.simulate_rk4(p, standstill_inputs(p), stop_time=0.05, step=5e-6, output_interval=1e-4)
    tail = t >= 0.045 - 1e-12
    assert abs(out["mesh_force"][0] - F) > 0.01 * F   # the start is visibly off equilibrium
    assert rel_err(out["mesh_force"][tail], np.full(tail.sum(), F)) < 1e-3
    assert rel_err(out["transmission_error"][tail], np.full(tail.sum(), te)) < 1e-3
    assert np.allclose(out["mesh_stiffness"], K_PAIR, rtol=1e-12, atol=0)   # stayed mid single contact


def two_inertia_frequency(p: GearboxParams) -> float:
    """Closed form [Hz]: pinion I5 and gear I10 coupled by K_PAIR along the line of action."""
    return math.sqrt(K_PAIR * (p.rb1 ** 2 / p.I5 + p.rb2 ** 2 / p.I10)) / (2 * math.pi)


def soft_shafts(p: GearboxParams) -> dict[str, float]:
    # Shafts 1000x softer than the mesh's torsional stiffness (K*rb1^2 ~ 1.8e5 N.m/rad) would
    # otherwise shift the mesh mode by ~8 %; at 1e-3 their share is ~1e-4.
    return {n: 1e-3 * getattr(p, n) for n in ("kt35", "kt57", "kt810", "kt1012")}


def test_two_inertia_mesh_mode_eigenvalue():
    """Linearised model with soft shafts and very stiff lateral supports (all lateral springs
    x1e4): exactly one natural frequency lies within a factor 3 of the closed-form 2-inertia
    mesh mode sqrt(k (rb1^2/I5 + rb2^2/I10))/(2 pi) = 4665 Hz, and it matches to 1e-3."""
    base = GearboxParams()
    stiff = {f.name: 1e4 * getattr(base, f.name) for f in dataclasses.fields(base)
             if f.name[0] == "k" and f.name[1] in "xy"}
    p = reduced_params(**soft_shafts(base), **stiff)
    theta5 = gn.initial_state(p)[gn.STATE_NAMES.index("theta5")]
    f_cf = two_inertia_frequency(p)
    assert f_cf == pytest.approx(4665, rel=1e-3)
    f = gn.natural_frequencies(p, n=20, theta5=theta5)
    near = f[(f > f_cf / 3) & (f < 3 * f_cf)]
    assert near.size == 1
    assert near[0] == pytest.approx(f_cf, rel=1e-3)


def test_two_inertia_mesh_mode_free_vibration():
    """Time domain through rhs: soft shafts, pinion and gear laterally frozen (m5 = m10 =
    1e9 kg), mesh and the pinion/gear shaft dampers set to zero (an undamped mesh mode).  The
    pre-load mismatch (k_mesh_mean = CR*K_PAIR at the start, K_PAIR at rest) starts a free
    mesh vibration about the static TE = F/K_PAIR; its zero-crossing frequency over 2 ms
    matches the closed form to 1e-3 (measured 6e-5, the soft shafts' share)."""
    base = GearboxParams()
    p = reduced_params(**soft_shafts(base), m5=1e9, m10=1e9, c_mesh=0.0,
                       ct35=0.0, ct57=0.0, ct810=0.0, ct1012=0.0)
    t, out = gn.simulate_rk4(p, standstill_inputs(p), stop_time=0.002, step=2.5e-6, output_interval=2.5e-6)
    s = out["transmission_error"] - p.load_start / p.rb2 / K_PAIR
    i = np.flatnonzero(np.sign(s[:-1]) != np.sign(s[1:]))
    tc = t[i] - s[i] * (t[i + 1] - t[i]) / (s[i + 1] - s[i])   # linear interpolation
    f_measured = (tc.size - 1) / (2 * (tc[-1] - tc[0]))
    assert tc.size > 15
    assert np.max(np.abs(s)) > 0.3 * p.load_start / p.rb2 / K_PAIR   # a real vibration
    assert f_measured == pytest.approx(two_inertia_frequency(p), rel=1e-3)


def test_linearisation_matches_rhs_jacobian():
    """mass_matrix_stiffness (assembled spring by spring) equals the finite-difference Jacobian
    of rhs at the reduced static state, where the mesh stiffness is locally flat:
    d(acc)/dq = -M^-1 K and d(acc)/dq' = -M^-1 C to 1e-6 of each row's largest entry."""
    p = reduced_params()
    u = standstill_inputs(p)
    x0, _, _ = hand_static_state(p)
    M, K, C = gn.mass_matrix_stiffness(p, theta5=x0[gn.STATE_NAMES.index("theta5")])
    pos = [gn.STATE_NAMES.index(n) for n in gn.DOF_NAMES]
    vel = [gn.STATE_NAMES.index(("omega" + n[5:]) if n.startswith("theta") else "v" + n)
           for n in gn.DOF_NAMES]
    jac = np.empty((gn.N_STATES, gn.N_STATES))
    for j in range(gn.N_STATES):
        h = 1e-7 if j < 18 else (1e-10 if j < 30 else 1e-5)
        e = np.zeros(gn.N_STATES)
        e[j] = h
        jac[:, j] = (gn.rhs(0.0, x0 + e, p, u) - gn.rhs(0.0, x0 - e, p, u)) / (2 * h)
    minv = np.diag(1.0 / np.diag(M))
    for got, want in ((jac[np.ix_(vel, pos)], -minv @ K), (jac[np.ix_(vel, vel)], -minv @ C)):
        scale = np.max(np.abs(want), axis=1, keepdims=True)
        assert np.all(np.abs(got - want) <= 1e-6 * scale)
    assert np.allclose(K, K.T) and np.allclose(C, C.T) and np.all(np.diag(M) > 0)
    # Kinematic rows: d(theta)/dt picks the matching speed.
    np.testing.assert_array_equal(jac[np.ix_(pos, vel)], np.eye(len(pos)))


def test_default_natural_frequencies_and_rigid_mode():
    """Default rig: the only zero mode of K is the rigid rotation of both shafts through the
    mesh (input side 1 rad, output side rb1/rb2 rad, no lateral motion); the returned
    frequencies are positive and ascending, and the rigid mode is not among them."""
    p = GearboxParams()
    M, K, C = gn.mass_matrix_stiffness(p)
    rigid = np.array([1.0] * 5 + [p.rb1 / p.rb2] * 4 + [0.0] * 12)   # DOF_NAMES order
    assert np.max(np.abs(K @ rigid)) < 1e-12 * np.max(np.abs(K))
    assert np.linalg.matrix_rank(K) == K.shape[0] - 1
    f = gn.natural_frequencies(p, n=8)
    assert f.shape == (8,)
    assert np.all(np.diff(f) > 0) and f[0] > 10.0


# ---- signs -----------------------------------------------------------------------------------
def test_more_load_more_mesh_force_and_transmission_error():
    """Raising the brake torque (input load_torque 20 -> 30 -> 40 N.m, same start) raises the
    mean mesh force and mean transmission error over 10-20 ms, each step by at least half the
    static increment dT/rb2 resp. dT/(rb2 k_mesh_mean)."""
    p = GearboxParams()
    means = []
    for load in (20.0, 30.0, 40.0):
        t, out = gn.simulate_rk4(p, {"load_torque": load}, stop_time=0.02, step=5e-6, output_interval=1e-4)
        late = t >= 0.01
        means.append((out["mesh_force"][late].mean(), out["transmission_error"][late].mean()))
    force, te = np.array(means).T
    assert np.all(np.diff(force) > 0.5 * 10.0 / p.rb2)
    assert np.all(np.diff(te) > 0.5 * 10.0 / p.rb2 / p.k_mesh_mean)
    assert np.all(force > 0) and np.all(te > 0)   # the pinion drives: flanks compressed


def test_gear_tooth_follows_the_mesh_count():
    """Gear tooth j is in the current pair at completed mesh cycles k = j - 1 (mod z2), whatever
    pinion tooth it meets: a deviation on gear tooth 3 shows in the current pair at k = 2 and one
    gear revolution (52 cycles, pinion tooth 17 instead of 3) later, in the leading pair one cycle
    after that, and nowhere else."""
    wheel = np.zeros(52)
    wheel[2] = 1e-6
    c = gn._constants(GearboxParams(wheel_tooth_deviation_offset=wheel))
    x = np.zeros(gn.N_STATES)

    def deviation(cycles):                      # pair deviations at mid-cycle after `cycles` cycles
        x[gn.STATE_NAMES.index("theta5")] = 2 * math.pi * (cycles + 0.5) / 19
        return gn._mesh(c, x)["pair_deviation"]

    np.testing.assert_allclose(deviation(2), [0, 1e-6, 0], atol=1e-15)
    np.testing.assert_allclose(deviation(2 + 52), [0, 1e-6, 0], atol=1e-15)
    np.testing.assert_allclose(deviation(3), [1e-6, 0, 0], atol=1e-15)
    np.testing.assert_allclose(deviation(1), [0, 0, 1e-6], atol=1e-15)
    for k in (0, 5, 21, 40, 57):
        np.testing.assert_allclose(deviation(k), 0, atol=1e-15)


def test_gear_tooth_array_needs_z2_entries():
    with pytest.raises(ValueError, match="wheel_tooth_deviation_offset needs z2=52 entries, got 19"):
        GearboxParams(wheel_tooth_deviation_offset=np.zeros(19))


def test_gear_error_variant_has_the_base_parameters_plus_the_gear_teeth(gearbox_fmu, wheel_fmu):
    """GearTwin.Variants.Gearbox21WheelErrors: the base model's parameters, the same defaults, and
    the 52 gear-tooth offsets; with them all zero it gives the base model's numbers exactly."""
    def params(fmu):
        md = read_model_description(str(fmu))
        return {v.name: float(v.start) for v in md.modelVariables
                if v.causality == "parameter" and not v.name.startswith("solver.")}
    base, variant = params(gearbox_fmu), params(wheel_fmu)
    assert set(variant) == set(GearboxParams().fmu_start_values(only_changed=False, variant=True))
    assert set(variant) - set(base) == {f"wheel_tooth_deviation_offset[{i}]" for i in range(1, 53)}
    assert all(variant[n] == v for n, v in base.items())
    a = simulate_compiled(gearbox_fmu, 0.005, 1e-5)
    b = simulate_compiled(wheel_fmu, 0.005, 1e-5)
    for name in ACCEL_FORCE:
        np.testing.assert_array_equal(a[name], b[name])
