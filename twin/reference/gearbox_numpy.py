"""Independent numpy implementation of the 21-DOF spur-gearbox model ``GearTwin.Gearbox21``.

The equations are transcribed by hand from the physics of ``modelica/GearTwin/Gearbox21.mo``
(no CasADi, no code shared with :mod:`fmu_build`), so the compiled FMU can be checked against a
second, separately written implementation.

Model summary
-------------
* Torsional chain (9 DOF, angles in rad): motor 1 - torque meter 2 - input coupling 3 -
  pinion 5 - slip ring 7 on the input side; slip ring 8 - gear 10 - output coupling 12 -
  brake 13 on the output side.  Gear-side angles count positive in the driven direction, so
  the rigid mesh reads ``rb1*theta5 = rb2*theta10``.
* Lateral (12 DOF, displacements in m): pedestals 4 and 6 and pinion 5 (input shaft),
  pedestals 9 and 11 and gear 10 (output shaft), each in x (horizontal) and y (vertical).
* Mesh: three tooth pairs (leading, current, next) with smooth entry/exit windows; pair
  stiffness interpolated with hat functions on ``k_pair`` along the path of contact, scaled
  per pinion tooth; each pair's flank deviation adds the offset of its pinion tooth and, in the
  variant ``GearTwin.Variants.Gearbox21WheelErrors``, of its gear tooth (both counted by the
  completed mesh cycles); a pair whose flank deviation exceeds the approach carries no load.

State vector (42,), in the declaration order of the Modelica model
-----------------------------------------------------------------
``theta1, theta2, theta3, theta5, theta7, theta10, theta8, theta12, theta13`` (note theta10
before theta8), ``omega1, omega2, omega3, omega5, omega7, omega8, omega10, omega12, omega13``
(note omega8 before omega10), ``x4, y4, x5, y5, x6, y6, x9, y9, x10, y10, x11, y11``, then the
matching velocities ``vx4, vy4, ..., vx11, vy11``.  :data:`STATE_NAMES` lists them.

Every function that takes a state accepts ``x`` of shape ``(42,)`` or ``(42, m)`` (``m``
states side by side, e.g. a whole stored trajectory) and returns arrays shaped accordingly.

This module is one file on purpose, above the project's usual module size: the pure-Python
reference FMU (:mod:`twin.reference.gearbox_pythonfmu`) ships it as a single resource and
imports it by file name inside the FMU, so it must stand alone (numpy only, no package imports).
"""
from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

# GearTwin.pi in package.mo is the double nearest to pi, i.e. math.pi.
PI = math.pi

STATE_NAMES: tuple[str, ...] = (
    "theta1", "theta2", "theta3", "theta5", "theta7", "theta10", "theta8", "theta12", "theta13",
    "omega1", "omega2", "omega3", "omega5", "omega7", "omega8", "omega10", "omega12", "omega13",
    "x4", "y4", "x5", "y5", "x6", "y6", "x9", "y9", "x10", "y10", "x11", "y11",
    "vx4", "vy4", "vx5", "vy5", "vx6", "vy6", "vx9", "vy9", "vx10", "vy10", "vx11", "vy11",
)
N_STATES = len(STATE_NAMES)
_I = {name: i for i, name in enumerate(STATE_NAMES)}

#: Generalised coordinates of :func:`mass_matrix_stiffness` (21,): the position part of the state.
DOF_NAMES: tuple[str, ...] = STATE_NAMES[:9] + STATE_NAMES[18:30]

#: Output names, identical to the ``output`` variables of the Modelica model.
OUTPUT_NAMES: tuple[str, ...] = (
    "mesh_force", "mesh_stiffness", "accel_pinion_casing", "accel_gear_casing",
    "encoder_pinion_angle", "encoder_gear_angle", "transmission_error", "motor_speed",
    "motor_torque",
)

#: Input defaults (the ``start`` values of the Modelica inputs).
DEFAULT_INPUTS: dict[str, float] = {
    "motor_speed_ref": 2 * PI * 20,   # rad/s
    "drive_torque": 0.0,              # N.m
    "load_torque": 20.0,              # N.m
}

_ARRAY_FIELDS = ("k_pair", "profile_deviation", "tooth_stiffness_factor", "tooth_deviation_offset",
                 "tooth_pit_field",
                 "wheel_tooth_deviation_offset", "effect_tooth_stiffness_factor", "effect_tooth_offset",
                 "effect_profile_deviation")
#: Structural Integer parameters of the model: FMU constants, never set as start values.
STRUCTURAL = ("z1", "z2", "n_profile")
#: Fields that only ``GearTwin.Variants.Gearbox21WheelErrors`` has as parameters (the base model
#: has them at zero, through its hook ``effect_pair_deviation``).
VARIANT_FIELDS = ("wheel_tooth_deviation_offset",)


