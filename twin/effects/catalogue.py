"""The catalogue of physical effects the base gearbox model lacks.

Each :class:`Effect` names a Modelica component in ``GearTwin.Effects`` and says how a variant
of ``GearTwin.Gearbox21`` wires it in:

* ``inputs``: modifiers that feed the component from the gearbox (``shaft_angle = theta5``);
* ``hooks``: which effect hook of the base model each component output adds to
  (``effect_drive_torque`` += ``<id>.torque``); several effects on one hook are summed;
* ``base_bindings``: parameter hooks of the base model the component binds
  (``effect_tooth_stiffness_factor = <id>.tooth_factor``).  They compose with the base model's
  own degradation parameters (``tooth_stiffness_factor``, ``profile_deviation``), so a variant
  still takes the degradation state a scenario or a degradation run gives it.

``fit`` lists the component parameters :func:`twin.effects.diagnose` refits, with bounds and
whether they are searched on a log scale; ``related`` names the base parameters whose value
shapes the same signature, refitted with the effect within +-:data:`RELATED_SPAN` of their
calibrated values (the leading candidates of a diagnosis, and ``twin add-effect``); ``neutral`` holds values that switch the effect off, so
one candidate model carrying every effect reproduces the base model exactly.
``evidence`` maps finding kinds (see :mod:`twin.compare`) to the physical reason the effect
explains them.

To add an effect of your own: write the component in ``modelica/GearTwin/Effects/`` with a
readme, add an :class:`Effect` here, regenerate the candidate model
(``twin effects --write-candidates``), and add a hidden-effect case to
``tests/twin/effects/test_hidden.py``. See ``modelica/GearTwin/Effects/README.md``.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class FitParameter:
    name: str                    # component parameter, e.g. "eccentricity"
    lower: float
    upper: float
    log: bool = False            # search on a log scale (amplitudes spanning decades)
    guess: str | None = None     # start from the spectrum: "unlocked_line", "slow_sideband", "resonance"
    grid: int = 7                # points of the coarse search before the local polish


@dataclass(frozen=True)
class Effect:
    id: str
    component: str                              # Modelica class
    title: str
    inputs: dict[str, str] = field(default_factory=dict)
    hooks: dict[str, str] = field(default_factory=dict)          # base hook -> component output
    base_bindings: dict[str, str] = field(default_factory=dict)  # parameter hook -> component parameter
    fit: tuple[FitParameter, ...] = ()
    related: tuple[str, ...] = ()                               # base parameters refitted with it
    neutral: dict[str, float] = field(default_factory=dict)
    evidence: dict[str, str] = field(default_factory=dict)       # finding kind -> physical reason

    def parameter(self, name: str) -> str:
        """FMU name of a component parameter, e.g. ``pinion_eccentricity.eccentricity``."""
        return f"{self.id}.{name}"


#: Relative band [-] in which a related base parameter moves around its calibrated value.
RELATED_SPAN = 0.1

_GEOMETRY = {"roll_pitch": "roll_pitch", "contact_start_radius": "contact_start_radius",
             "contact_path_length": "contact_path_length", "line_of_action_length": "line_of_action_length"}

def _eccentricity(gear: str) -> Effect:
    """Run-out of the pinion or the gear: one component, on that gear's shaft."""
    # the component reads its shaft's angle counter-clockwise in the plane of the line of action:
    # the pinion's theta5; the gear turns the other way, theta10 counts its own sense
    shaft = {"pinion": ("theta5", "omega5"), "gear": ("-theta10", "-omega10")}[gear]
    return Effect(
        f"{gear}_eccentricity", "GearTwin.Effects.ShaftEccentricity", f"{gear.capitalize()} run-out",
        inputs={"shaft_angle": shaft[0], "shaft_speed": shaft[1]},
        hooks={"effect_mesh_displacement": "mesh_displacement",
               "effect_mesh_displacement_rate": "mesh_displacement_rate",
               "effect_off_line_displacement": "off_line_displacement",
               "effect_lead_mismatch": "lead_mismatch"},
        # a gear bored off-centre is usually bored off-square too: its tilt sweeps the lead
        # across the face once per turn (wobble), which at light load shrinks the contact
        fit=(FitParameter("eccentricity", 2e-7, 2e-4, log=True), FitParameter("wobble", 1e-7, 2e-4, log=True)),
        # the mesh force of a run-out approach scales with the mesh stiffness
        related=("mesh_stiffness_scale",),
        neutral={"eccentricity": 0.0, "wobble": 0.0},
        evidence={"sideband": f"run-out of the {gear} modulates the mesh approach and the start of contact "
                              f"(the centre distance) once per {gear} revolution, "
                              f"which puts sidebands at {gear}-speed spacing around the mesh harmonics",
                  "shaft_order": f"the once-per-revolution approach change excites the first {gear} orders",
                  "mesh_harmonic": "the modulation moves energy between the mesh harmonics and their sidebands; "
                                   "a tilted gear's wobble shrinks the face contact, which softens the mesh "
                                   "and raises its harmonics",
                  "resonance": "sideband families fill the region around resonances",
                  "angular_line": f"below the first torsional mode the shafts turn to follow the run-out's approach "
                                  f"change, so the encoder's angle moves once per {gear} revolution"})


