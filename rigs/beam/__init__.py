"""Beam rig: an independent full-rig simulator of the 19/52 spur-gear test rig.

Timoshenko shafts, rigid gear disks, load-dependent ball bearings into a modal casing, a DC
drive with current and speed loops, a particle brake, Weber-Banaschek tooth compliance with a
slice-wise unilateral contact, Archard wear and a discrete pit field, and a 50 kHz acquisition
chain; an impact-hammer test record. See rigs/beam/README.md.
"""
from .effects import DEFAULTS as EFFECTS, Effect, EffectError
from .hammer import LOCATIONS as IMPACT_LOCATIONS, HammerError
from .io import WriteError, write
from .params import VERSION, Params
from .rig import PITTING_EDGES, WEAR_EDGES, Mode, Rig, RigError, RigRecord
from .simulate import Damage, DamageError

__all__ = ["Rig", "RigRecord", "Mode", "Damage", "Effect", "EFFECTS", "Params", "VERSION",
           "PITTING_EDGES", "WEAR_EDGES", "write", "RigError", "EffectError", "DamageError",
           "WriteError", "IMPACT_LOCATIONS", "HammerError"]