@dataclass(frozen=True)
class GearboxParams:
    """Every parameter of ``GearTwin.Gearbox21``, same names, units and defaults.

    Array parameters are tuples of floats (``k_pair`` and ``profile_deviation`` have
    ``n_profile`` entries, ``tooth_stiffness_factor`` and ``tooth_deviation_offset`` have
    ``z1``, ``wheel_tooth_deviation_offset`` has ``z2``, and is the variant
    ``GearTwin.Variants.Gearbox21WheelErrors``'s); lists or numpy arrays passed in are converted.  The Modelica parameters with a binding to other parameters (``rb1``, ``rb2``, ``contact_ratio``, ``torque_out``,
    ``torque_in``, ``mesh_force_static``, ``speed_start``, ``k_mesh_mean``, ``pitch_curvature_pinion``,
    ``pitch_curvature_gear``, ``hertz_half_width``) are properties.
    The instance is hashable, which lets the per-parameter-set constants be cached.
    """

    # ---- gear geometry
    z1: int = 19                         # pinion teeth (structural)
    z2: int = 52                         # gear teeth (structural)
    module: float = 3.0e-3               # m, normal module
    alpha: float = 20 * PI / 180         # rad, pressure angle
    face_width: float = 0.020            # m
    addendum_coefficient: float = 1.0    # addendum / module
    # ---- mesh stiffness and profile
    n_profile: int = 11                  # nodes along the path of contact (structural)
    k_pair: tuple[float, ...] = (1.650e8, 2.136e8, 2.514e8, 2.784e8, 2.946e8, 3.000e8,
                                 2.946e8, 2.784e8, 2.514e8, 2.136e8, 1.650e8)   # N/m
    profile_deviation: tuple[float, ...] = (0.0,) * 11                          # m
    tooth_stiffness_factor: tuple[float, ...] = (1.0,) * 19                     # -
    tooth_deviation_offset: tuple[float, ...] = (0.0,) * 19                     # m
    tooth_pit_field: tuple[float, ...] = (0.0,) * (19 * 11)                     # m, tooth-major (z1 * n_profile)
    wheel_tooth_deviation_offset: tuple[float, ...] = (0.0,) * 52               # m, per gear tooth
    # parameter hooks of the effect catalogue (neutral here; they compose with the three above)
    effect_tooth_stiffness_factor: tuple[float, ...] = (1.0,) * 19              # -
    effect_tooth_offset: tuple[float, ...] = (0.0,) * 19                        # m
    effect_profile_deviation: tuple[float, ...] = (0.0,) * 11                   # m
    mesh_stiffness_scale: float = 1.0
    c_mesh: float = 1.1e3                # N.s/m, along the line of action
    contact_damping_width: float = 1e-8  # m, approach over which the mesh damping engages
    lead_mismatch: float = 0.0           # m, lead mismatch of the flanks across the face (misalignment)
    mesh_phase0: float = 0.0             # rad, mesh phase at theta5 = 0
    contact_smoothing: float = 0.01      # fraction of the path of contact
    # ---- inertias [kg.m2] and masses [kg]
    I1: float = 4.3e-3
    I2: float = 4.0e-4
    I3: float = 3.0e-4
    I5: float = 2.5e-4
    I7: float = 5.0e-4
    I8: float = 5.0e-4
    I10: float = 9.5e-3
    I12: float = 5.0e-4
    I13: float = 2.0e-2
    m4: float = 2.0
    m5: float = 0.6
    m6: float = 2.0
    m9: float = 2.0
    m10: float = 3.5
    m11: float = 2.0
    # ---- torsional stiffness [N.m/rad] and damping [N.m.s/rad]
    kt12: float = 1.5e3
    kt23: float = 2.0e3
    kt35: float = 1.5e4
    kt57: float = 1.5e4
    kt810: float = 2.0e4
    kt1012: float = 2.0e4
    kt1213: float = 1.5e3
    ct12: float = 0.10
    ct23: float = 0.10
    ct35: float = 0.08
    ct57: float = 0.08
    ct810: float = 0.10
    ct1012: float = 0.10
    ct1213: float = 0.10
    # ---- lateral stiffness [N/m] and damping [N.s/m]
    kx45: float = 1.0e8
    ky45: float = 1.0e8
    kx56: float = 1.0e8
    ky56: float = 1.0e8
    kx910: float = 1.5e8
    ky910: float = 1.5e8
    kx1011: float = 1.5e8
    ky1011: float = 1.5e8
    cx45: float = 400.0
    cy45: float = 400.0
    cx56: float = 400.0
    cy56: float = 400.0
    cx910: float = 500.0
    cy910: float = 500.0
    cx1011: float = 500.0
    cy1011: float = 500.0
    kx4: float = 3.0e7
    ky4: float = 5.0e7
    kx6: float = 3.0e7
    ky6: float = 5.0e7
    kx9: float = 3.0e7
    ky9: float = 5.0e7
    kx11: float = 3.0e7
    ky11: float = 5.0e7
    cx4: float = 400.0
    cy4: float = 400.0
    cx6: float = 400.0
    cy6: float = 400.0
    cx9: float = 400.0
    cy9: float = 400.0
    cx11: float = 400.0
    cy11: float = 400.0
    # ---- drive, load and sensors
    c_motor: float = 3.0                 # N.m.s/rad, torque-slip slope of the motor
    sensor_angle_pinion: float = 0.0     # rad, 0 = vertical, pi/2 = horizontal
    sensor_angle_gear: float = 0.0       # rad
    speed_ref_start: float = 2 * PI * 20  # rad/s, speed command assumed for the steady start
    load_start: float = 20.0             # N.m, brake torque of the static pre-load
    # ---- gear steel (the Hertzian width that ends the roughness band of the measured models)
    gear_youngs_modulus: float = 2.06e11  # Pa
    gear_poisson_ratio: float = 0.3      # -

    def __post_init__(self):
        for name in _ARRAY_FIELDS:
            value = tuple(float(v) for v in np.asarray(getattr(self, name), dtype=float).ravel())
            object.__setattr__(self, name, value)
        for name in ("k_pair", "profile_deviation", "effect_profile_deviation"):
            if len(getattr(self, name)) != self.n_profile:
                raise ValueError(f"{name} needs n_profile={self.n_profile} entries, "
                                 f"got {len(getattr(self, name))}")
        for name in ("tooth_stiffness_factor", "tooth_deviation_offset", "effect_tooth_stiffness_factor",
                     "effect_tooth_offset"):
            if len(getattr(self, name)) != self.z1:
                raise ValueError(f"{name} needs z1={self.z1} entries, got {len(getattr(self, name))}")
        if len(self.tooth_pit_field) != self.z1 * self.n_profile:
            raise ValueError(f"tooth_pit_field needs z1*n_profile={self.z1 * self.n_profile} entries, "
                             f"got {len(self.tooth_pit_field)}")
        if len(self.wheel_tooth_deviation_offset) != round(self.z2):
            raise ValueError(f"wheel_tooth_deviation_offset needs z2={self.z2} entries, "
                             f"got {len(self.wheel_tooth_deviation_offset)}")
        if self.n_profile < 2:
            raise ValueError("n_profile must be >= 2 (hat interpolation needs two nodes)")

    def replace(self, **changes) -> "GearboxParams":
        """Copy with some fields changed (``dataclasses.replace``)."""
        return dataclasses.replace(self, **changes)

    # ---- derived parameters (bindings of the Modelica model) -------------------------------
    @property
    def rb1(self) -> float:
        """Pinion base radius [m]."""
        return 0.5 * self.module * self.z1 * math.cos(self.alpha)

    @property
    def rb2(self) -> float:
        """Gear base radius [m]."""
        return 0.5 * self.module * self.z2 * math.cos(self.alpha)

    @property
    def contact_ratio(self) -> float:
        """Transverse contact ratio [-]: length of the path of contact / base pitch."""
        ra1 = 0.5 * self.module * self.z1 + self.addendum_coefficient * self.module
        ra2 = 0.5 * self.module * self.z2 + self.addendum_coefficient * self.module
        path = (math.sqrt(ra1 ** 2 - self.rb1 ** 2) + math.sqrt(ra2 ** 2 - self.rb2 ** 2)
                - 0.5 * self.module * (self.z1 + self.z2) * math.sin(self.alpha))
        return path / (PI * self.module * math.cos(self.alpha))

    @property
    def line_of_action_length(self) -> float:
        """Distance T1-T2 between the base-circle tangency points [m]."""
        return 0.5 * self.module * (self.z1 + self.z2) * math.sin(self.alpha)

    @property
    def contact_path_length(self) -> float:
        """Length of the path of contact [m]."""
        return self.contact_ratio * PI * self.module * math.cos(self.alpha)

    @property
    def contact_start_radius(self) -> float:
        """Distance from T1 to the start of contact [m] (gear tip circle on the line of action)."""
        ra2 = 0.5 * self.module * self.z2 + self.addendum_coefficient * self.module
        return self.line_of_action_length - math.sqrt(ra2 ** 2 - self.rb2 ** 2)

    @property
    def roll_pitch(self) -> float:
        """Roll position of the pitch point [-] (0 = start, 1 = end of contact)."""
        return (0.5 * self.module * self.z1 * math.sin(self.alpha) - self.contact_start_radius) / self.contact_path_length

    @property
    def torque_out(self) -> float:
        """Static torque in the output chain [N.m]."""
        return self.load_start

    @property
    def torque_in(self) -> float:
        """Static torque in the input chain [N.m]."""
        return self.load_start * self.rb1 / self.rb2

    @property
    def mesh_force_static(self) -> float:
        """Static mesh force [N]."""
        return self.torque_in / self.rb1

    @property
    def pitch_curvature_pinion(self) -> float:
        """Radius of curvature of the pinion flank at the pitch point [m]."""
        return 0.5 * self.module * self.z1 * math.sin(self.alpha)

    @property
    def pitch_curvature_gear(self) -> float:
        """Radius of curvature of the gear flank at the pitch point [m]."""
        return 0.5 * self.module * self.z2 * math.sin(self.alpha)

    @property
    def hertz_half_width(self) -> float:
        """Hertzian half-width [m] of the static mesh force on one pair at the pitch point (line contact, steel on steel)."""
        r1, r2 = self.pitch_curvature_pinion, self.pitch_curvature_gear
        line_load = max(self.mesh_force_static, 0.0) / self.face_width
        return math.sqrt(8 * line_load * (r1 * r2 / (r1 + r2)) * (1 - self.gear_poisson_ratio ** 2)
                         / (PI * self.gear_youngs_modulus))

    @property
    def speed_start(self) -> float:
        """Motor speed at t = 0 [rad/s]: steady slip under the static load."""
        return self.speed_ref_start - self.torque_in / self.c_motor

    @property
    def k_mesh_mean(self) -> float:
        """Approximate mean mesh stiffness [N/m] used for the static pre-load."""
        return self.mesh_stiffness_scale * self.contact_ratio * sum(self.k_pair) / self.n_profile

    def fmu_start_values(self, only_changed: bool = True, variant: bool = False) -> dict[str, float]:
        """Start values for the compiled FMU, keyed by its variable names (``k_pair[3]``, ...).

        ``z1``, ``z2`` and ``n_profile`` are structural constants of the FMU and never included.  With
        ``only_changed`` only the fields that differ from the defaults are returned.  The gear's
        tooth offsets (:data:`VARIANT_FIELDS`) are parameters of the variant only: they are
        included when they are not all zero, or when ``variant`` is true.
        """
        default = GearboxParams()
        out: dict[str, float] = {}
        for f in dataclasses.fields(self):
            if f.name in STRUCTURAL:
                continue
            value = getattr(self, f.name)
            unchanged = value == getattr(default, f.name)
            if unchanged and (only_changed or (f.name in VARIANT_FIELDS and not variant)):
                continue
            if f.name in _ARRAY_FIELDS:
                out.update({f"{f.name}[{i + 1}]": v for i, v in enumerate(value)})
            else:
                out[f.name] = float(value)
        return out


