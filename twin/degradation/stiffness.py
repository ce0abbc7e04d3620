"""Single-tooth-pair mesh stiffness from gear geometry and material.

Potential-energy method (Yang & Lin 1987; Tian 2004; Chaari et al. 2009) with the fillet-
foundation compliance of Sainsot, Velex & Duverger (2004).  For a unit normal force F at the
contact point, the energy stored in each tooth, a cantilever along its centreline with the
generated section of :class:`~twin.degradation.tooth.ToothForm`, gives the compliances

    1/k_b = int M(y)^2 / (E' I(y)) dy,   M(y) = P_x u_y - (P_y - y) u_x       bending
    1/k_s = int 1.2 u_x^2 / (G A(y)) dy                                       shear
    1/k_a = int u_y^2 / (E' A(y)) dy                                          axial compression
    1/k_f = cos^2(a_m) / (E' L) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2 a_m)]
                                                                              fillet foundation
    1/k_h = 4 (1 - nu^2) / (pi E L)                                           Hertz (Yang & Sun 1985)

with P the contact point and u the unit force (along the line of action, into the tooth) in
the tooth frame, A = 2 h L, I = (2 h)^3 L / 12 (h: half-thickness at height y, L: face width),
y from the root circle to the contact.  u_f is the distance from the root circle to where the
force line crosses the centreline, S_f the tooth thickness at the root circle, a_m the angle
of the force with the normal to the centreline; L*, M*, P*, Q* are Sainsot's polynomials in
h_f = r_f / r_int (bore) and the half-angle of the tooth at the root circle.  The single pair
is the series connection of both teeth and the contact:

    1 / k_pair = 1/k_h + sum_{pinion, gear} (1/k_b + 1/k_s + 1/k_a + 1/k_f)

E' = E / (1 - nu^2) (plane strain: the face width is several tooth thicknesses), G = E / (2 (1 +
nu)).  The compliances are evaluated at the roll positions xi of
:class:`~twin.degradation.geometry.GearPair` (any z1, z2, module, face width, pressure angle and
profile shift).

ISO 6336-1:2019 method B (:func:`iso_single_stiffness`) gives the standard's single stiffness
c' b and mesh stiffness c_gamma_alpha b for comparison; :func:`stiffness_report` states both.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from twin.degradation.geometry import GearPair
from twin.degradation.tooth import ToothForm
from twin.errors import ParameterError

# Sainsot, Velex & Duverger, J. Mech. Des. 126 (2004) 748-752, Table 1:
# X*(h_f, theta_f) = A / theta_f^2 + B h_f^2 + C h_f / theta_f + D / theta_f + E h_f + F
_SAINSOT = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}
# ISO 6336-1:2019, 9.3.2, Table 10: q' = C1 + C2/zn1 + C3/zn2 + C4 x1 + C5 x1/zn1 + C6 x2 + C7 x2/zn2
# + C8 x1^2 + C9 x2^2 [mm um / N]
_ISO_C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
_ISO_CM = 0.8        # correction factor C_M (solid disc gears, theory vs measurement)
_ISO_CR = 1.0        # gear blank factor C_R (solid discs)


@dataclass(frozen=True)
class PairCompliance:
    """Compliances [m/N] of one tooth pair at roll positions xi (arrays of the shape of xi).

    ``pinion`` and ``gear`` map ``bending``, ``shear``, ``axial``, ``foundation`` to arrays;
    ``hertz`` is the contact compliance (constant along the path).
    """

    xi: np.ndarray
    pinion: dict
    gear: dict
    hertz: np.ndarray

    @property
    def total(self) -> np.ndarray:
        """1 / k_pair [m/N]."""
        return self.hertz + sum(self.pinion.values()) + sum(self.gear.values())

    @property
    def bulk(self) -> np.ndarray:
        """The tooth-body part (bending, shear, axial, foundation of both teeth) [m/N]."""
        return sum(self.pinion.values()) + sum(self.gear.values())

    @property
    def stiffness(self) -> np.ndarray:
        """k_pair = 1 / total [N/m]."""
        return 1.0 / self.total


def _tooth(geometry: GearPair, which: str) -> ToothForm:
    z = geometry.z1 if which == "pinion" else geometry.z2
    x = geometry.profile_shift_pinion if which == "pinion" else geometry.profile_shift_gear
    return _tooth_cached(z, geometry.module, geometry.pressure_angle, x, geometry.addendum_coefficient,
                         geometry.dedendum_coefficient, geometry.root_radius_coefficient)


@lru_cache(maxsize=32)
def _tooth_cached(z, m, a, x, ha, hf, crho) -> ToothForm:
    return ToothForm(z, m, a, x, ha, hf, crho)


def _sainsot(h_f: float, theta_f: float) -> dict[str, float]:
    return {k: a / theta_f ** 2 + b * h_f ** 2 + c * h_f / theta_f + d / theta_f + e * h_f + f
            for k, (a, b, c, d, e, f) in _SAINSOT.items()}


def tooth_compliance(tooth: ToothForm, radius, *, face_width: float, youngs_modulus: float,
                     poisson_ratio: float, bore_radius: float | None = None,
                     n_section: int = 400) -> dict[str, np.ndarray]:
    """Bending, shear, axial and fillet-foundation compliance [m/N] of one tooth loaded along the
    line of action at flank radius ``radius`` [m] (array).

    ``bore_radius`` [m] is the inner radius of the gear body (default: half the root radius).
    """
    radius = np.atleast_1d(np.asarray(radius, dtype=float))
    e_plane = youngs_modulus / (1.0 - poisson_ratio ** 2)
    shear_modulus = youngs_modulus / (2.0 * (1.0 + poisson_ratio))
    rb = tooth.base_radius
    if radius.min() < rb * (1 - 1e-12):
        raise ParameterError(f"contact radius {radius.min()!r} m lies inside the base circle {rb!r} m")
    r_sec, y_sec, h_sec = tooth.section(n_section)
    # contact point and force direction in the tooth frame (see the module docstring)
    psi = tooth.half_angle(np.clip(radius, tooth.root_radius, tooth.tip_radius))
    alpha_r = np.arccos(np.clip(rb / radius, -1.0, 1.0))
    px, py = radius * np.sin(psi), radius * np.cos(psi)
    tx, ty = rb * np.sin(psi - alpha_r), rb * np.cos(psi - alpha_r)
    ux, uy = tx - px, ty - py
    norm = np.hypot(ux, uy)
    ux, uy = ux / norm, uy / norm
    area = 2.0 * h_sec * face_width                                   # (S,)
    inertia = (2.0 * h_sec) ** 3 * face_width / 12.0
    y = y_sec[None, :]
    loaded = y <= py[:, None]                                           # sections below the contact
    moment = px[:, None] * uy[:, None] - (py[:, None] - y) * ux[:, None]
    bending = np.where(loaded, moment ** 2 / (e_plane * inertia), 0.0)
    shear = np.where(loaded, 1.2 * ux[:, None] ** 2 / (shear_modulus * area), 0.0)
    axial = np.where(loaded, uy[:, None] ** 2 / (e_plane * area), 0.0)
    out = {"bending": np.trapezoid(bending, y_sec, axis=1), "shear": np.trapezoid(shear, y_sec, axis=1),
           "axial": np.trapezoid(axial, y_sec, axis=1)}
    # fillet foundation (Sainsot et al. 2004)
    rf = tooth.root_radius
    theta_f = float(tooth.half_angle(rf))
    r_int = 0.5 * rf if bore_radius is None else float(bore_radius)
    coef = _sainsot(rf / r_int, theta_f)
    s_f = 2.0 * rf * theta_f
    # height where the force line crosses the centreline (x = 0)
    y_cross = py - px * uy / ux
    u_f = y_cross - rf
    cos_m, tan_m = np.abs(ux), np.abs(uy / ux)
    out["foundation"] = cos_m ** 2 / (e_plane * face_width) * (
        coef["L"] * (u_f / s_f) ** 2 + coef["M"] * (u_f / s_f) + coef["P"] * (1.0 + coef["Q"] * tan_m ** 2))
    return out


def pair_compliance(geometry: GearPair, xi, *, n_section: int = 400) -> PairCompliance:
    """Compliances of the tooth pair in contact at roll positions ``xi`` (any shape, in [0, 1])."""
    if not isinstance(geometry, GearPair):
        raise ParameterError(f"geometry must be a GearPair, got {geometry!r}")
    xi_arr = np.asarray(xi, dtype=float)
    flat = xi_arr.ravel()
    rho1, rho2 = geometry.rho1(flat), geometry.rho2(flat)
    r1 = np.sqrt(geometry.base_radius_pinion ** 2 + rho1 ** 2)
    r2 = np.sqrt(geometry.base_radius_gear ** 2 + rho2 ** 2)
    common = dict(face_width=geometry.face_width, youngs_modulus=geometry.youngs_modulus,
                  poisson_ratio=geometry.poisson_ratio, n_section=n_section)
    pin = tooth_compliance(_tooth(geometry, "pinion"), r1, bore_radius=geometry.bore_radius_pinion, **common)
    gear = tooth_compliance(_tooth(geometry, "gear"), r2, bore_radius=geometry.bore_radius_gear, **common)
    hertz = np.full(flat.shape, 4.0 * (1.0 - geometry.poisson_ratio ** 2)
                    / (math.pi * geometry.youngs_modulus * geometry.face_width))
    shape = xi_arr.shape
    return PairCompliance(xi_arr, {k: v.reshape(shape) for k, v in pin.items()},
                          {k: v.reshape(shape) for k, v in gear.items()}, hertz.reshape(shape))


def pair_stiffness(geometry: GearPair, xi) -> np.ndarray:
    """Single-tooth-pair stiffness k_pair [N/m] at roll positions ``xi`` (shape of xi)."""
    return pair_compliance(geometry, xi).stiffness


def k_pair_nodes(geometry: GearPair, n_profile: int = 11) -> list[float]:
    """k_pair [N/m] at the FMU's ``n_profile`` equally spaced roll positions, as a list."""
    if not (isinstance(n_profile, (int, np.integer)) and n_profile >= 2):
        raise ParameterError(f"n_profile must be an integer >= 2, got {n_profile!r}")
    return [float(k) for k in pair_stiffness(geometry, np.linspace(0.0, 1.0, int(n_profile)))]


