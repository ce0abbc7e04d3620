"""Time integration: exact discretisation of the modal (linear) part with the mesh force as
input, and Newton's method on the unilateral mesh contact at every step.

Each retained mode is a damped oscillator whose step map is exact for inputs varying
linearly over the step (first-order hold; matrix exponential of the augmented system). The
mesh force enters as the residual N = F(delta) - k_mean delta, implicitly: with the modal
state predicted from the other inputs, delta_{k+1} = delta_pred - beta N(delta_{k+1}) is a
scalar equation, monotone in delta, solved by Newton's method (beta is the step's own mesh
compliance plus the static compliance of the modes left out). Drive, friction and the
state-dependent effect forces are explicit (they are slow or small against the step).
"""
from __future__ import annotations

import numba
import numpy as np
from scipy.linalg import expm

from .contact import pair_force

# indices of the scalar parameter vector of the loop
NAMES = (
    "h", "k_mean", "beta", "rb1", "pb", "g_len", "u_pitch", "rho1_start", "loa_length",
    "z1", "z2", "gear_offset", "q", "mu", "ratio", "alpha",
    "R", "L", "kt", "kp_i", "ki_i", "kp_w", "ki_w", "i_max", "v_max", "sensor_err",
    "w_a", "w_b", "t_a", "t_b", "t0",
    "comm_n", "comm_a", "rip_amp", "rip_freq", "rip_phase",
    "load", "brake_1x", "brake_phase", "brake_visc",
    "ecc_p", "ecc_p_phase", "ecc_g", "ecc_g_phase",
    "mis_force", "mis_torque", "mis_phase")
P = {name: i for i, name in enumerate(NAMES)}
# in-loop input channels (columns of the modal input matrix B)
LOOP_CHANNELS = ("motor", "brake", "pinion_y", "pinion_z", "pinion_t", "gear_y", "gear_z",
                 "gear_t", "coupling_y", "coupling_z", "coupling_t")


def step_matrices(freq, zeta, h):
    """Exact first-order-hold step matrices per mode: Phi (m,2,2), G0 (m,2), G1 (m,2)."""
    m = freq.size
    Ph = np.zeros((m, 2, 2))
    G0 = np.zeros((m, 2))
    G1 = np.zeros((m, 2))
    for r in range(m):
        w = 2 * np.pi * freq[r]
        a = np.zeros((4, 4))
        a[0, 1] = 1.0
        a[1, 0] = -w * w
        a[1, 1] = -2 * zeta[r] * w
        a[1, 2] = 1.0          # input u
        a[2, 3] = 1.0          # du/dt, constant over the step
        e = expm(a * h)
        Ph[r] = e[:2, :2]
        # x+ = Phi x + e[:2,2] u_k + e[:2,3] (u_{k+1} - u_k) / h
        G1[r] = e[:2, 3] / h
        G0[r] = e[:2, 2] - G1[r]
    return Ph, G0, G1


@numba.njit(cache=True)
def _mesh(delta, s, par, gap_p, gap_g, comp_p, width_p, hertz_a, du, extra_gap, shrink,
          fguess, out_f, out_u):
    """Total mesh force [N] and tangent stiffness [N/m]; pair forces and positions out."""
    pb = par[4]
    g_len = par[5]
    z1 = int(par[9])
    z2 = int(par[10])
    q = par[12]
    nmax = int(np.floor(s / pb))
    ftot = 0.0
    ktot = 0.0
    nu = gap_p.shape[1]
    for m in range(2):
        n = nmax - m
        u = s - n * pb
        out_f[m] = 0.0
        out_u[m] = u
        if u < 0.5 * shrink or u > g_len - 0.5 * shrink:
            continue
        x = u / du
        if x >= nu - 1:
            x = nu - 1.000001
        i0 = int(x)
        t = x - i0
        k = ((n % z1) + z1) % z1
        j = (((n + int(par[11])) % z2) + z2) % z2
        gap = (gap_p[k, i0] * (1 - t) + gap_p[k, i0 + 1] * t
               + gap_g[j, i0] * (1 - t) + gap_g[j, i0 + 1] * t + extra_gap)
        c = comp_p[k, i0] * (1 - t) + comp_p[k, i0 + 1] * t
        w = width_p[k, i0] * (1 - t) + width_p[k, i0 + 1] * t
        aw = hertz_a[i0] * (1 - t) + hertz_a[i0 + 1] * t + np.log(w)
        f, kk = pair_force(delta - gap, c, q / w, aw, fguess[m])
        out_f[m] = f
        ftot += f
        ktot += kk
    return ftot, ktot