class _Constants:
    """Per-parameter-set constants of the right-hand side, computed once (see :func:`_constants`)."""

    def __init__(self, p: GearboxParams):
        self.p = p
        self.rb1 = p.rb1
        self.rb2 = p.rb2
        self.contact_ratio = p.contact_ratio
        self.sin_a = math.sin(p.alpha)
        self.cos_a = math.cos(p.alpha)
        self.k_pair = p.mesh_stiffness_scale * np.asarray(p.k_pair)          # (n_profile,)
        self.profile_deviation = np.asarray(p.profile_deviation) + np.asarray(p.effect_profile_deviation)
        self.node_index = np.arange(p.n_profile, dtype=float)                # (n_profile,)
        self.tooth_factor = np.asarray(p.tooth_stiffness_factor) * np.asarray(p.effect_tooth_stiffness_factor)
        self.tooth_offset = np.asarray(p.tooth_deviation_offset) + np.asarray(p.effect_tooth_offset)
        self.tooth_pit_field = np.asarray(p.tooth_pit_field).reshape(p.z1, p.n_profile)  # (z1, n_profile)
        tooth_node = 2 * PI * np.arange(p.z1) / p.z1
        self.tooth_node_cos = np.cos(tooth_node)                              # (z1,)
        self.tooth_node_sin = np.sin(tooth_node)                              # (z1,)
        # Squared chord of half a tooth spacing: the radius of the tooth-selection hat.
        self.inv_chord2 = 1.0 / math.sin(PI / p.z1) ** 2
        # Offsets of the leading / current / next pair: pinion-tooth angle [rad] and cycle, (3,).
        self.pair_tooth_shift = np.array([-2 * PI / p.z1, 0.0, 2 * PI / p.z1])
        self.pair_cycle_shift = np.array([1.0, 0.0, -1.0])
        # The same for the gear's teeth, counted by the same mesh cycles.
        self.wheel_offset = np.asarray(p.wheel_tooth_deviation_offset)           # (z2,)
        self.wheel_teeth = self.wheel_offset.size
        wheel_node = 2 * PI * np.arange(self.wheel_teeth) / self.wheel_teeth
        self.wheel_node_cos, self.wheel_node_sin = np.cos(wheel_node), np.sin(wheel_node)
        self.wheel_inv_chord2 = 1.0 / math.sin(PI / self.wheel_teeth) ** 2
        self.pair_wheel_shift = np.array([-2 * PI, 0.0, 2 * PI]) / self.wheel_teeth
        self.cs_sensor_p = (math.cos(p.sensor_angle_pinion), math.sin(p.sensor_angle_pinion))
        self.cs_sensor_g = (math.cos(p.sensor_angle_gear), math.sin(p.sensor_angle_gear))