def mesh_stiffness_curve(geometry: GearPair, n: int = 400, stiffness=None) -> tuple[np.ndarray, np.ndarray]:
    """Mesh stiffness over one mesh cycle: sum of the pairs in contact (no load sharing needed).

    Returns ``(fraction, k_mesh)``, (n,) each: position in the mesh cycle (0 = a pair enters
    contact) and the summed stiffness [N/m].  ``stiffness(xi)`` defaults to :func:`pair_stiffness`.
    """
    f = np.linspace(0.0, 1.0, n, endpoint=False)
    k_of = stiffness or (lambda x: pair_stiffness(geometry, x))
    cr = geometry.contact_ratio
    total = np.zeros(n)
    for j in range(int(math.ceil(cr)) + 1):
        xi = (f + j) / cr
        inside = xi <= 1.0
        if inside.any():
            total[inside] += k_of(xi[inside])
    return f, total


@dataclass(frozen=True)
class IsoStiffness:
    """ISO 6336-1 method B stiffness of a solid spur pair."""

    single_per_width: float     # c' [N/m per m of face width] (N/(mm um) x 1e9)
    single: float               # c' b [N/m]
    mesh: float                 # c_gamma_alpha b = c' b (0.75 eps_alpha + 0.25) [N/m]


def iso_single_stiffness(geometry: GearPair) -> IsoStiffness:
    """ISO 6336-1:2019 method B: c' = c'_th C_M C_R C_B, c'_th = 1 / q' (spur, solid gears).

    C_B = [1 + 0.5 (1.2 - h_fP/m)] [1 - 0.02 (20 deg - alpha)], with h_fP the rack dedendum.  The
    standard applies to steel pairs; the result is scaled by E / 206 GPa for other moduli.
    """
    z1, z2 = geometry.z1, geometry.z2
    x1, x2 = geometry.profile_shift_pinion, geometry.profile_shift_gear
    c = _ISO_C
    q = (c[0] + c[1] / z1 + c[2] / z2 + c[3] * x1 + c[4] * x1 / z1 + c[5] * x2 + c[6] * x2 / z2
         + c[7] * x1 ** 2 + c[8] * x2 ** 2)
    c_th = 1.0 / q                                                   # N/(mm um)
    c_b = (1.0 + 0.5 * (1.2 - geometry.dedendum_coefficient)) * (
        1.0 - 0.02 * (20.0 - math.degrees(geometry.pressure_angle)))
    c_prime = c_th * _ISO_CM * _ISO_CR * c_b * geometry.youngs_modulus / 206e9
    per_width = c_prime * 1e9                                        # N/(mm um) -> N/m per m
    single = per_width * geometry.face_width
    return IsoStiffness(per_width, single, single * (0.75 * geometry.contact_ratio + 0.25))


