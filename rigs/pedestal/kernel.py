"""Time integration of the rig: classical RK4 at a fixed step, compiled with numba.

State: generalised displacements ``x`` and velocities ``v`` (see ``structure.DOF``), the PI
integrator ``z`` of the speed loop and the motor air-gap torque ``te``. Per step the right-hand
side evaluates

* the gear mesh: every tooth pair whose contact point lies on the path of contact carries
  ``k (delta - e) + c d(delta)/dt`` when compressed over the whole face, and the integral of
  that law over the face when a mismatch across the face (assembly misalignment, the wobble
  of a run-out gear) leaves part of it open (unilateral), with the pair's stiffness law
  and deviation interpolated from the per-tooth tables and the run-out of both gears added to
  the deviation; the back flanks close below minus the backlash; Coulomb sliding friction
  (regularised sign) acts across the line of action with the flank radii as lever arms;
* the drive: ``te`` follows the PI command with the current-loop lag, clipped to the torque
  limit; the brake torque opposes the brake rotor's rotation;
* external generalised forces: torques, mass unbalance, and any number of force time series
  along fixed generalised directions (a bearing defect, a hammer).

Forcing arrays are sampled at the integration step and held over a step (zero-order hold); the
speed reference is interpolated linearly. Outputs are stored at every step from the first RK
stage, i.e. at the state of the step's start.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .structure import I_B, I_G, I_M, I_P, I_XG, I_XP, I_YG, I_YP


@njit(cache=True, fastmath=False)
def _rhs(x, v, z, te, w_ref, i, P, mass, K_ptr, K_col, K_val, C_val, g, tabs, pin_dev, pin_k,
         gear_dev, gear_k, ext_torque, ext_force, force_dirs, acc, out):
    """Fill ``acc`` with accelerations; return (dz, dte, mesh force, delta)."""
    n = mass.size
    rb1, rb2, pb, L, ds, u0 = P[0], P[1], P[2], P[3], P[4], P[5]
    k_max, c_max, k_back, backlash, mu, rho1_start = P[6], P[7], P[8], P[9], P[10], P[11]
    t1t2, e1, e2, psi1, psi2, m_p = P[12], P[13], P[14], P[15], P[16], P[17]
    m_g, kp, ki, lag, tlim, tan_a = P[18], P[19], P[20], P[21], P[22], P[23]
    nx, ny, tx, ty, v_reg, brake_w = P[24], P[25], P[26], P[27], P[28], P[29]
    f0, wob = P[30], P[31]
    z1 = pin_dev.shape[0]
    z2 = gear_dev.shape[0]
    ns = pin_dev.shape[1]

    delta = 0.0
    ddelta = 0.0
    for j in range(n):
        delta += g[j] * x[j]
        ddelta += g[j] * v[j]
    th_p = x[I_P]
    w_p = v[I_P]
    w_g = v[I_G]
    phi1 = th_p + u0 / rb1 + psi1
    phi2 = -(x[I_G] + u0 / rb2) + psi2
    r1x, r1y = e1 * np.cos(phi1), e1 * np.sin(phi1)
    r2x, r2y = e2 * np.cos(phi2), e2 * np.sin(phi2)
    e_run = -(r1x * nx + r1y * ny) + (r2x * nx + r2y * ny)
    back = backlash + 2.0 * tan_a * (r2x - r1x)
    # mismatch across the face: assembly misalignment plus the wobble of tilted (run-out) gears
    mis = abs(f0 + wob * (e1 * np.cos(phi1) + e2 * np.cos(phi2)))
    if mis < 1e-9:
        mis = 1e-9

    for j in range(n):
        out[j] = 0.0
    f_mesh = 0.0
    # an eccentric gear also shifts its teeth along the line of action: the engagement of every
    # pair comes earlier or later (phase modulation of the mesh), hence u - e_run
    u = rb1 * th_p + u0 - e_run
    n_hi = int(np.floor(u / pb))
    for jj in range(3):
        nn = n_hi - jj
        s = u - nn * pb
        if s < 0.0 or s > L:
            continue
        q = s / ds
        i0 = int(q)
        if i0 > ns - 2:
            i0 = ns - 2
        fr = q - i0
        ip = nn % z1
        ig = nn % z2
        kk = (tabs[i0] * (1 - fr) + tabs[i0 + 1] * fr)
        kk *= pin_k[ip, i0] * (1 - fr) + pin_k[ip, i0 + 1] * fr
        kk *= gear_k[ig, i0] * (1 - fr) + gear_k[ig, i0 + 1] * fr
        e = (pin_dev[ip, i0] * (1 - fr) + pin_dev[ip, i0 + 1] * fr
             + gear_dev[ig, i0] * (1 - fr) + gear_dev[ig, i0 + 1] * fr + e_run)
        # face-integrated unilateral contact with a linear gap across the face (mismatch mis)
        h = delta - e + 0.5 * mis
        if h <= 0.0:
            continue
        if h >= mis:
            f = k_max * kk * (delta - e) + c_max * kk * ddelta
        else:
            f = k_max * kk * h * h / (2.0 * mis) + c_max * kk * (h / mis) * ddelta
        if f <= 0.0:
            continue
        f_mesh += f
        rho1 = rho1_start + s
        rho2 = t1t2 - rho1
        slide = w_p * (rho1 - rho2 * z1 / z2)
        ff = mu * f * np.tanh(slide / v_reg)
        # friction opposes the slip coordinate h = rho1 th_p - rho2 th_g + t.(r_p - r_g)
        out[I_P] -= ff * rho1
        out[I_G] += ff * rho2
        out[I_XP] -= ff * tx
        out[I_YP] -= ff * ty
        out[I_XG] += ff * tx
        out[I_YG] += ff * ty
    if delta - e_run < -back:
        fb = k_back * (delta - e_run + back) + c_max * ddelta
        if fb < 0.0:
            f_mesh += fb
    for j in range(n):
        out[j] -= f_mesh * g[j]

    # drive and brake
    err = w_ref - v[I_M]
    cmd = kp * err + ki * z
    if cmd > tlim:
        cmd = tlim
    elif cmd < -tlim:
        cmd = -tlim
    out[I_M] += te + ext_torque[i, 0]
    out[I_P] += ext_torque[i, 1]
    out[I_G] += ext_torque[i, 2]
    out[I_B] -= ext_torque[i, 3] * np.tanh(v[I_B] / brake_w)
    # unbalance of the eccentric gears
    out[I_XP] += m_p * e1 * w_p * w_p * np.cos(phi1)
    out[I_YP] += m_p * e1 * w_p * w_p * np.sin(phi1)
    out[I_XG] += m_g * e2 * w_g * w_g * np.cos(phi2)
    out[I_YG] += m_g * e2 * w_g * w_g * np.sin(phi2)
    for m in range(force_dirs.shape[0]):
        fm = ext_force[i, m]
        if fm != 0.0:
            for j in range(n):
                out[j] += fm * force_dirs[m, j]
    # K and C share one sparsity pattern, held in compressed rows
    for r in range(n):
        acc_r = out[r]
        for q in range(K_ptr[r], K_ptr[r + 1]):
            c = K_col[q]
            acc_r -= K_val[q] * x[c] + C_val[q] * v[c]
        acc[r] = acc_r / mass[r]
    return err, (cmd - te) / lag, f_mesh, delta


@njit(cache=True, fastmath=False)
def integrate(x0, v0, z0, te0, dt, n_steps, w_ref, P, mass, K_ptr, K_col, K_val, C_val, g, tabs,
              pin_dev, pin_k, gear_dev, gear_k, ext_torque, ext_force, force_dirs, rows, acc_out,
              theta_out, force_out, delta_out):
    """Advance ``n_steps`` RK4 steps; outputs (arrays of length n_steps) are filled in place."""
    n = mass.size
    x = x0.copy()
    v = v0.copy()
    z = z0
    te = te0
    a1 = np.empty(n)
    a2 = np.empty(n)
    a3 = np.empty(n)
    a4 = np.empty(n)
    xs = np.empty(n)
    vs = np.empty(n)
    scratch = np.empty(n)
    k2x = np.empty(n)
    k3x = np.empty(n)
    for i in range(n_steps):
        wr0 = w_ref[i]
        wr1 = w_ref[i + 1]
        wrm = 0.5 * (wr0 + wr1)
        dz1, dt1, fm, dl = _rhs(x, v, z, te, wr0, i, P, mass, K_ptr, K_col, K_val, C_val, g,
                                tabs, pin_dev, pin_k, gear_dev, gear_k, ext_torque, ext_force,
                                force_dirs, a1, scratch)
        for s in range(rows.shape[0]):
            acc = 0.0
            for j in range(n):
                acc += rows[s, j] * a1[j]
            acc_out[s, i] = acc
        theta_out[i] = x[I_P]
        force_out[i] = fm
        delta_out[i] = dl
        h = 0.5 * dt
        for j in range(n):
            xs[j] = x[j] + h * v[j]
            vs[j] = v[j] + h * a1[j]
        dz2, dt2, _, _ = _rhs(xs, vs, z + h * dz1, te + h * dt1, wrm, i, P, mass, K_ptr, K_col,
                              K_val, C_val, g, tabs, pin_dev, pin_k, gear_dev, gear_k,
                              ext_torque, ext_force, force_dirs, a2, scratch)
        for j in range(n):
            k2x[j] = vs[j]
            xs[j] = x[j] + h * k2x[j]
            vs[j] = v[j] + h * a2[j]
        dz3, dt3, _, _ = _rhs(xs, vs, z + h * dz2, te + h * dt2, wrm, i, P, mass, K_ptr, K_col,
                              K_val, C_val, g, tabs, pin_dev, pin_k, gear_dev, gear_k,
                              ext_torque, ext_force, force_dirs, a3, scratch)
        for j in range(n):
            k3x[j] = vs[j]
            xs[j] = x[j] + dt * k3x[j]
            vs[j] = v[j] + dt * a3[j]
        dz4, dt4, _, _ = _rhs(xs, vs, z + dt * dz3, te + dt * dt3, wr1, i, P, mass, K_ptr,
                              K_col, K_val, C_val, g, tabs, pin_dev, pin_k, gear_dev, gear_k,
                              ext_torque, ext_force, force_dirs, a4, scratch)
        for j in range(n):
            x[j] += dt / 6.0 * (v[j] + 2.0 * k2x[j] + 2.0 * k3x[j] + vs[j])
            v[j] += dt / 6.0 * (a1[j] + 2.0 * a2[j] + 2.0 * a3[j] + a4[j])
        z += dt / 6.0 * (dz1 + 2.0 * dz2 + 2.0 * dz3 + dz4)
        te += dt / 6.0 * (dt1 + 2.0 * dt2 + 2.0 * dt3 + dt4)
    return x, v, z, te


N_PARAMS = 32


def compressed_rows(K: np.ndarray, C: np.ndarray):
    """Row pointers, columns and values of K and C on their common sparsity pattern."""
    mask = (K != 0) | (C != 0)
    ptr = np.concatenate([[0], np.cumsum(mask.sum(axis=1))]).astype(np.int64)
    rows, cols = np.nonzero(mask)
    return ptr, cols.astype(np.int64), np.ascontiguousarray(K[rows, cols]), \
        np.ascontiguousarray(C[rows, cols])
