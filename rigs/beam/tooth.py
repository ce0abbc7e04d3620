"""Tooth geometry and Weber-Banaschek tooth compliance along the path of contact.

Geometry: involute flank above the form circle, root fillet as the envelope of the rounded
tip of the generating rack (basic rack ISO 53, tip radius 0.38 m), obtained numerically.

Compliance of one tooth for a unit normal load at a point of its flank (Weber 1949,
Weber and Banaschek 1953): the tooth is a cantilever of variable thickness clamped at the
root circle (bending with the moment of both load components, shear with factor 1.2,
compression, plane strain), plus the rotation and translation of its root section in the
rim (Weber's half-plane foundation term) and the Hertzian flattening of the two flanks with
Weber's logarithmic approach of two cylinders bounded by the tooth half-thicknesses.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .params import Gears

# Foundation term coefficients (half-plane form, moment / shear / normal parts)
FOUNDATION_L = 16.67 / np.pi
FOUNDATION_Q = 0.4167


def _foundation_mp(nu: float) -> tuple[float, float]:
    return 2.0 * (1.0 - nu - 2.0 * nu * nu) / (1.0 - nu * nu), 1.534 / (1.0 + nu)


def involute(a):
    return np.tan(a) - a


@dataclass(frozen=True)
class MeshGeometry:
    """Path of contact of the pair, all lengths in m; u runs from the start of contact."""
    r1: float
    r2: float
    rb1: float
    rb2: float
    ra1: float
    ra2: float
    centre_distance: float
    base_pitch: float
    rho1_start: float        # pinion curvature radius at the start of contact
    path_length: float       # g_alpha
    pitch_u: float           # u of the pitch point
    contact_ratio: float

    def rho(self, u):
        """Curvature radii of pinion and gear flanks at path position u."""
        rho1 = self.rho1_start + np.asarray(u)
        rho2 = self.centre_distance * np.sin(self.alpha) - rho1
        return rho1, rho2

    @property
    def alpha(self):
        return np.arccos(self.rb1 / self.r1)


def mesh_geometry(g: Gears) -> MeshGeometry:
    m, a0 = g.module, g.pressure_angle
    r1, r2 = m * g.z_pinion / 2, m * g.z_gear / 2
    rb1, rb2 = r1 * np.cos(a0), r2 * np.cos(a0)
    ra1, ra2 = r1 + g.addendum * m, r2 + g.addendum * m
    a = r1 + r2
    pb = np.pi * m * np.cos(a0)
    rho1_start = a * np.sin(a0) - np.sqrt(ra2**2 - rb2**2)
    rho1_end = np.sqrt(ra1**2 - rb1**2)
    g_len = rho1_end - rho1_start
    return MeshGeometry(r1, r2, rb1, rb2, ra1, ra2, a, pb, rho1_start, g_len,
                        r1 * np.sin(a0) - rho1_start, g_len / pb)


def tooth_profile(z: int, g: Gears, n_fillet: int = 400, n_inv: int = 200):
    """Half-thickness x [m] against the height y [m] along the tooth centre line.

    Returns (y, x) sorted by y from the root-circle section to the tip, and the radius at
    which the fillet meets the involute (form circle).
    """
    m, alpha = g.module, g.pressure_angle
    r = m * z / 2
    rho = g.root_fillet * m
    d_c = g.dedendum * m - rho                         # depth of the rack tip-round centre
    u_c = np.pi * m / 4 - d_c * np.tan(alpha) - rho / np.cos(alpha)
    phi = np.linspace(-0.9, 0.9, 6 * n_fillet)
    cx, cy = u_c + r * phi, np.full_like(phi, r - d_c)
    c, s = np.cos(phi), np.sin(phi)
    gx, gy = cx * c - cy * s, cx * s + cy * c          # centre path in the gear frame
    vx, vy = np.gradient(gx, phi), np.gradient(gy, phi)
    nrm = np.hypot(vx, vy)
    nx, ny = vy / nrm, -vx / nrm                       # envelope normal (towards the root)
    px, py = gx + rho * nx, gy + rho * ny
    # keep only the normals that the tip-round arc actually has (rack frame: -90 .. -alpha)
    rnx, rny = nx * c + ny * s, -nx * s + ny * c
    ang = np.arctan2(rny, rnx)
    keep = (ang >= -np.pi / 2 - 1e-9) & (ang <= -alpha + 1e-9)
    px, py = px[keep], py[keep]
    rad = np.hypot(px, py)
    beta = np.arctan2(px, py)                          # from the space centre line
    psi = np.pi / z - beta                             # tooth half angle
    order = np.argsort(rad)
    rad, psi = rad[order], psi[order]
    r_form = rad[-1]
    rb, ra = r * np.cos(alpha), r + g.addendum * m
    r_inv = np.linspace(max(r_form, rb), ra, n_inv)
    psi_inv = np.pi / (2 * z) + involute(alpha) - involute(np.arccos(np.clip(rb / r_inv, -1, 1)))
    rr = np.concatenate([rad[rad < r_inv[0]], r_inv])
    pp = np.concatenate([psi[rad < r_inv[0]], psi_inv])
    y, x = rr * np.cos(pp), rr * np.sin(pp)
    order = np.argsort(y)
    y, x = y[order], x[order]
    return y, x, r_form


def flank_half_thickness(z: int, g: Gears, r_c):
    """Half angle psi and half thickness x at radii r_c of the involute flank."""
    r = g.module * z / 2
    rb = r * np.cos(g.pressure_angle)
    a_r = np.arccos(np.clip(rb / r_c, -1, 1))
    psi = np.pi / (2 * z) + involute(g.pressure_angle) - involute(a_r)
    return psi, r_c * np.sin(psi), a_r


def tooth_compliance(z: int, g: Gears, r_c, n_int: int = 300, thinning=None):
    """Weber compliances [m/N] of one tooth for a unit normal load at radii r_c.

    thinning: optional material removed from the loaded flank at r_c [m] (wear), which
    reduces the half-thickness above the contact as a first-order correction.
    Returns dict of arrays: bending, shear, axial, foundation, half_thickness, load_angle.
    """
    r_c = np.atleast_1d(np.asarray(r_c, float))
    E, nu, b = g.young, g.poisson, g.face_width
    e_ps = E / (1 - nu * nu)
    G = E / (2 * (1 + nu))
    y_p, x_p, _ = tooth_profile(z, g)
    psi_c, x_c, a_r = flank_half_thickness(z, g, r_c)
    y_c = r_c * np.cos(psi_c)
    a_f = a_r - psi_c                                   # load angle to the tooth normal
    y_f, x_f = y_p[0], x_p[0]
    t = np.linspace(0.0, 1.0, n_int)
    yy = y_f + (y_c[:, None] - y_f) * t[None, :]        # (n, n_int)
    xx = np.interp(yy, y_p, x_p)
    if thinning is not None:
        xx = np.maximum(xx - 0.5 * np.asarray(thinning)[:, None] * t[None, :] ** 2, 0.2 * xx)
    h2 = 2.0 * xx
    ca, sa = np.cos(a_f)[:, None], np.sin(a_f)[:, None]
    lever = ca * (y_c[:, None] - yy) - sa * x_c[:, None]
    dy = (y_c - y_f)
    bend = np.trapezoid(12.0 * lever**2 / (e_ps * b * h2**3), t, axis=1) * dy
    shear = np.trapezoid(1.2 * ca**2 / (G * b * h2), t, axis=1) * dy
    axial = np.trapezoid(sa**2 / (e_ps * b * h2), t, axis=1) * dy
    s_f = 2.0 * x_f
    u_f = y_c - x_c * np.tan(a_f) - y_f
    M, P = _foundation_mp(nu)
    found = (1 - nu * nu) * np.cos(a_f) ** 2 / (E * b) * (
        FOUNDATION_L * (u_f / s_f) ** 2 + M * (u_f / s_f) + P * (1 + FOUNDATION_Q * np.tan(a_f) ** 2))
    return {"bending": bend, "shear": shear, "axial": axial, "foundation": found,
            "half_thickness": x_c, "load_angle": a_f}


@dataclass(frozen=True)
class PathTables:
    """Tooth-pair properties sampled along the path of contact (u grid)."""
    u: np.ndarray                # (n,) path position [m]
    body_pinion: np.ndarray      # (n,) compliance of the pinion tooth body [m/N]
    body_gear: np.ndarray        # (n,) compliance of the gear tooth body [m/N]
    hertz_a: np.ndarray          # (n,) Weber's log constant A for the full face width
    hertz_q: float               # 2(1-nu^2)/(pi E b) [m/N]
    rho1: np.ndarray
    rho2: np.ndarray
    half_pinion: np.ndarray
    half_gear: np.ndarray


def path_tables(g: Gears, geo: MeshGeometry, n: int) -> PathTables:
    u = np.linspace(0.0, geo.path_length, n)
    rho1, rho2 = geo.rho(u)
    rc1 = np.hypot(geo.rb1, rho1)
    rc2 = np.hypot(geo.rb2, rho2)
    tp = tooth_compliance(g.z_pinion, g, rc1)
    tg = tooth_compliance(g.z_gear, g, rc2)
    sf = g.stiffness_factor
    body_p = (tp["bending"] + tp["shear"] + tp["axial"] + tp["foundation"]) / sf
    body_g = (tg["bending"] + tg["shear"] + tg["axial"] + tg["foundation"]) / sf
    E, nu, b = g.young, g.poisson, g.face_width
    R = rho1 * rho2 / (rho1 + rho2)
    h1 = tp["half_thickness"] / np.cos(tp["load_angle"])
    h2 = tg["half_thickness"] / np.cos(tg["load_angle"])
    A = np.log(4 * h1 * h2 * np.pi * b * E / (8 * R * (1 - nu * nu))) - nu / (1 - nu)
    q = 2 * (1 - nu * nu) / (np.pi * E * b) / sf
    return PathTables(u, body_p, body_g, A, q, rho1, rho2, tp["half_thickness"], tg["half_thickness"])
