"""Surface degradation of the pinion flank (abrasive wear, fatigue pitting) and its mapping to
the FMU's mesh parameters.  Pure numpy/scipy; see README.md in this directory.

Typical loop (the orchestrator owns the FMU)::

    geometry = GearPair.from_parameters(fmu_parameters)
    wear = ArchardWear();  state = wear.initial_state(geometry)
    load = MeshLoad.from_samples(roll, pair_force)            # from a short co-simulation
    state = wear.advance(state, load, cycles, omega1)
    update = mesh_parameters(geometry, wear=state)            # -> update.parameters to the FMU
    state = project_wear(state)                               # keep the state what the FMU sees
"""
from twin.degradation.archard import DEFAULT_WEAR_COEFFICIENT, ArchardWear
from twin.degradation.base import DegradationModel, PittingState, WearState, flank_mean
from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad, TransmittedLoad
from twin.degradation.ltca import FlankDamage, LoadedContact
from twin.degradation.contact_check import ContactCheck, contact_check
from twin.degradation.wear import FlankWear
from twin.degradation.mapping import (HEALTHY_K_PAIR, MeshUpdate, contact_k_pair, mesh_parameters, project_on_nodes,
                                      project_wear, wear_deviation)
from twin.degradation.pitting import (DEFAULT_DEPTH_EXPONENT, DEFAULT_PITTING_COEFFICIENT, DEFAULT_STRESS_EXPONENT,
                                      DEFAULT_WEIBULL_SLOPE, FatiguePitting)

__all__ = [
    "ArchardWear", "ContactCheck", "DEFAULT_DEPTH_EXPONENT", "DEFAULT_PITTING_COEFFICIENT", "DEFAULT_STRESS_EXPONENT",
    "DEFAULT_WEAR_COEFFICIENT", "DEFAULT_WEIBULL_SLOPE", "DegradationModel", "FatiguePitting", "FlankDamage",
    "FlankWear", "GearPair", "HEALTHY_K_PAIR", "LoadedContact", "MeshLoad", "MeshUpdate", "PittingState",
    "TransmittedLoad", "WearState", "contact_check", "contact_k_pair", "flank_mean", "mesh_parameters", "project_on_nodes", "project_wear",
    "wear_deviation",
]