@dataclass(frozen=True)
class StiffnessReport:
    """Potential-energy mesh stiffness against ISO 6336-1 for one gear pair."""

    k_pair_max: float           # largest single-pair stiffness along the path [N/m]
    k_pair_pitch: float         # at the pitch point [N/m]
    k_mesh_mean: float          # mean over a mesh cycle of the summed pair stiffness [N/m]
    iso: IsoStiffness

    @property
    def single_difference(self) -> float:
        """(k_pair_max - c' b) / c' b."""
        return self.k_pair_max / self.iso.single - 1.0

    @property
    def mesh_difference(self) -> float:
        """(k_mesh_mean - c_gamma_alpha b) / c_gamma_alpha b."""
        return self.k_mesh_mean / self.iso.mesh - 1.0


def stiffness_report(geometry: GearPair) -> StiffnessReport:
    """The potential-energy stiffness of ``geometry`` beside ISO 6336-1's."""
    xi = np.linspace(0.0, 1.0, 201)
    k = pair_stiffness(geometry, xi)
    _, k_mesh = mesh_stiffness_curve(geometry)
    return StiffnessReport(float(k.max()), float(pair_stiffness(geometry, geometry.pitch_point_xi)),
                           float(k_mesh.mean()), iso_single_stiffness(geometry))
