"""The pedestal rig: an independent full-rig simulator of the 19/52 spur-gear test rig.

A speed-controlled motor (VFD with a PI speed loop), couplings and a torque meter, pinion and
gear on shafts with lateral and torsional freedom, rolling-bearing pedestals in a casing that is
a rigid body on isolators with casing panel modes, accelerometers on brackets, and a
magnetic-particle brake. See ``rigs/pedestal/README.md``.

    from rigs.pedestal import Rig, write
    box = Rig().scattered(seed=3, scatter=0.12)
    box.modes(speed=20.0, load=20.0)
    rec = box.steady(speed=20.0, load=20.0, duration=2.0, effect="pinion_runout", seed=0)
    write("rig.h5", [rec])                     # and rig.h5.truth.json
"""
from .effects import CATALOGUE, EFFECTS, OUTSIDE_CATALOGUE, Effect
from .io import read_truth, write
from .modes import Mode
from .record import Damage, RigRecord
from .rig import VERSION, Rig
from .stages import Stage

__all__ = ["Rig", "Mode", "RigRecord", "Damage", "Effect", "Stage", "write", "read_truth",
           "EFFECTS", "CATALOGUE", "OUTSIDE_CATALOGUE", "VERSION"]
