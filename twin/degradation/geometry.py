"""Spur-gear pair geometry along the path of contact, and Hertzian line contact.

Conventions (shared with ``GearTwin.Gearbox21``)
------------------------------------------------
* ``xi`` is the roll position along the path of contact, dimensionless, in [0, 1]:
  ``xi = 0`` is the start of contact (gear tip on the pinion root side) and ``xi = 1`` the end
  of contact (pinion tip).  The FMU's ``roll[i]`` outputs use the same coordinate: the mesh
  phase grows linearly with the pinion angle, and so does the distance along the line of
  action, ``s = rb1 * theta1``.
* ``s`` is the distance along the line of action [m] measured from ``T1``, the point where the
  line of action touches the pinion's base circle.  On an involute the radius of curvature at
  the contact point equals that distance, so ``rho1 = s`` and ``rho2 = T1T2 - s``.
* Profile-shifted gears (coefficients ``x1``, ``x2``) run on the centre distance without
  backlash: ``inv(alpha_w) = inv(alpha) + 2 tan(alpha) (x1 + x2) / (z1 + z2)``,
  ``a_w = (r1 + r2) cos(alpha) / cos(alpha_w)``; tip radii ``r + (h_a + x) m`` (no tip
  shortening).  Unshifted gears (the default) give ``alpha_w = alpha`` and ``a = r1 + r2``.
* Speeds: ``omega1`` [rad/s] is the pinion (input shaft) speed; ``omega2 = omega1 * z1 / z2``.

Hertz line contact per unit face width ``w = F / face_width`` [N/m], equal materials:

    1/E* = 2 (1 - nu^2) / E,   b = sqrt(4 w R / (pi E*)),   Pmax = 2 w / (pi b) = sqrt(w E* / (pi R))

with ``R = rho1 rho2 / (rho1 + rho2)`` the equivalent radius (Johnson, *Contact Mechanics*, 1985,
section 4.2).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from twin.errors import ParameterError

# FMU parameter name -> GearPair field.  The elastic constants are not FMU parameters; they are
# accepted under their own names so a scenario can override the S45C defaults.
_FMU_NAMES = {
    "z1": "z1",
    "z2": "z2",
    "module": "module",
    "alpha": "pressure_angle",
    "face_width": "face_width",
    "addendum_coefficient": "addendum_coefficient",
    "youngs_modulus": "youngs_modulus",
    "poisson_ratio": "poisson_ratio",
    "profile_shift_pinion": "profile_shift_pinion",
    "profile_shift_gear": "profile_shift_gear",
    "dedendum_coefficient": "dedendum_coefficient",
    "root_radius_coefficient": "root_radius_coefficient",
    "bore_radius_pinion": "bore_radius_pinion",
    "bore_radius_gear": "bore_radius_gear",
}


def involute(angle):
    """inv(a) = tan(a) - a [rad]."""
    return np.tan(angle) - angle


def inverse_involute(value: float) -> float:
    """The angle a in (0, pi/2) with tan(a) - a = value (Newton from Cheng's cube-root start)."""
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(f"involute function value must be > 0, got {value!r}")
    a = min(1.5, (3.0 * value) ** (1.0 / 3.0))
    for _ in range(60):
        t = math.tan(a)
        step = (t - a - value) / (t * t)
        a -= step
        if abs(step) < 1e-15:
            break
    return a

# Tolerance on xi when checking that a roll position lies on the path of contact.
_XI_TOL = 1e-9


def _as_xi(xi: Any) -> np.ndarray:
    """Roll positions as a float array, checked to lie in [0, 1]."""
    arr = np.asarray(xi, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"roll position xi must be finite, got {xi!r}")
    if arr.size and (arr.min() < -_XI_TOL or arr.max() > 1 + _XI_TOL):
        bad = arr[(arr < -_XI_TOL) | (arr > 1 + _XI_TOL)].ravel()[0]
        raise ParameterError(f"roll position xi must lie in [0, 1] (the path of contact), got {bad!r}")
    return np.clip(arr, 0.0, 1.0)


def _as_force(force: Any) -> np.ndarray:
    arr = np.asarray(force, dtype=float)
    if not np.all(np.isfinite(arr)) or (arr.size and arr.min() < 0):
        bad = arr[~np.isfinite(arr) | (arr < 0)].ravel()[0]
        raise ParameterError(f"contact force must be finite and >= 0 N, got {bad!r}")
    return arr


@dataclass(frozen=True)
class GearPair:
    """Geometry and elastic constants of a standard external spur-gear pair.

    Attributes
    ----------
    z1, z2 : int
        Tooth numbers of the pinion (driver) and the gear.
    module : float
        Module [m].
    pressure_angle : float
        Pressure angle [rad].
    face_width : float
        Face width [m].
    addendum_coefficient : float
        Addendum as a multiple of the module (both gears).
    youngs_modulus : float
        Young's modulus [Pa] of both gears; 206 GPa for JIS S45C.
    poisson_ratio : float
        Poisson's ratio of both gears.
    profile_shift_pinion, profile_shift_gear : float
        Profile shift coefficients x1, x2 (multiples of the module).
    dedendum_coefficient : float
        Dedendum of the generating rack (= root depth below the reference circle for x = 0) as a
        multiple of the module; 1.25 for the ISO 53 basic rack.
    root_radius_coefficient : float
        Tip radius of the generating rack (the root fillet) as a multiple of the module; 0.38
        for ISO 53 profile A.
    bore_radius_pinion, bore_radius_gear : float or None
        Inner radius of the gear body (shaft bore) [m], for the fillet-foundation compliance of
        the mesh stiffness; None takes half the root radius.
    """

    z1: int = 19
    z2: int = 52
    module: float = 3.0e-3
    pressure_angle: float = math.radians(20.0)
    face_width: float = 0.020
    addendum_coefficient: float = 1.0
    youngs_modulus: float = 206e9
    poisson_ratio: float = 0.3
    profile_shift_pinion: float = 0.0
    profile_shift_gear: float = 0.0
    dedendum_coefficient: float = 1.25
    root_radius_coefficient: float = 0.38
    bore_radius_pinion: float | None = None
    bore_radius_gear: float | None = None

    def __post_init__(self):
        for name in ("z1", "z2"):
            value = getattr(self, name)
            try:
                ok = float(value) == int(value) and int(value) >= 5
            except (TypeError, ValueError, OverflowError):
                ok = False
            if not ok:
                raise ParameterError(f"{name} must be an integer >= 5, got {value!r}")
            object.__setattr__(self, name, int(value))
        positive = ("module", "face_width", "addendum_coefficient", "youngs_modulus")
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ParameterError(f"{name} must be a finite number > 0, got {value!r}")
            object.__setattr__(self, name, float(value))
        alpha = self.pressure_angle
        if not (isinstance(alpha, (int, float)) and math.radians(5) <= alpha <= math.radians(45)):
            raise ParameterError(f"pressure_angle (alpha) must lie in [5, 45] deg (in rad), got {alpha!r}")
        object.__setattr__(self, "pressure_angle", float(alpha))
        nu = self.poisson_ratio
        if not (isinstance(nu, (int, float)) and 0 <= nu < 0.5):
            raise ParameterError(f"poisson_ratio must lie in [0, 0.5), got {nu!r}")
        object.__setattr__(self, "poisson_ratio", float(nu))
        for name in ("profile_shift_pinion", "profile_shift_gear"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and -1.0 <= value <= 1.5):
                raise ParameterError(f"{name} must be a number in [-1, 1.5], got {value!r}")
            object.__setattr__(self, name, float(value))
        for name, lo, hi in (("dedendum_coefficient", 1.0, 2.0), ("root_radius_coefficient", 0.0, 0.6)):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise ParameterError(f"{name} must be a number in [{lo}, {hi}], got {value!r}")
            object.__setattr__(self, name, float(value))
        for name, root in (("bore_radius_pinion", self.root_radius_pinion),
                           ("bore_radius_gear", self.root_radius_gear)):
            value = getattr(self, name)
            if value is None:
                continue
            if not (isinstance(value, (int, float)) and math.isfinite(value) and 0 < value < root):
                raise ParameterError(f"{name} must be a number in (0, root radius {root:.4g} m), got {value!r}")
            object.__setattr__(self, name, float(value))
        if self.root_radius_pinion <= 0 or self.root_radius_gear <= 0:
            raise ParameterError(f"root circle radius must be > 0 (z1={self.z1}, z2={self.z2})")
        # Contact must start outside the pinion base circle (no interference / undercut) and end
        # before the gear base circle, otherwise rho1 or rho2 would vanish on the path.
        if self.contact_start <= 0:
            raise ParameterError(
                f"gear tip reaches below the pinion base circle (involute interference) for z1={self.z1}, "
                f"z2={self.z2}, addendum_coefficient={self.addendum_coefficient!r}")
        if self.contact_end >= self.line_of_action_length:
            raise ParameterError(
                f"pinion tip reaches below the gear base circle (involute interference) for z1={self.z1}, "
                f"z2={self.z2}, addendum_coefficient={self.addendum_coefficient!r}")
        if self.contact_ratio < 1:
            raise ParameterError(f"contact ratio must be >= 1 for continuous meshing, got {self.contact_ratio!r}")

    @classmethod
    def from_parameters(cls, mapping: Mapping[str, Any]) -> "GearPair":
        """Build from FMU parameter names (``z1``, ``z2``, ``module``, ``alpha``, ``face_width``,
        ``addendum_coefficient``; also ``youngs_modulus``, ``poisson_ratio``).

        Unknown keys are ignored; missing keys take the defaults.  Invalid values raise
        :class:`~twin.errors.ParameterError` naming the value.
        """
        known = {f.name for f in fields(cls)}
        kwargs = {field: mapping[name] for name, field in _FMU_NAMES.items() if name in mapping and field in known}
        return cls(**kwargs)

    # ---- radii and lengths [m] -------------------------------------------------------------
    @property
    def gear_ratio(self) -> float:
        """z2 / z1 (speed reduction), dimensionless."""
        return self.z2 / self.z1

    @property
    def pitch_radius_pinion(self) -> float:
        return 0.5 * self.module * self.z1

    @property
    def pitch_radius_gear(self) -> float:
        return 0.5 * self.module * self.z2

    @property
    def base_radius_pinion(self) -> float:
        """rb1 [m], as ``rb1`` in the FMU."""
        return self.pitch_radius_pinion * math.cos(self.pressure_angle)

    @property
    def base_radius_gear(self) -> float:
        """rb2 [m], as ``rb2`` in the FMU."""
        return self.pitch_radius_gear * math.cos(self.pressure_angle)

    @property
    def tip_radius_pinion(self) -> float:
        return self.pitch_radius_pinion + (self.addendum_coefficient + self.profile_shift_pinion) * self.module

    @property
    def tip_radius_gear(self) -> float:
        return self.pitch_radius_gear + (self.addendum_coefficient + self.profile_shift_gear) * self.module

    @property
    def root_radius_pinion(self) -> float:
        """rf1 = r1 - (h_f - x1) m [m]."""
        return self.pitch_radius_pinion - (self.dedendum_coefficient - self.profile_shift_pinion) * self.module

    @property
    def root_radius_gear(self) -> float:
        """rf2 = r2 - (h_f - x2) m [m]."""
        return self.pitch_radius_gear - (self.dedendum_coefficient - self.profile_shift_gear) * self.module

    @property
    def working_pressure_angle(self) -> float:
        """alpha_w [rad]: inv(alpha_w) = inv(alpha) + 2 tan(alpha) (x1 + x2) / (z1 + z2)."""
        shift = self.profile_shift_pinion + self.profile_shift_gear
        if shift == 0:
            return self.pressure_angle
        a = self.pressure_angle
        return inverse_involute(math.tan(a) - a + 2.0 * math.tan(a) * shift / (self.z1 + self.z2))

    @property
    def centre_distance(self) -> float:
        """a_w = (r1 + r2) cos(alpha) / cos(alpha_w) [m] (r1 + r2 for unshifted gears)."""
        a = self.pitch_radius_pinion + self.pitch_radius_gear
        if self.profile_shift_pinion + self.profile_shift_gear == 0:
            return a
        return a * math.cos(self.pressure_angle) / math.cos(self.working_pressure_angle)

    @property
    def base_pitch(self) -> float:
        """pb = pi m cos(alpha) [m], the spacing of successive tooth pairs on the line of action."""
        return math.pi * self.module * math.cos(self.pressure_angle)

    @property
    def line_of_action_length(self) -> float:
        """T1T2 = a_w sin(alpha_w) [m], between the tangent points on the two base circles."""
        return self.centre_distance * math.sin(self.working_pressure_angle)

    @property
    def contact_start(self) -> float:
        """s_A [m]: start of contact (gear tip circle) measured from T1."""
        rb2, ra2 = self.base_radius_gear, self.tip_radius_gear
        return self.line_of_action_length - math.sqrt(ra2 ** 2 - rb2 ** 2)

    @property
    def contact_end(self) -> float:
        """s_E [m]: end of contact (pinion tip circle) measured from T1."""
        rb1, ra1 = self.base_radius_pinion, self.tip_radius_pinion
        return math.sqrt(ra1 ** 2 - rb1 ** 2)

    @property
    def path_of_contact_length(self) -> float:
        """L = s_E - s_A [m]."""
        return self.contact_end - self.contact_start

    @property
    def contact_ratio(self) -> float:
        """Transverse contact ratio L / pb, the FMU's ``contact_ratio`` (1.6526 by default)."""
        return self.path_of_contact_length / self.base_pitch

    @property
    def pitch_point_xi(self) -> float:
        """Roll position of the (operating) pitch point, rho1 = rb1 tan(alpha_w), where sliding vanishes."""
        pitch = self.base_radius_pinion * math.tan(self.working_pressure_angle)
        return (pitch - self.contact_start) / self.path_of_contact_length

    @property
    def contact_modulus(self) -> float:
        """E* [Pa], with 1/E* = 2 (1 - nu^2) / E for two bodies of the same material."""
        return self.youngs_modulus / (2.0 * (1.0 - self.poisson_ratio ** 2))

    # ---- functions of the roll position (vectorised; xi of any shape, values in [0, 1]) ----
    def line_of_action_position(self, xi) -> np.ndarray:
        """s(xi) = s_A + xi L [m], distance from T1 along the line of action; same shape as xi."""
        return self.contact_start + _as_xi(xi) * self.path_of_contact_length

    def rho1(self, xi) -> np.ndarray:
        """Radius of curvature of the pinion flank at the contact point [m]; same shape as xi."""
        return self.line_of_action_position(xi)

    def rho2(self, xi) -> np.ndarray:
        """Radius of curvature of the gear flank at the contact point [m]; same shape as xi."""
        return self.line_of_action_length - self.line_of_action_position(xi)

    def equivalent_radius(self, xi) -> np.ndarray:
        """R = rho1 rho2 / (rho1 + rho2) [m]; same shape as xi."""
        r1, r2 = self.rho1(xi), self.rho2(xi)
        return r1 * r2 / (r1 + r2)

    def flank_position(self, xi) -> np.ndarray:
        """Arc length of the pinion involute from its base circle to the contact point [m].

        For an involute, d(arc) = rho d(phi) and rho = rb1 phi, so arc = rho1^2 / (2 rb1).  This is
        the physical coordinate along the pinion flank in which the Hertzian contact half-width b
        is measured (the contact is tangent to the flank).  Same shape as xi.
        """
        return self.rho1(xi) ** 2 / (2.0 * self.base_radius_pinion)

    def xi_at_flank_position(self, u) -> np.ndarray:
        """Inverse of :meth:`flank_position`: roll position of the pinion flank point at arc length u [m]."""
        s = np.sqrt(2.0 * self.base_radius_pinion * np.asarray(u, dtype=float))
        return np.clip((s - self.contact_start) / self.path_of_contact_length, 0.0, 1.0)

    def rolling_speeds(self, xi, omega1: float) -> tuple[np.ndarray, np.ndarray]:
        """Speeds of the contact point over the pinion and gear flanks [m/s], (v1, v2) = (omega1 rho1, omega2 rho2)."""
        omega2 = omega1 * self.z1 / self.z2
        return omega1 * self.rho1(xi), omega2 * self.rho2(xi)

    def sliding_velocity(self, xi, omega1: float) -> np.ndarray:
        """Signed sliding velocity v1 - v2 [m/s]; negative before the pitch point (pinion dedendum,
        where the gear flank slides faster), positive after it.  Same shape as xi."""
        v1, v2 = self.rolling_speeds(xi, omega1)
        return v1 - v2

    def sliding_speed(self, xi, omega1: float) -> np.ndarray:
        """v_s = |omega1 rho1 - omega2 rho2| [m/s]; zero at the pitch point.  Same shape as xi."""
        return np.abs(self.sliding_velocity(xi, omega1))

    def slide_to_roll_ratio(self, xi) -> np.ndarray:
        """v_s / v1, dimensionless: sliding distance per unit distance the contact travels over the
        pinion flank.  Speed-independent.  Same shape as xi."""
        r1 = self.rho1(xi)
        return np.abs(r1 - self.rho2(xi) * self.z1 / self.z2) / r1

    # ---- Hertz line contact ----------------------------------------------------------------
    def hertz_half_width(self, force, xi) -> np.ndarray:
        """b = sqrt(4 w R / (pi E*)) [m] for a pair force ``force`` [N] at roll position ``xi``.

        ``force`` and ``xi`` broadcast; w = force / face_width.
        """
        w = _as_force(force) / self.face_width
        return np.sqrt(4.0 * w * self.equivalent_radius(xi) / (math.pi * self.contact_modulus))

    def hertz_max_pressure(self, force, xi) -> np.ndarray:
        """Pmax = 2 w / (pi b) = sqrt(w E* / (pi R)) [Pa]; 0 where the force is 0."""
        w = _as_force(force) / self.face_width
        # The closed form avoids 0/0 at zero load.
        return np.sqrt(w * self.contact_modulus / (math.pi * self.equivalent_radius(xi)))