@functools.lru_cache(maxsize=32)
def _constants(p: GearboxParams) -> _Constants:
    return _Constants(p)


def _inputs(inputs: Mapping[str, float] | None) -> tuple[float, float, float]:
    u = dict(DEFAULT_INPUTS)
    if inputs:
        unknown = set(inputs) - set(u)
        if unknown:
            raise KeyError(f"unknown inputs {sorted(unknown)}; expected {sorted(u)}")
        u.update(inputs)
    return float(u["motor_speed_ref"]), float(u["drive_torque"]), float(u["load_torque"])


def initial_state(params: GearboxParams) -> np.ndarray:
    """Start state (42,) of the Modelica model: static pre-load at steady speed, lateral at rest.

    The shafts are wound up by the static torques (``torque_in`` on the input side,
    ``torque_out`` on the output side) and the mesh is compressed by
    ``mesh_force_static / k_mesh_mean``; all inertias spin at ``speed_start`` (gear side
    scaled by ``rb1/rb2``).
    """
    p = params
    ti, to = p.torque_in, p.torque_out
    th1 = 0.0
    th2 = -ti / p.kt12
    th3 = th2 - ti / p.kt23
    th5 = th3 - ti / p.kt35
    th7 = th5
    th10 = (p.rb1 * th5 - p.mesh_force_static / p.k_mesh_mean) / p.rb2
    th8 = th10
    th12 = th10 - to / p.kt1012
    th13 = th12 - to / p.kt1213
    w_in = p.speed_start
    w_out = p.speed_start * p.rb1 / p.rb2
    x = np.zeros(N_STATES)
    x[:9] = [th1, th2, th3, th5, th7, th10, th8, th12, th13]
    x[9:18] = [w_in] * 5 + [w_out] * 4
    return x


def _clip01(v):
    return np.minimum(1.0, np.maximum(0.0, v))


def _smoothstep(u):
    return u * u * (3.0 - 2.0 * u)


def _tooth_select(angle, node_cos, node_sin, inv_chord2) -> np.ndarray:
    """(..., teeth) weights of the teeth in contact: a hat of radius half a chord around each
    tooth's position on the unit circle, 1 at the tooth whose angle ``angle`` [rad] is, 0 elsewhere."""
    chord2 = (np.cos(angle)[..., None] - node_cos) ** 2 + (np.sin(angle)[..., None] - node_sin) ** 2
    return np.maximum(0.0, 1.0 - chord2 * inv_chord2)