CATALOGUE: dict[str, Effect] = {e.id: e for e in (
    _eccentricity("pinion"),
    _eccentricity("gear"),
    Effect("motor_torque_ripple", "GearTwin.Effects.MotorTorqueRipple", "Drive motor torque ripple",
           hooks={"effect_drive_torque": "torque"},
           fit=(FitParameter("frequency", 20.0, 400.0, guess="unlocked_line"),
                FitParameter("amplitude", 1e-3, 2.0, log=True)),
           related=("kt35",),              # the input coupling carries the ripple to the pinion
           neutral={"amplitude": 0.0},
           evidence={"unlocked_line": "an electrical torque ripple vibrates the drive train at its own frequency, "
                                      "which is locked to neither shaft",
                     "sideband": "the ripple modulates the mesh force, giving sidebands at the ripple frequency",
                     "angular_line": "the ripple's torque turns the drive train at its own frequency, which the "
                                     "encoder's angle shows locked to neither shaft"}),
    Effect("load_torque_fluctuation", "GearTwin.Effects.LoadTorqueFluctuation", "Brake torque fluctuation",
           hooks={"effect_load_torque": "torque"},
           fit=(FitParameter("frequency", 0.5, 15.0, guess="slow_sideband"),
                FitParameter("amplitude", 1e-2, 10.0, log=True)),
           related=("c_motor",),           # the motor's torque-slip slope sets the slow speed response
           neutral={"amplitude": 0.0},
           evidence={"angular_line": "the brake's torque fluctuation turns the drive train at its frequency",
                     "unlocked_line": "a slow load fluctuation modulates the mesh force and the speed, giving "
                                      "lines beside the mesh harmonics at a spacing locked to no shaft",
                     "sideband": "the mesh-force modulation gives sidebands around the mesh harmonics",
                     "mesh_harmonic": "the modulation moves energy out of the mesh harmonics"}),
    Effect("housing_mode", "GearTwin.Effects.SensorMountMode", "Casing or sensor-mount mode",
           # the mode filters what reaches the sensor: on a model with a transfer path and sensor
           # (Gearbox21Measured, Gearbox21Casing and those extending it) that is the path's
           # output, not the pedestal's motion (sensor_path_acceleration_pinion is 0 without one)
           inputs={"base_acceleration": "casing_acceleration_pinion + sensor_path_acceleration_pinion"},
           hooks={"effect_sensor_acceleration_pinion": "extra_acceleration"},
           fit=(FitParameter("frequency", 300.0, 4800.0, guess="resonance"),
                FitParameter("participation", 0.02, 3.0, log=True),
                FitParameter("damping_ratio", 0.005, 0.1, log=True)),
           related=("ky6",),               # the pedestal sets the casing motion the mode filters
           neutral={"participation": 0.0},
           evidence={"resonance": "a structural mode in the path to the sensor amplifies a band of frequencies "
                                  "whatever excites it",
                     "mesh_harmonic": "mesh harmonics inside the band of the mode are amplified",
                     "sideband": "sidebands inside the band of the mode are amplified"}),
    Effect("local_tooth_damage", "GearTwin.Effects.LocalToothDamage", "Local damage of one pinion tooth",
           # the spall sits where spalls start, from the pinion's lowest point of single-tooth contact
           # to the pitch point (it carries the whole load there, under negative sliding); its edges
           # are as sharp as the Hertzian contact is wide
           inputs={"z1": "z1", "roll": "roll", "pair_tooth": "pair_tooth", "contact_ratio": "contact_ratio",
                   "roll_pitch": "roll_pitch",
                   "edge_width": "max(1e-3, 2 * hertz_half_width / contact_path_length)"},
           hooks={"effect_pair_deviation": "pair_deviation"},
           base_bindings={"effect_tooth_stiffness_factor": "tooth_factor"},
           fit=(FitParameter("stiffness_loss", 0.0, 0.9), FitParameter("spall_depth", 1e-7, 2e-5, log=True)),
           related=("mesh_stiffness_scale",),
           neutral={"stiffness_loss": 0.0, "spall_depth": 0.0},
           evidence={"impulsive": "a weak or spalled tooth gives one short change of mesh stiffness or approach per "
                                  "pinion revolution, an impulse in the synchronous average",
                     "sideband": "a once-per-revolution impulse spreads into many sidebands at pinion-speed spacing",
                     "resonance": "the impulse excites the structural resonances once per revolution",
                     "shaft_order": "the impulse train has lines at every pinion order"}),
    Effect("backlash", "GearTwin.Effects.Backlash", "Backlash (back-flank contact)",
           inputs={"mesh_deflection": "mesh_deflection", "mesh_stiffness": "mesh_stiffness"},
           hooks={"effect_mesh_force": "back_force"},
           # impacts make the discrepancy a narrow valley in the gap (about +-0.15 decade wide),
           # which a 7-point grid over 2.3 decades steps over
           fit=(FitParameter("gap", 1e-6, 2e-4, log=True, grid=15),),
           related=("c_mesh",),            # the mesh damping absorbs the impacts
           neutral={"gap": 2e-4},
           evidence={"resonance": "when the teeth separate, back-flank impacts excite broadband resonances",
                     "mesh_harmonic": "loss of contact and impacts raise the higher mesh harmonics",
                     "impulsive": "impacts are impulsive"}),
    Effect("tooth_friction", "GearTwin.Effects.ToothFriction", "Sliding friction on the flanks",
           inputs={"roll": "roll", "pair_force": "pair_force", **_GEOMETRY},
           hooks={"effect_pinion_torque": "pinion_torque", "effect_gear_torque": "gear_torque",
                  "effect_off_line_force": "off_line_force"},
           fit=(FitParameter("friction_coefficient", 0.0, 0.15),),
           related=("c_mesh",),            # friction and mesh damping both dissipate per mesh cycle
           neutral={"friction_coefficient": 0.0},
           evidence={"mesh_harmonic": "friction reverses at the pitch point once per mesh cycle; the resulting "
                                      "force across the line of action adds to every mesh harmonic",
                     "resonance": "the off-line force excites modes the line-of-action force does not"}),
    Effect("distributed_wear", "GearTwin.Effects.DistributedWear", "Distributed wear of all pinion teeth",
           inputs={"n_profile": "n_profile", "roll_pitch": "roll_pitch"},
           base_bindings={"effect_profile_deviation": "deviation"},
           fit=(FitParameter("wear_depth", 1e-8, 3e-5, log=True),),
           related=("mesh_stiffness_scale",),   # the profile error acts against the mesh stiffness
           neutral={"wear_depth": 0.0},
           evidence={"mesh_harmonic": "wear removes material away from the pitch point on every tooth, which "
                                      "changes the transmission error once per mesh cycle and so the mesh harmonics",
                     "resonance": "the changed mesh excitation changes the response around the mesh resonances"}),
)}


def effect(effect_id: str) -> Effect:
    """The catalogue entry; raises :class:`twin.errors.ParameterError` naming the unknown id."""
    from twin.errors import ParameterError
    try:
        return CATALOGUE[effect_id]
    except KeyError:
        raise ParameterError(f"unknown effect {effect_id!r}; the catalogue has: {', '.join(CATALOGUE)}") from None