@numba.njit(cache=True)
def run(n_steps, n_settle, par, Ph, G0, G1, two_zw, w2, gvec, B, G_ser, series, brake_fluct,
        rows, gap_p, gap_g, comp_p, width_p, hertz_a, du, q0, v0, t_start):
    """Integrate n_settle + n_steps steps of length h; return the last n_steps outputs.

    rows: (7, m) modal rows of: sensor 1, sensor 2 (accelerations along their axes), pinion
    encoder angle, gear encoder angle, motor angle, brake angle, pinion-node angle, in this
    order; gear-node angle is row 7. series: (n, c) precomputed external forces projected by
    G_ser (m, c). Outputs (n_steps, 7): sensor 1, sensor 2 [m/s2], pinion and gear encoder
    angles [rad], mesh force [N], mesh deflection [m], motor speed [rad/s].
    """
    m = Ph.shape[0]
    h = par[0]
    kbar = par[1]
    beta = par[2]
    ca = np.cos(par[15])
    sa = np.sin(par[15])
    q = q0.copy()
    v = v0.copy()
    out = np.zeros((n_steps, 7))
    u_prev = np.zeros(m)
    u_new = np.zeros(m)
    qp = np.zeros(m)
    vp = np.zeros(m)
    f_loop = np.zeros(B.shape[1])
    fguess = np.array([100.0, 100.0])
    pf = np.zeros(2)
    pu = np.zeros(2)
    i_arm = par[36] * par[14] / par[18]
    x_w = i_arm
    x_i = par[16] * i_arm
    n_ser = series.shape[1]
    total = n_steps + n_settle
    # modal input at the start: the static loads
    f_loop[0] = par[18] * i_arm
    f_loop[1] = -par[36]
    for r in range(m):
        acc = 0.0
        for c in range(B.shape[1]):
            acc += B[r, c] * f_loop[c]
        u_prev[r] = acc
    for k in range(total):
        t = t_start + (k + 1) * h
        kk = k + 1 if k + 1 < series.shape[0] else series.shape[0] - 1
        th_m = 0.0
        w_m = 0.0
        th_b = 0.0
        w_b = 0.0
        th_p = 0.0
        th_g = 0.0
        for r in range(m):
            th_m += rows[4, r] * q[r]
            w_m += rows[4, r] * v[r]
            th_b += rows[5, r] * q[r]
            w_b += rows[5, r] * v[r]
            th_p += rows[6, r] * q[r]
            th_g += rows[7, r] * q[r]
        # drive: speed PI, current PI, armature
        tt = 1.0
        if par[29] > par[28]:
            tt = (t - par[28]) / (par[29] - par[28])
            tt = min(max(tt, 0.0), 1.0)
        w_ref = par[26] + (par[27] - par[26]) * tt
        e_w = w_ref - w_m * (1.0 + par[25])
        i_ref = par[21] * e_w + x_w
        if i_ref > par[23]:
            i_ref = par[23]
        elif i_ref < -par[23]:
            i_ref = -par[23]
        else:
            x_w += par[22] * e_w * h
        e_i = i_ref - i_arm
        volt = par[19] * e_i + x_i + par[18] * w_m
        if volt > par[24]:
            volt = par[24]
        elif volt < -par[24]:
            volt = -par[24]
        else:
            x_i += par[20] * e_i * h
        i_arm += h * (volt - par[16] * i_arm - par[18] * w_m) / par[17]
        f_loop[0] = (par[18] * i_arm * (1.0 + par[32] * np.sin(par[31] * th_m))
                     + par[33] * np.sin(2 * np.pi * par[34] * t + par[35]))
        f_loop[1] = -(par[36] * (1.0 + brake_fluct[kk] + par[37] * np.sin(th_b + par[38]))
                      + par[39] * w_b)
        for c in range(2, B.shape[1]):
            f_loop[c] = 0.0
        # sliding friction of the pairs of the last step (along the flank tangent)
        wsum = w_m + w_b
        for mm in range(2):
            if pf[mm] > 0.0:
                ft = par[13] * pf[mm] * np.tanh(wsum * (pu[mm] - par[6]) / 0.005)
                rho1 = par[7] + pu[mm]
                rho2 = par[8] - rho1
                f_loop[2] += ft * ca
                f_loop[3] -= ft * sa
                f_loop[4] -= rho1 * ft
                f_loop[5] -= ft * ca
                f_loop[6] += ft * sa
                f_loop[7] -= rho2 * ft
        # coupling misalignment: force and torque twice per revolution
        if par[44] != 0.0 or par[45] != 0.0:
            ph2 = 2.0 * th_p + par[46]
            f_loop[8] = par[44] * np.cos(ph2)
            f_loop[9] = par[44] * np.sin(ph2)
            f_loop[10] = par[45] * np.sin(ph2)
        for r in range(m):
            acc = 0.0
            for c in range(B.shape[1]):
                acc += B[r, c] * f_loop[c]
            for c in range(n_ser):
                acc += G_ser[r, c] * series[kk, c]
            u_new[r] = acc
        # predictor without the mesh residual
        d_pred = 0.0
        for r in range(m):
            qp[r] = Ph[r, 0, 0] * q[r] + Ph[r, 0, 1] * v[r] + G0[r, 0] * u_prev[r] + G1[r, 0] * u_new[r]
            vp[r] = Ph[r, 1, 0] * q[r] + Ph[r, 1, 1] * v[r] + G0[r, 1] * u_prev[r] + G1[r, 1] * u_new[r]
            d_pred += gvec[r] * qp[r]
        # eccentricities: separation along the line of action and centre-distance change
        dp_y = par[40] * np.cos(th_p + par[41])
        dp_z = par[40] * np.sin(th_p + par[41])
        dg_y = par[42] * np.cos(-th_g + par[43])
        dg_z = par[42] * np.sin(-th_g + par[43])
        e_run = -(dp_y * sa + dp_z * ca) + (dg_y * sa + dg_z * ca)
        shrink = (dg_y - dp_y) / sa       # path of contact shortens as the centres part
        s = par[3] * th_p + dp_y * sa + dp_z * ca     # eccentric pinion: its teeth arrive early/late
        delta = d_pred
        for it in range(50):
            ftot, ktot = _mesh(delta, s, par, gap_p, gap_g, comp_p, width_p, hertz_a, du,
                               e_run, shrink, fguess, pf, pu)
            gfun = delta - d_pred + beta * (ftot - kbar * delta)
            step = gfun / (1.0 + beta * (ktot - kbar))
            delta -= step
            if abs(step) < 1e-13:       # 0.1 pm: far below any flank deviation
                break
        ftot, ktot = _mesh(delta, s, par, gap_p, gap_g, comp_p, width_p, hertz_a, du,
                           e_run, shrink, fguess, pf, pu)
        for mm in range(2):
            fguess[mm] = pf[mm] if pf[mm] > 0 else 100.0
        nres = ftot - kbar * delta
        for r in range(m):
            u_new[r] -= gvec[r] * nres
            q[r] = qp[r] - G1[r, 0] * gvec[r] * nres
            v[r] = vp[r] - G1[r, 1] * gvec[r] * nres
            u_prev[r] = u_new[r]
        if k >= n_settle:
            o = k - n_settle
            a1 = 0.0
            a2 = 0.0
            enc = 0.0
            genc = 0.0
            wm = 0.0
            for r in range(m):
                acc = u_new[r] - two_zw[r] * v[r] - w2[r] * q[r]
                a1 += rows[0, r] * acc
                a2 += rows[1, r] * acc
                enc += rows[2, r] * q[r]
                genc += rows[3, r] * q[r]
                wm += rows[4, r] * v[r]
            out[o, 0] = a1
            out[o, 1] = a2
            out[o, 2] = enc
            out[o, 3] = genc
            out[o, 4] = ftot
            out[o, 5] = delta
            out[o, 6] = wm
    return out