def _mesh(c: _Constants, x: np.ndarray) -> dict[str, np.ndarray]:
    """Mesh quantities for states ``x`` (42, ...): forces [N], stiffnesses [N/m], deflections [m].

    Per-pair arrays have a leading axis of length 3 (leading, current, next pair).
    """
    p = c.p
    theta5, theta10 = x[_I["theta5"]], x[_I["theta10"]]
    omega5, omega10 = x[_I["omega5"]], x[_I["omega10"]]
    mesh_angle = p.z1 * theta5 + p.mesh_phase0
    # Position in the mesh cycle in (0, 1]: the phase wrapped without events.
    cycle = np.arctan2(np.sin(mesh_angle - PI), np.cos(mesh_angle - PI)) / (2 * PI) + 0.5
    # Angle of the pinion tooth that entered contact last: an exact multiple of 2*pi/z1.
    tooth_angle = (mesh_angle - 2 * PI * cycle) / p.z1
    extra = (slice(None),) + (None,) * np.ndim(cycle)
    roll = (cycle + c.pair_cycle_shift[extra]) / c.contact_ratio               # (3, ...)
    s = p.contact_smoothing
    window = (_smoothstep(_clip01((roll + s) / (2 * s)))
              * _smoothstep(_clip01((1.0 - roll + s) / (2 * s))))            # (3, ...)
    # Hat-function interpolation on the n_profile nodes (node n sits at roll n/(n_profile-1)).
    pos = _clip01(roll) * (p.n_profile - 1)
    hat = np.maximum(0.0, 1.0 - np.abs(pos[..., None] - c.node_index))        # (3, ..., n)
    k_profile = hat @ c.k_pair
    dev_profile = hat @ c.profile_deviation
    select = _tooth_select(tooth_angle + c.pair_tooth_shift[extra], c.tooth_node_cos, c.tooth_node_sin,
                           c.inv_chord2)                                      # (3, ..., z1)
    pair_stiffness = window * k_profile * (select @ c.tooth_factor)
    pair_deviation = dev_profile + select @ c.tooth_offset
    if c.tooth_pit_field.any():
        # each pair reads the field of the tooth it holds, interpolated along the roll
        pair_deviation = pair_deviation + np.einsum("...j,jn,...n->...", select, c.tooth_pit_field, hat)
    if c.wheel_offset.any():
        # The variant's gear tooth of each pair: the same completed mesh cycles, on z2 teeth.
        wheel_ang = (mesh_angle - 2 * PI * cycle) / c.wheel_teeth + c.pair_wheel_shift[extra]
        pair_deviation = pair_deviation + _tooth_select(wheel_ang, c.wheel_node_cos, c.wheel_node_sin,
                                                        c.wheel_inv_chord2) @ c.wheel_offset
    # Approach of the flanks along the line of action: torsional plus the lateral projection.
    deflection = (c.rb1 * theta5 - c.rb2 * theta10
                  + (x[_I["x5"]] - x[_I["x10"]]) * c.sin_a + (x[_I["y5"]] - x[_I["y10"]]) * c.cos_a)
    deflection_rate = (c.rb1 * omega5 - c.rb2 * omega10
                       + (x[_I["vx5"]] - x[_I["vx10"]]) * c.sin_a
                       + (x[_I["vy5"]] - x[_I["vy10"]]) * c.cos_a)
    # A pair whose flanks are apart (deviation larger than the approach) carries no load. With
    # leads that differ by D across the face, a pair touches first at one face end: k a^2 / (2 D)
    # while the length a/D of the face touches, k (a - D/2) once all of it does.
    gap = deflection - pair_deviation
    mismatch = abs(p.lead_mismatch)
    if mismatch > 0:
        pair_force = pair_stiffness * (np.clip(gap, 0.0, mismatch) ** 2 / (2 * mismatch)
                                       + np.maximum(gap - mismatch, 0.0))
    else:
        pair_force = pair_stiffness * np.maximum(0.0, gap)
    # The flanks damp each other only while they touch; apart, the gears fly across the clearance.
    contact = np.minimum(1.0, (window * _clip01((deflection - pair_deviation) / p.contact_damping_width)).sum(axis=0))
    force = pair_force.sum(axis=0) + contact * p.c_mesh * deflection_rate
    return {
        "cycle_fraction": cycle, "roll": roll, "window": window, "pair_stiffness": pair_stiffness,
        "pair_deviation": pair_deviation, "pair_force": pair_force, "mesh_deflection": deflection,
        "mesh_deflection_rate": deflection_rate, "mesh_force": force, "mesh_contact": contact,
        "mesh_stiffness": pair_stiffness.sum(axis=0),
    }


