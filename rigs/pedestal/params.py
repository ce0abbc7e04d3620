"""Parameters of the pedestal rig: frozen dataclasses holding the committed defaults.

Values are engineering estimates for the UNSW-type rig (a ~3 kW four-pole motor on a VFD, jaw
couplings and an in-line torque meter, KHK-type S45C modular gears, 62xx bearings in pedestal
housings bolted into a fabricated casing on rubber isolators, a magnetic-particle brake). Each
field carries its unit. ``SCATTERED`` lists the fields that ``Rig.scattered`` perturbs.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Drivetrain:
    """Torsional chain: motor, coupling, torque meter, coupling, pinion | gear, coupling, brake."""

    motor_inertia: float = 0.0125          # [kg m2] rotor + fan
    meter_inertia: float = 1.6e-3          # [kg m2] torque-meter flanges + coupling hubs
    pinion_inertia: float = 4.5e-4         # [kg m2] pinion + shaft + coupling hub
    gear_inertia: float = 8.5e-3           # [kg m2] gear + shaft + coupling hub
    brake_inertia: float = 0.018           # [kg m2] particle-brake rotor
    motor_meter_stiffness: float = 3.3e3   # [N m/rad] jaw coupling + half the meter shaft
    meter_pinion_stiffness: float = 5.5e3  # [N m/rad] half meter shaft + coupling + pinion shaft
    gear_brake_stiffness: float = 4.2e3    # [N m/rad] gear shaft and brake coupling
    coupling_damping_ratio: float = 0.08   # [-] elastomer spiders
    speed_bandwidth: float = 4.0           # [Hz] closed-loop speed bandwidth of the VFD loop
    speed_loop_damping: float = 0.8        # [-] design damping of the PI speed loop
    torque_lag: float = 1.5e-3             # [s] current-loop (torque) time constant
    torque_limit: float = 45.0             # [N m] drive torque limit
    brake_fluctuation: float = 0.015       # [-] RMS of the brake's own torque fluctuation (< 40 Hz)
    brake_ripple: float = 0.006            # [-] once-per-brake-rev torque ripple (rotor run-out)
    process_noise: float = 0.004           # [-] RMS torque noise / pinion torque, 20 Hz - 8 kHz


@dataclass(frozen=True)
class Structure:
    """Lateral dynamics in the gear plane (x along the centre line, y up), casing on isolators."""

    pinion_mass: float = 1.3               # [kg] pinion + share of shaft
    gear_mass: float = 3.8                 # [kg]
    pinion_pedestal_mass: float = 1.6      # [kg] bearing outer rings + pedestal housings
    gear_pedestal_mass: float = 2.4        # [kg]
    pinion_support_stiffness: float = 1.2e8  # [N/m] shaft bending in series with both bearings
    gear_support_stiffness: float = 2.0e8    # [N/m]
    pinion_pedestal_stiffness: float = 4.0e8  # [N/m] pedestal into the casing wall (y; x: 0.8x)
    gear_pedestal_stiffness: float = 6.0e8    # [N/m]
    support_damping_ratio: float = 0.03    # [-] bearings and shafts
    pedestal_damping_ratio: float = 0.02   # [-] bolted joints
    casing_mass: float = 28.0              # [kg]
    casing_inertia: float = 0.45           # [kg m2] about the shaft axis direction
    isolator_stiffness_y: float = 4.0e5    # [N/m] per mount (two mounts in the plane)
    isolator_stiffness_x: float = 2.5e5    # [N/m] per mount
    isolator_damping_ratio: float = 0.06   # [-] rubber
    isolator_half_span: float = 0.16       # [m] mounts at x = +-span, y = -isolator_depth
    isolator_depth: float = 0.12           # [m]
    shaft_height: float = 0.03             # [m] shaft axes above the casing centre of mass
    panel_frequencies: tuple = (690.0, 1580.0, 2480.0, 4350.0, 6150.0)  # [Hz] wall/top plates
    panel_damping: tuple = (0.015, 0.012, 0.012, 0.015, 0.018)         # [-]
    # Mass-normalised panel mode shapes [m/sqrt(kg)] at (pinion pedestal x, y, gear pedestal
    # x, y, pinion sensor, gear sensor) along the listed directions.
    panel_shapes: tuple = ((0.15, 0.05, -0.12, 0.04, 0.25, 0.18),
                           (0.03, 0.20, 0.02, -0.18, 0.35, -0.30),
                           (0.10, -0.10, 0.12, 0.10, -0.20, 0.30),
                           (-0.08, 0.12, 0.10, 0.06, 0.30, 0.22),
                           (0.06, 0.09, -0.07, 0.11, -0.28, 0.34))
    sensor_positions: tuple = ((-0.055, 0.10), (0.065, 0.10))  # [m] pinion-side, gear-side
    sensor_directions: tuple = ((0.0, 1.0), (0.0, 1.0))        # unit vectors (both vertical)
    mount_frequencies: tuple = (7600.0, 9300.0)  # [Hz] accelerometer-on-bracket resonance
    mount_damping: tuple = (0.04, 0.05)          # [-]


@dataclass(frozen=True)
class Flanks:
    """Manufacturing deviations (ISO 1328-1:2013 flank tolerance classes) and surface texture."""

    iso_class: int = 7                     # flank tolerance class of both gears
    deviation_fraction: float = 0.10       # actual deviations: std = fraction * tolerance
    tooth_to_tooth: float = 0.3            # tooth-specific share of the profile deviations
    roughness_rms: float = 0.08e-6         # [m] face-width-averaged roughness along the profile
    roughness_correlation: float = 0.15e-3  # [m] correlation length along the profile
    tip_relief: float = 12e-6              # [m] edge break of the tips, at the tip
    tip_roll: float = 1.0e-3               # [m] of path over which the edge break fades out
    eccentricity: float = 4.0e-6           # [m] healthy run-out of each gear (assembly)
    backlash: float = 1.0e-4               # [m] normal backlash
    face_mismatch: float = 4.0e-6          # [m] assembled lead mismatch across the face (F_beta)
    wobble_ratio: float = 0.4              # lead wobble across the face / radial run-out
    mesh_damping_ratio: float = 0.06       # [-] of the gear-pair torsional mode
    friction_lubricated: float = 0.05      # [-] oil bath
    friction_dry: float = 0.25             # [-] dry test


@dataclass(frozen=True)
class Acquisition:
    """Sensors, conditioning and the ADC."""

    sample_rate: float = 50_000.0          # [Hz] output
    oversampling: int = 4                  # integration steps per output sample
    antialias_order: int = 8               # Butterworth poles
    antialias_cutoff: float = 0.40         # fraction of the output rate (20 kHz at 50 kHz)
    sensor_noise: float = 0.02             # [m/s2] RMS broadband electronic noise per channel
    gain_error: float = 0.03               # [-] std of the per-record gain error
    encoder_lines: int = 512               # quadrature-decoded: 4 counts per line
    speed_jitter: float = 0.003            # [-] std of the per-record true-speed error
    preroll: float = 0.3                   # [s] simulated before the record starts


#: Fields scattered by ``Rig.scattered`` (section, field name).
SCATTERED = tuple(
    [("drivetrain", n) for n in ("motor_inertia", "meter_inertia", "pinion_inertia",
                                 "gear_inertia", "brake_inertia", "motor_meter_stiffness",
                                 "meter_pinion_stiffness", "gear_brake_stiffness",
                                 "coupling_damping_ratio")]
    + [("structure", n) for n in ("pinion_mass", "gear_mass", "pinion_pedestal_mass",
                                  "gear_pedestal_mass", "pinion_support_stiffness",
                                  "gear_support_stiffness", "pinion_pedestal_stiffness",
                                  "gear_pedestal_stiffness", "support_damping_ratio",
                                  "pedestal_damping_ratio", "casing_mass", "casing_inertia",
                                  "isolator_stiffness_y", "isolator_stiffness_x",
                                  "isolator_damping_ratio", "panel_frequencies",
                                  "panel_damping", "mount_frequencies")]
    + [("flanks", n) for n in ("mesh_damping_ratio",)])


def scatter_value(value, factor_fn):
    """Scale a float or each element of a tuple of floats by independent factors."""
    if isinstance(value, tuple):
        return tuple(float(v) * factor_fn() for v in value)
    return float(value) * factor_fn()


def default_sections() -> dict:
    return {"drivetrain": Drivetrain(), "structure": Structure(), "flanks": Flanks(),
            "acquisition": Acquisition()}


@dataclass(frozen=True)
class GearboxIdentity:
    """What makes one physical gearbox itself beyond its base parameters (all seeded)."""

    seed: int = 0                          # tooth deviations, roughness, pit nuclei
    speed_offset: float = -0.006           # [-] true/commanded speed - 1 (slip compensation error)
    sensor_gains: tuple = (1.0, 1.0)       # [-] calibration error of each accelerometer
    runout_phases: tuple = (0.7, 2.1)      # [rad] of the pinion and gear eccentricities
    fault_tooth: int = 7                   # pinion tooth of local_tooth_fault
    ripple_frequency: float = 100.0        # [Hz] DC-link ripple of the VFD (2 x 50 Hz mains)


def identity_from_seed(seed: int) -> GearboxIdentity:
    rng = np.random.default_rng([seed, 101])
    return GearboxIdentity(
        seed=int(seed),
        speed_offset=float(rng.normal(0.0, 0.008)),
        sensor_gains=tuple(float(g) for g in 1.0 + rng.normal(0.0, 0.04, 2)),
        runout_phases=tuple(float(p) for p in rng.uniform(0, 2 * np.pi, 2)),
        fault_tooth=int(rng.integers(0, 19)),
        ripple_frequency=100.0,
    )
