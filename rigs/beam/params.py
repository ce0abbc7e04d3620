"""Committed defaults of the beam rig, as frozen dataclasses (SI units throughout).

The numbers describe the 19/52 spur-gear test rig from its datasheet (module 3 mm, 20 deg,
mild steel, 20 mm face width), catalogue values of the parts a rig of this size is built
from (a 2 kW DC motor, jaw couplings, 6205/6206 ball bearings, a magnetic-particle brake, a
cast casing bolted to a bedplate) and textbook material data. None is fitted to a twin.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import numpy as np

VERSION = "beam rig v1, 2026-11-25"


@dataclass(frozen=True)
class Gears:
    z_pinion: int = 19
    z_gear: int = 52
    module: float = 3.0e-3            # m
    pressure_angle: float = np.deg2rad(20.0)
    face_width: float = 20.0e-3       # m
    addendum: float = 1.0             # x module
    dedendum: float = 1.25            # x module (basic rack ISO 53 A)
    root_fillet: float = 0.38         # rack tip radius, x module
    young: float = 206.0e9            # Pa, S45C
    poisson: float = 0.3
    density: float = 7850.0           # kg/m3
    tip_edge_break: float = 6.0e-6    # m, natural tip rounding depth (no designed relief)
    tip_edge_length: float = 0.35e-3  # m of path over which the edge break acts
    stiffness_factor: float = 1.0     # scales the tooth compliance (manufacturing scatter)
    pinion_bore: float = 25.0e-3
    gear_bore: float = 30.0e-3
    gear_web_factor: float = 0.82     # mass of the webbed gear blank / solid disk


@dataclass(frozen=True)
class Shafts:
    # Node stations [m] along each shaft; the same layout on both shafts:
    # coupling end, bearing in front wall, gear, bearing in back wall, free end (encoder)
    stations: tuple = (0.0, 0.035, 0.070, 0.105, 0.140, 0.175, 0.210, 0.250, 0.290)
    bearing_nodes: tuple = (2, 6)
    gear_node: int = 4
    pinion_diameters: tuple = (0.025, 0.025, 0.030, 0.030, 0.030, 0.030, 0.025, 0.022)
    gear_diameters: tuple = (0.030, 0.030, 0.035, 0.035, 0.035, 0.035, 0.030, 0.025)
    young: float = 206.0e9
    poisson: float = 0.3
    density: float = 7850.0
    bending_factor: float = 1.0       # effective EI of shoulders and fits
    # lumped parts at the shaft ends: (mass [kg], polar inertia [kg m2])
    pinion_coupling_half: tuple = (0.30, 2.0e-4)
    pinion_encoder_end: tuple = (0.22, 0.9e-4)
    gear_encoder_end: tuple = (0.22, 0.9e-4)
    gear_coupling_half: tuple = (0.40, 3.5e-4)
    coupling_radial: float = 2.0e6    # N/m, radial stiffness of a coupling to its machine


@dataclass(frozen=True)
class Drivetrain:
    motor_inertia: float = 0.0125     # kg m2, rotor + coupling half
    torque_meter_inertia: float = 6.0e-4
    brake_inertia: float = 0.045      # magnetic-particle brake rotor + coupling half
    coupling_motor: float = 2800.0    # N m/rad, motor - torque meter
    coupling_pinion: float = 1600.0   # N m/rad, torque meter - pinion shaft (jaw coupling)
    coupling_brake: float = 2200.0    # N m/rad, gear shaft - brake


@dataclass(frozen=True)
class Bearings:
    # deep-groove ball bearings: balls, ball diameter, pitch diameter, Hertz constant
    pinion_balls: int = 9
    pinion_ball_d: float = 7.94e-3
    pinion_pitch_d: float = 39.04e-3
    pinion_hertz: float = 7.5e9       # N/m^1.5 (ball between both races)
    gear_balls: int = 9
    gear_ball_d: float = 9.53e-3
    gear_pitch_d: float = 46.5e-3
    gear_hertz: float = 8.5e9
    min_load: float = 40.0            # N, wave-spring preload and shaft weight
    housing: float = 4.0e8            # N/m, housing boss and fit, in series
    transverse_ratio: float = 0.55    # stiffness across the load line / along it


@dataclass(frozen=True)
class Casing:
    mass: float = 26.0                # kg, cast box with oil
    size: tuple = (0.16, 0.275, 0.25)  # box x (axial), y, z [m]
    origin: tuple = (0.06, -0.075, -0.13)  # lowest corner in the shaft frame [m]
    mount_stiffness: tuple = (6.0e7, 6.0e7, 1.5e8)   # per foot x, y, z [N/m]
    mount_damping: float = 0.025
    # flexible panel / wall modes: (label, frequency [Hz], modal mass [kg], damping ratio)
    panels: tuple = (
        ("top cover (1,1)", 1180.0, 1.8, 0.014),
        ("gear-side wall (1,1)", 1640.0, 2.2, 0.012),
        ("end walls ovalising", 2380.0, 3.0, 0.010),
        ("top cover (2,1)", 2950.0, 1.6, 0.012),
        ("gear-side wall (2,1)", 3700.0, 2.0, 0.011),
        ("end walls shear", 4450.0, 3.5, 0.010),
    )
    # sensor points in the shaft frame and their axes (0 = x, 1 = y, 2 = z)
    pinion_sensor: tuple = (0.12, 0.0, 0.12)
    pinion_sensor_axis: int = 2
    gear_sensor: tuple = (0.155, 0.2, 0.0)
    gear_sensor_axis: int = 1


@dataclass(frozen=True)
class Damping:
    """Component loss figures, combined per mode by modal strain energy."""
    shaft: float = 0.006
    coupling: float = 0.05
    bearing: float = 0.035
    mesh_lubricated: float = 0.06
    mesh_dry: float = 0.03
    coupling_radial: float = 0.08


@dataclass(frozen=True)
class Drive:
    """DC motor with a current loop and a speed PI loop (a thyristor/chopper drive)."""
    resistance: float = 1.2           # ohm
    inductance: float = 12.0e-3       # H
    torque_constant: float = 1.3      # N m/A = V s/rad
    current_bandwidth: float = 300.0  # Hz
    speed_bandwidth: float = 6.0      # Hz
    current_limit: float = 30.0       # A
    voltage_limit: float = 260.0      # V
    commutator_segments: int = 24     # torque ripple locked to the motor shaft
    commutator_ripple: float = 0.004  # relative
    speed_sensor_error: float = 0.006  # s.d. of the drive's speed-feedback gain error (per box)
    speed_drift: float = 0.003        # s.d. of a record's speed offset on top


@dataclass(frozen=True)
class Brake:
    fluctuation: float = 0.02         # relative r.m.s. of the particle-brake torque
    fluctuation_band: float = 12.0    # Hz, its low-pass corner
    once_per_rev: float = 0.012       # relative, rotor air-gap eccentricity
    viscous: float = 0.002            # N m s/rad drag


@dataclass(frozen=True)
class Surfaces:
    """Micro-geometry of run-in flanks of ground test gears (about ISO 1328 grade 5)."""
    pitch_error: float = 0.6e-6       # r.m.s. single pitch deviation [m]
    form_error: float = 0.6e-6        # r.m.s. of the low-order profile form common to all teeth
    form_scatter: float = 0.15e-6     # r.m.s. of its tooth-to-tooth variation
    waviness: float = 0.2e-6          # r.m.s. waviness
    waviness_length: float = 0.7e-3   # correlation length [m]
    roughness: float = 0.4e-6         # Rq of one profile trace [m]
    roughness_length: float = 40.0e-6  # its correlation length along the profile
    roughness_face_length: float = 1.0e-3  # correlation length across the face: the contact
    #                                   line averages b / this many independent traces
    friction_lubricated: float = 0.05
    friction_dry: float = 0.32


@dataclass(frozen=True)
class Broadband:
    bearing_force: float = 0.015      # r.m.s. / static bearing load
    bearing_floor: float = 0.6        # N r.m.s. at any load
    casing_force: float = 0.8         # N r.m.s. process force (churning, splash) on the casing
    band: float = 18000.0             # Hz upper corner of both


@dataclass(frozen=True)
class Sensors:
    mount_frequency: float = 28000.0  # Hz, stud-mounted accelerometer
    mount_damping: float = 0.03
    highpass: float = 1.0             # Hz, IEPE coupling and conditioning (2 poles)
    noise: float = 0.004              # m/s2 r.m.s. over the band
    gain_error_box: float = 0.02      # s.d. of a sensor's calibration error (per box)
    gain_error_record: float = 0.03   # s.d. per record
    ranges: tuple = (20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0)  # +- m/s2
    bits: int = 16
    encoder_lines: int = 512
    encoder_line_error: float = 25e-6  # rad r.m.s. line placement error
    sample_rate: float = 50000.0
    internal_rate: float = 100000.0


@dataclass(frozen=True)
class Hammer:
    """The instrumented impact hammer of a hammer test (a test instrument, not the gearbox):
    a hard plastic tip on cast iron and steel, a quartz load cell on the IEPE input."""
    contact_time: tuple = (0.15e-3, 0.30e-3)   # s, range of a blow's contact time
    peak: tuple = (100.0, 300.0)                # N, range of a blow's peak force
    interval_shape: float = 5.0       # gamma shape of the interval between blows (a hand's rhythm)
    min_interval: float = 0.05        # s, no two blows closer (the hammer must come back up)
    noise: float = 0.03               # N r.m.s. load-cell and conditioning noise over the band
    gain_error: float = 0.015         # s.d. of the load cell's sensitivity error (per record)
    ranges: tuple = (50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0)  # +- N
    bits: int = 16


@dataclass(frozen=True)
class Numerics:
    mode_cutoff: float = 16000.0      # Hz, modes kept in the time integration
    settle: float = 0.3               # s simulated and dropped before a record
    path_samples: int = 512           # samples of a tooth's path of contact
    slices: int = 32                  # face-width slices of the loaded contact


@dataclass(frozen=True)
class Params:
    gears: Gears = field(default_factory=Gears)
    shafts: Shafts = field(default_factory=Shafts)
    drivetrain: Drivetrain = field(default_factory=Drivetrain)
    bearings: Bearings = field(default_factory=Bearings)
    casing: Casing = field(default_factory=Casing)
    damping: Damping = field(default_factory=Damping)
    drive: Drive = field(default_factory=Drive)
    brake: Brake = field(default_factory=Brake)
    surfaces: Surfaces = field(default_factory=Surfaces)
    broadband: Broadband = field(default_factory=Broadband)
    sensors: Sensors = field(default_factory=Sensors)
    numerics: Numerics = field(default_factory=Numerics)
    hammer: Hammer = field(default_factory=Hammer)


# Base parameters a gearbox-to-gearbox scatter acts on: (group, field).
SCATTERED = (
    ("gears", "stiffness_factor"),
    ("gears", "gear_web_factor"),
    ("shafts", "bending_factor"),
    ("drivetrain", "motor_inertia"),
    ("drivetrain", "torque_meter_inertia"),
    ("drivetrain", "brake_inertia"),
    ("drivetrain", "coupling_motor"),
    ("drivetrain", "coupling_pinion"),
    ("drivetrain", "coupling_brake"),
    ("bearings", "pinion_hertz"),
    ("bearings", "gear_hertz"),
    ("bearings", "housing"),
    ("casing", "mass"),
    ("casing", "mount_stiffness"),
    ("casing", "panels"),
    ("damping", "bearing"),
    ("damping", "mesh_lubricated"),
)


def scatter_params(params: Params, rng: np.random.Generator, scatter: float) -> tuple[Params, dict]:
    """Scale every base parameter in SCATTERED by its own factor uniform in [1-s, 1+s].

    Tuples of numbers are scaled element-wise with independent factors; the panel table
    scatters frequency and modal mass of each panel. Returns the new parameters and the
    factors applied (for the truth file).
    """
    factors: dict = {}
    groups = {f.name: getattr(params, f.name) for f in fields(params)}
    for group, name in SCATTERED:
        value = getattr(groups[group], name)
        key = f"{group}.{name}"
        if name == "panels":
            new, fac = [], []
            for label, freq, mass, zeta in value:
                a, b = rng.uniform(1 - scatter, 1 + scatter, 2)
                new.append((label, freq * a, mass * b, zeta))
                fac.append([float(a), float(b)])
            value, factors[key] = tuple(new), fac
        elif isinstance(value, tuple):
            f = rng.uniform(1 - scatter, 1 + scatter, len(value))
            value = tuple(float(v * x) for v, x in zip(value, f))
            factors[key] = [float(x) for x in f]
        else:
            f = float(rng.uniform(1 - scatter, 1 + scatter))
            value = type(value)(value * f)
            factors[key] = f
        groups[group] = replace(groups[group], **{name: value})
    return Params(**groups), factors