def _derivatives(c: _Constants, x: np.ndarray, u: tuple[float, float, float]):
    """State derivative (42, ...) plus the mesh dict and the motor torque [N.m]."""
    p = c.p
    speed_ref, drive_torque, load_torque = u
    (th1, th2, th3, th5, th7, th10, th8, th12, th13,
     w1, w2, w3, w5, w7, w8, w10, w12, w13,
     x4, y4, x5, y5, x6, y6, x9, y9, x10, y10, x11, y11,
     vx4, vy4, vx5, vy5, vx6, vy6, vx9, vy9, vx10, vy10, vx11, vy11) = x.tolist() if x.ndim == 1 else x
    mesh = _mesh(c, x)
    # Python floats for a single state: scalar arithmetic on them is several times faster
    # than on numpy scalars, and this function dominates every simulation.
    F = float(mesh["mesh_force"]) if x.ndim == 1 else mesh["mesh_force"]
    motor_torque = drive_torque + p.c_motor * (speed_ref - w1)

    # Shaft torques, positive when they accelerate the downstream inertia.
    t12 = p.kt12 * (th1 - th2) + p.ct12 * (w1 - w2)
    t23 = p.kt23 * (th2 - th3) + p.ct23 * (w2 - w3)
    t35 = p.kt35 * (th3 - th5) + p.ct35 * (w3 - w5)
    t57 = p.kt57 * (th5 - th7) + p.ct57 * (w5 - w7)
    t810 = p.kt810 * (th10 - th8) + p.ct810 * (w10 - w8)        # slip ring 8 hangs off the gear
    t1012 = p.kt1012 * (th10 - th12) + p.ct1012 * (w10 - w12)
    t1213 = p.kt1213 * (th12 - th13) + p.ct1213 * (w12 - w13)

    # The mesh force pushes the pinion back (-rb1*F) and drives the gear (+rb2*F).
    dw1 = (motor_torque - t12) / p.I1
    dw2 = (t12 - t23) / p.I2
    dw3 = (t23 - t35) / p.I3
    dw5 = (t35 - t57 - c.rb1 * F) / p.I5
    dw7 = t57 / p.I7
    dw8 = t810 / p.I8
    dw10 = (c.rb2 * F - t810 - t1012) / p.I10
    dw12 = (t1012 - t1213) / p.I12
    dw13 = (t1213 - load_torque) / p.I13

    # Lateral: pedestals on ground springs, shaft springs between pedestal and gear body; the
    # line of action pushes the pinion along -(sin a, cos a) and the gear along +(sin a, cos a).
    fx45 = p.kx45 * (x5 - x4) + p.cx45 * (vx5 - vx4)
    fy45 = p.ky45 * (y5 - y4) + p.cy45 * (vy5 - vy4)
    fx56 = p.kx56 * (x5 - x6) + p.cx56 * (vx5 - vx6)
    fy56 = p.ky56 * (y5 - y6) + p.cy56 * (vy5 - vy6)
    fx910 = p.kx910 * (x10 - x9) + p.cx910 * (vx10 - vx9)
    fy910 = p.ky910 * (y10 - y9) + p.cy910 * (vy10 - vy9)
    fx1011 = p.kx1011 * (x10 - x11) + p.cx1011 * (vx10 - vx11)
    fy1011 = p.ky1011 * (y10 - y11) + p.cy1011 * (vy10 - vy11)
    ax4 = (-p.kx4 * x4 - p.cx4 * vx4 + fx45) / p.m4
    ay4 = (-p.ky4 * y4 - p.cy4 * vy4 + fy45) / p.m4
    ax5 = (-fx45 - fx56 - F * c.sin_a) / p.m5
    ay5 = (-fy45 - fy56 - F * c.cos_a) / p.m5
    ax6 = (-p.kx6 * x6 - p.cx6 * vx6 + fx56) / p.m6
    ay6 = (-p.ky6 * y6 - p.cy6 * vy6 + fy56) / p.m6
    ax9 = (-p.kx9 * x9 - p.cx9 * vx9 + fx910) / p.m9
    ay9 = (-p.ky9 * y9 - p.cy9 * vy9 + fy910) / p.m9
    ax10 = (-fx910 - fx1011 + F * c.sin_a) / p.m10
    ay10 = (-fy910 - fy1011 + F * c.cos_a) / p.m10
    ax11 = (-p.kx11 * x11 - p.cx11 * vx11 + fx1011) / p.m11
    ay11 = (-p.ky11 * y11 - p.cy11 * vy11 + fy1011) / p.m11

    xdot = np.array([w1, w2, w3, w5, w7, w10, w8, w12, w13,   # der(theta10) = omega10 comes before der(theta8)
                     dw1, dw2, dw3, dw5, dw7, dw8, dw10, dw12, dw13,
                     vx4, vy4, vx5, vy5, vx6, vy6, vx9, vy9, vx10, vy10, vx11, vy11,
                     ax4, ay4, ax5, ay5, ax6, ay6, ax9, ay9, ax10, ay10, ax11, ay11])
    return xdot, mesh, motor_torque


def rhs(t: float, x: np.ndarray, params: GearboxParams,
        inputs: Mapping[str, float] | None = None) -> np.ndarray:
    """Time derivative of the state.

    Parameters
    ----------
    t : time [s] (the model is autonomous; kept for solver signatures).
    x : state, shape (42,) or (42, m), order of :data:`STATE_NAMES`.
    params : parameter set.
    inputs : ``motor_speed_ref`` [rad/s], ``drive_torque`` [N.m], ``load_torque`` [N.m];
        missing entries take :data:`DEFAULT_INPUTS`.

    Returns
    -------
    xdot : same shape as ``x``.
    """
    return _derivatives(_constants(params), np.asarray(x, dtype=float), _inputs(inputs))[0]


