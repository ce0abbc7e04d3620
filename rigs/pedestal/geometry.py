"""Involute geometry of the 19/52 spur pair and its mesh stiffness along the path of contact.

Everything is expressed on the *path coordinate* ``s`` [m]: the distance along the line of
action from the start of active contact A (where the gear's tip circle cuts the line of action)
to its end E (the pinion's tip circle). A point ``s`` meets one point of the pinion flank and one
of the gear flank, so flank deviations, damage and stiffness of a tooth pair are all tables on
``s``. A pinion tooth enters at A near its root and leaves at E at its tip.

Stiffness (ISO 6336-1:2019, method B, section 9):

* theoretical single stiffness ``c'_th = 1 / q'`` from the series in ``z_n1``, ``z_n2``, ``x``;
* ``c' = c'_th C_M C_R C_B cos(beta)`` with ``C_M = 0.8`` (solid disc gears, ``C_R = 1``) and
  the basic-rack factor ``C_B``; for a line load below 100 N/mm ISO reduces it by
  ``(F_t K_A / b / 100) ** 0.25``;
* mesh stiffness ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)``.

ISO gives only these two numbers. The rig's own law along the path is a parabola for one tooth
pair, ``k1(s) = k_max (1 - a (2 xi - 1)^2)``, ``xi = s / L``, stiffest mid-path where the load acts
near the tooth's middle height and softest at both ends (tip of one tooth against root of the
other). Its two constants are fixed by ISO: the maximum is ``c' b`` and the mesh-cycle mean of the
sum over the pairs in contact equals ``c_gamma b``, which gives ``a = 3/4 (1 - 1/eps_alpha)``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

#: ISO 6336-1 Table 9 coefficients of q' [mm um / N].
_Q_COEFF = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)


@dataclass(frozen=True)
class GearPair:
    """Nominal geometry of the spur pair (SI units; angles in rad).

    The defaults are the rig's datasheet: 19/52 teeth, module 3 mm, 20 deg, standard
    (unshifted) KHK-type modular gears in S45C, face width 30 mm, hobbed to ISO 1328 grade 8.
    """

    z1: int = 19
    z2: int = 52
    module: float = 3.0e-3
    pressure_angle: float = math.radians(20.0)
    face_width: float = 30.0e-3
    addendum: float = 1.0          # in modules
    dedendum: float = 1.25         # in modules (basic rack h_fP)
    young: float = 206e9           # [Pa] S45C
    poisson: float = 0.3

    # -- circles ---------------------------------------------------------------------------
    @property
    def r1(self) -> float:
        return 0.5 * self.module * self.z1

    @property
    def r2(self) -> float:
        return 0.5 * self.module * self.z2

    @property
    def rb1(self) -> float:
        return self.r1 * np.cos(self.pressure_angle)

    @property
    def rb2(self) -> float:
        return self.r2 * np.cos(self.pressure_angle)

    @property
    def ra1(self) -> float:
        return self.r1 + self.addendum * self.module

    @property
    def ra2(self) -> float:
        return self.r2 + self.addendum * self.module

    @property
    def centre_distance(self) -> float:
        return self.r1 + self.r2

    @property
    def base_pitch(self) -> float:
        return np.pi * self.module * np.cos(self.pressure_angle)

    @property
    def ratio(self) -> float:
        """Speed ratio pinion/gear, z2/z1."""
        return self.z2 / self.z1

    # -- path of contact -------------------------------------------------------------------
    @cached_property
    def tangent_length(self) -> float:
        """Distance T1T2 between the tangent points on the two base circles [m]."""
        return self.centre_distance * np.sin(self.pressure_angle)

    @cached_property
    def rho1_start(self) -> float:
        """Pinion radius of curvature at A, the start of active contact [m]."""
        return self.tangent_length - np.sqrt(self.ra2 ** 2 - self.rb2 ** 2)

    @cached_property
    def path_length(self) -> float:
        """Length L of the path of contact AE [m]."""
        return np.sqrt(self.ra1 ** 2 - self.rb1 ** 2) - self.rho1_start

    @cached_property
    def contact_ratio(self) -> float:
        """Transverse contact ratio eps_alpha = L / p_b."""
        return self.path_length / self.base_pitch

    @cached_property
    def pitch_point(self) -> float:
        """Path coordinate of the pitch point [m]."""
        return self.r1 * np.sin(self.pressure_angle) - self.rho1_start

    def radii_of_curvature(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Flank radii of curvature (pinion, gear) at path coordinate ``s`` [m]."""
        rho1 = self.rho1_start + np.asarray(s, float)
        return rho1, self.tangent_length - rho1

    def sliding_ratio(self, s: np.ndarray) -> np.ndarray:
        """(v1 - v2) / v1 of the flank surface speeds; 0 at the pitch point."""
        rho1, rho2 = self.radii_of_curvature(s)
        return (rho1 - rho2 * self.z1 / self.z2) / rho1

    # -- ISO 6336 stiffness ----------------------------------------------------------------
    @cached_property
    def single_stiffness_th(self) -> float:
        """Theoretical single stiffness c'_th [N/(mm um)] (x1 = x2 = 0)."""
        c = _Q_COEFF
        q = c[0] + c[1] / self.z1 + c[2] / self.z2
        return 1.0 / q

    @cached_property
    def basic_rack_factor(self) -> float:
        """ISO 6336-1 C_B for the basic rack (h_fP / m_n, alpha_n)."""
        alpha_deg = np.rad2deg(self.pressure_angle)
        return (1 + 0.5 * (1.2 - self.dedendum)) * (1 - 0.02 * (20.0 - alpha_deg))

    def single_stiffness(self, load: float) -> float:
        """ISO c' [N/(mm um)] at a pinion-side tangential load from output torque ``load`` [N.m]."""
        c = self.single_stiffness_th * 0.8 * 1.0 * self.basic_rack_factor
        line_load = abs(load) / self.r2 / (self.face_width * 1e3)  # [N/mm]
        if line_load < 100.0:
            c *= (max(line_load, 5.0) / 100.0) ** 0.25
        return c

    def pair_stiffness_max(self, load: float) -> float:
        """Peak single tooth-pair stiffness k_max = c' b [N/m]."""
        return self.single_stiffness(load) * self.face_width * 1e3 * 1e6

    def mesh_stiffness_iso(self, load: float) -> float:
        """ISO mean mesh stiffness c_gamma_alpha b [N/m]."""
        return self.pair_stiffness_max(load) * (0.75 * self.contact_ratio + 0.25)

    @cached_property
    def stiffness_curvature(self) -> float:
        """Coefficient a of the parabolic single-pair law (see module docstring)."""
        return 0.75 * (1.0 - 1.0 / self.contact_ratio)

    def pair_stiffness_shape(self, s: np.ndarray) -> np.ndarray:
        """k1(s) / k_max of one tooth pair, 0 outside the path of contact."""
        xi = np.asarray(s, float) / self.path_length
        shape = 1.0 - self.stiffness_curvature * (2.0 * xi - 1.0) ** 2
        return np.where((xi >= 0.0) & (xi <= 1.0), shape, 0.0)

    def hertz_half_width(self, s: np.ndarray, line_load: np.ndarray) -> np.ndarray:
        """Hertzian half-width b_H [m] of the line contact at ``s`` for a load per length [N/m]."""
        rho1, rho2 = self.radii_of_curvature(s)
        r_eq = rho1 * rho2 / (rho1 + rho2)
        e_star = self.young / (2.0 * (1.0 - self.poisson ** 2))
        return np.sqrt(4.0 * np.asarray(line_load, float) * r_eq / (np.pi * e_star))