def outputs(t: float, x: np.ndarray, params: GearboxParams,
            inputs: Mapping[str, float] | None = None, *, internals: bool = False) -> dict[str, np.ndarray]:
    """Model outputs for state ``x`` (42,) or (42, m), same names as the Modelica outputs.

    Units: ``mesh_force`` N, ``mesh_stiffness`` N/m, ``accel_*_casing`` m/s2 (pedestal 6
    resp. 9 acceleration projected on the sensor axis), encoder angles rad,
    ``transmission_error`` m, ``motor_speed`` rad/s, ``motor_torque`` N.m.  Each value is a
    float array of shape ``()`` or ``(m,)``.  With ``internals`` the mesh intermediates
    (``roll``, ``window``, ``pair_stiffness``, ``pair_force``, ``mesh_deflection``, ...) are
    added.
    """
    c = _constants(params)
    x = np.asarray(x, dtype=float)
    xdot, mesh, motor_torque = _derivatives(c, x, _inputs(inputs))
    shape = np.shape(mesh["mesh_force"])
    out = {
        "mesh_force": mesh["mesh_force"],
        "mesh_stiffness": mesh["mesh_stiffness"],
        "accel_pinion_casing": c.cs_sensor_p[0] * xdot[_I["vy6"]] + c.cs_sensor_p[1] * xdot[_I["vx6"]],
        "accel_gear_casing": c.cs_sensor_g[0] * xdot[_I["vy9"]] + c.cs_sensor_g[1] * xdot[_I["vx9"]],
        "encoder_pinion_angle": x[_I["theta7"]],
        "encoder_gear_angle": x[_I["theta8"]],
        "transmission_error": c.rb1 * x[_I["theta5"]] - c.rb2 * x[_I["theta10"]],
        "motor_speed": x[_I["omega1"]],
        "motor_torque": np.broadcast_to(motor_torque, shape),
    }
    out = {k: np.array(v, dtype=float) for k, v in out.items()}
    if internals:
        out.update({k: np.array(v) for k, v in mesh.items() if k not in out})
    return out


def rk4_advance(x: np.ndarray, span: float, params: GearboxParams,
                inputs: Mapping[str, float] | None = None, step: float = 5e-6) -> np.ndarray:
    """Advance the state by ``span`` [s] with classical RK4 in equal sub-steps no longer than ``step``.

    The partition ``n = ceil(span/step - 1e-9)`` equal sub-steps is the one of the compiled
    FMU's co-simulation ``doStep``, so both integrate the same discrete map.  Inputs are held
    constant over the span.  Returns the new state (42,) or (42, m).
    """
    if not step > 0:
        raise ValueError(f"step must be > 0 s, got {step!r}")
    c = _constants(params)
    u = _inputs(inputs)
    x = np.array(x, dtype=float)
    if span <= 0:
        return x
    n = max(1, math.ceil(span / step - 1e-9))
    h = span / n
    for _ in range(n):
        k1 = _derivatives(c, x, u)[0]
        k2 = _derivatives(c, x + 0.5 * h * k1, u)[0]
        k3 = _derivatives(c, x + 0.5 * h * k2, u)[0]
        k4 = _derivatives(c, x + h * k3, u)[0]
        x = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return x


def _output_grid(stop_time: float, output_interval: float) -> np.ndarray:
    if not output_interval > 0:
        raise ValueError(f"output_interval must be > 0 s, got {output_interval!r}")
    if not stop_time > 0:
        raise ValueError(f"stop_time must be > 0 s, got {stop_time!r}")
    n = int(round(stop_time / output_interval))
    if abs(n * output_interval - stop_time) > 1e-9 * stop_time:
        raise ValueError(f"stop_time {stop_time} s is not a multiple of output_interval {output_interval} s")
    return np.arange(n + 1) * output_interval


def simulate_rk4(params: GearboxParams | None = None, inputs: Mapping[str, float] | None = None,
                 stop_time: float = 0.02, step: float = 5e-6, output_interval: float = 1e-5,
                 *, x0: np.ndarray | None = None,
                 return_states: bool = False):
    """Fixed-step RK4 simulation from ``initial_state`` (or ``x0``) with constant inputs.

    Parameters
    ----------
    stop_time : end time [s], a multiple of ``output_interval``.
    step : largest RK4 step [s]; each output interval is split into equal sub-steps.
    output_interval : spacing of the stored samples [s].
    x0 : optional start state (42,).
    return_states : also return the states, shape (42, n_samples).

    Returns
    -------
    t : (n_samples,) sample times [s], ``0, output_interval, ..., stop_time``.
    out : dict of output name -> (n_samples,) array (see :func:`outputs`).
    states : only with ``return_states``.
    """
    params = params if params is not None else GearboxParams()
    t = _output_grid(stop_time, output_interval)
    x = initial_state(params) if x0 is None else np.array(x0, dtype=float)
    states = np.empty((N_STATES, t.size))
    states[:, 0] = x
    for k in range(1, t.size):
        x = rk4_advance(x, output_interval, params, inputs, step)
        states[:, k] = x
    out = outputs(t, states, params, inputs)
    return (t, out, states) if return_states else (t, out)


def default_atol() -> np.ndarray:
    """Absolute tolerances (42,) for adaptive solvers, scaled per state kind.

    Angles 1e-10 rad, angular speeds 1e-7 rad/s, displacements 1e-14 m, velocities 1e-10 m/s:
    well below the mesh deflection (~1e-6 m) and its rate so the mesh force is resolved.
    """
    return np.concatenate([np.full(9, 1e-10), np.full(9, 1e-7), np.full(12, 1e-14), np.full(12, 1e-10)])


def simulate_solve_ivp(params: GearboxParams | None = None, inputs: Mapping[str, float] | None = None,
                       stop_time: float = 0.02, output_interval: float = 1e-5,
                       rtol: float = 1e-8, atol: float | np.ndarray | None = None,
                       method: str = "DOP853", *, x0: np.ndarray | None = None):
    """Simulation with :func:`scipy.integrate.solve_ivp` (adaptive step), the plain-Python route.

    ``atol`` defaults to :func:`default_atol`.  Returns ``(t, out)`` like :func:`simulate_rk4`,
    the samples being taken from the solver's dense output at ``t``.
    """
    from scipy.integrate import solve_ivp

    params = params if params is not None else GearboxParams()
    t = _output_grid(stop_time, output_interval)
    c = _constants(params)
    u = _inputs(inputs)
    x_start = initial_state(params) if x0 is None else np.array(x0, dtype=float)
    sol = solve_ivp(lambda _t, y: _derivatives(c, y, u)[0], (0.0, float(t[-1])), x_start,
                    method=method, t_eval=t, rtol=rtol, atol=default_atol() if atol is None else atol)
    if not sol.success:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return t, outputs(t, sol.y, params, inputs)


def mass_matrix_stiffness(params: GearboxParams, theta5: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Linearised model ``M q'' + C q' + K q = f`` about a mesh position.

    The generalised coordinates ``q`` (21,) are :data:`DOF_NAMES` (the position part of the
    state, theta10 before theta8).  The mesh is a spring-damper along the line of action,
    ``delta = g . q`` with ``g = rb1 e_theta5 - rb2 e_theta10 + sin(a) (e_x5 - e_x10) +
    cos(a) (e_y5 - e_y10)``, with the stiffness frozen at the mesh stiffness of the pinion
    angle ``theta5`` [rad] (all pairs in contact carry load, i.e. the mesh is pre-loaded
    beyond any profile deviation).  The motor's speed regulator ``c_motor`` is a damper to
    ground and so only appears in ``C``.

    Returns
    -------
    M : (21, 21) diagonal mass matrix (kg.m2 on angles, kg on displacements).
    K : (21, 21) symmetric stiffness matrix, SI units consistent with q in rad and m.
    C : (21, 21) symmetric damping matrix, likewise.
    """
    p = params
    c = _constants(p)
    n = len(DOF_NAMES)
    idx = {name: i for i, name in enumerate(DOF_NAMES)}
    M = np.diag([getattr(p, "I" + name[5:]) if name.startswith("theta") else getattr(p, "m" + name[1:])
                 for name in DOF_NAMES])
    K = np.zeros((n, n))
    C = np.zeros((n, n))

    def between(a: str, b: str | None, k: float, d: float):
        # A spring-damper between coordinates a and b (b=None: to ground).
        v = np.zeros(n)
        v[idx[a]] = 1.0
        if b is not None:
            v[idx[b]] = -1.0
        K[:] += k * np.outer(v, v)
        C[:] += d * np.outer(v, v)

    for a, b, k, d in [("theta1", "theta2", p.kt12, p.ct12), ("theta2", "theta3", p.kt23, p.ct23),
                       ("theta3", "theta5", p.kt35, p.ct35), ("theta5", "theta7", p.kt57, p.ct57),
                       ("theta10", "theta8", p.kt810, p.ct810), ("theta10", "theta12", p.kt1012, p.ct1012),
                       ("theta12", "theta13", p.kt1213, p.ct1213)]:
        between(a, b, k, d)
    C[idx["theta1"], idx["theta1"]] += p.c_motor
    for ax in ("x", "y"):
        for a, b in [("4", "5"), ("5", "6"), ("9", "10"), ("10", "11")]:
            between(ax + a, ax + b, getattr(p, f"k{ax}{a}{b}"), getattr(p, f"c{ax}{a}{b}"))
        for a in ("4", "6", "9", "11"):
            between(ax + a, None, getattr(p, f"k{ax}{a}"), getattr(p, f"c{ax}{a}"))
    g = np.zeros(n)
    g[idx["theta5"]] = c.rb1
    g[idx["theta10"]] = -c.rb2
    g[idx["x5"]], g[idx["x10"]] = c.sin_a, -c.sin_a
    g[idx["y5"]], g[idx["y10"]] = c.cos_a, -c.cos_a
    x = np.zeros(N_STATES)
    x[_I["theta5"]] = theta5
    k_mesh = float(_mesh(c, x)["mesh_stiffness"])
    K += k_mesh * np.outer(g, g)
    C += p.c_mesh * np.outer(g, g)
    return M, K, C


def natural_frequencies(params: GearboxParams, n: int = 8, theta5: float = 0.0) -> np.ndarray:
    """Lowest ``n`` undamped natural frequencies [Hz] of the linearised model, shape (n,).

    Eigenvalues of ``M^-1 K`` (from :func:`mass_matrix_stiffness` at ``theta5``), sorted.  The
    torsional chain is free-free apart from the motor's damper, so ``K`` has exactly one zero
    eigenvalue (rigid rotation of the whole chain through the mesh); it is dropped.
    """
    from scipy.linalg import eigh

    M, K, _ = mass_matrix_stiffness(params, theta5)
    lam = eigh(K, M, eigvals_only=True)       # ascending; M is diagonal positive definite
    if abs(lam[0]) > 1e-6 * lam[1]:
        raise ArithmeticError(f"expected one rigid-body mode, smallest eigenvalues are {lam[:2]}")
    return np.sqrt(np.maximum(lam[1:n + 1], 0.0)) / (2 * PI)
