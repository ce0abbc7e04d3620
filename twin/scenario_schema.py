"""The scenario format's JSON Schema (``twin schema``): every key a scenario file may hold, its
type, range and meaning.  :mod:`twin.scenario` validates files against it and reads them."""
from __future__ import annotations

from typing import Any

FORMAT_VERSION = 1
#: Rules for which model modes are visible, i.e. pairing candidates (``calibration.visibility``;
#: :mod:`twin.calibration.model_modes`).
VISIBILITY_RULES = ("mesh", "run-up", "mesh+dominant", "run-up+dominant")

_NUM = {"type": "number"}
_POS = {"type": "number", "exclusiveMinimum": 0}
_NONNEG = {"type": "number", "minimum": 0}
_NAME_MAP = {"type": "object", "additionalProperties": {"type": "number"}}
#: a value of any FMI variable type: a number (Real/Float, Integer), a boolean, or a string
#: (String, or an enumeration item by name)
_VALUE = {"type": ["number", "boolean", "string"]}
_VALUE_MAP = {"type": "object", "additionalProperties": _VALUE}


def _profile_schema(value: dict, what: str) -> dict:
    return {
        "description": what,
        "oneOf": [
            value,
            {"type": "object", "additionalProperties": False, "required": ["constant"],
             "properties": {"constant": value}},
            {"type": "object", "additionalProperties": False, "required": ["ramp"],
             "properties": {"ramp": {"type": "object", "additionalProperties": False,
                                     "required": ["from", "to", "duration"],
                                     "properties": {"from": _NUM, "to": _NUM, "start": _NONNEG, "duration": _POS}}}},
            {"type": "object", "additionalProperties": False, "required": ["steps"],
             "properties": {"steps": {"type": "array", "minItems": 1,
                                      "items": {"type": "array", "prefixItems": [_NONNEG, value],
                                                "minItems": 2, "maxItems": 2}}}},
            {"type": "object", "additionalProperties": False, "required": ["table"],
             "properties": {"table": {"type": "object", "additionalProperties": False, "required": ["file", "column"],
                                      "properties": {"file": {"type": "string"}, "column": {"type": "string"},
                                                     "time_column": {"type": "string"}}}}},
        ],
    }


_PROFILE = _profile_schema(_NUM, "A scalar signal over time: constant, ramp, steps or a CSV table.")
_INPUT_PROFILE = _profile_schema(
    _VALUE, "An input over time: constant, ramp, steps or a CSV table; constants and steps may also be "
            "booleans or strings (String inputs, enumeration items by name) for inputs of those types.")

CALIBRATION_SCHEMA: dict[str, Any] = {
    "type": "object", "additionalProperties": False, "required": ["parameters"],
    "properties": {
        "parameters": {"oneOf": [
            {"const": "auto", "description": "the parameters the measured modes identify, with bounds from physics"},
            {"type": "object", "minProperties": 1,
             "additionalProperties": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}}]},
        "modes_from": {"oneOf": [{"type": "string"},
                                 {"type": "array", "items": {"type": "string"}, "minItems": 1, "uniqueItems": True}],
                       "description": "record (run-up or hammer test) the measured modes are read from, or several "
                                      "read together (a run-up and a hammer test per struck point)"},
        "struck_shafts": {"type": "object", "minProperties": 2,
                          "additionalProperties": {"enum": ["input", "output"]},
                          "description": "the shaft each hammer record of modes_from strikes (record name: input or "
                                         "output, one of each at least): a measured mode struck louder on one shaft "
                                         "is never paired with a model mode that lives on the other"},
        "path_from": {"type": "object", "minProperties": 1,
                      "additionalProperties": {"enum": ["bearing_force_input_x", "bearing_force_input_y",
                                                        "bearing_force_output_x", "bearing_force_output_y"]},
                      "description": "hammer records struck at the bearing housings (record name: the model's bearing "
                                     "force that stands for the blow); the casing sensors then read the twin's "
                                     "bearing forces through the accelerances these records measured (in-situ "
                                     "transfer path analysis), not through the modelled casing"},
        "mesh_form": {"enum": ["none", "fit"],
                      "description": "fit: the pinion's as-manufactured profile deviation (slope and crowning, "
                                     "profile_deviation) fitted to the measured gear-mesh harmonics before the "
                                     "levels; none (default): perfect involutes"},
        "face_contact_from": {"type": "string", "minLength": 1,
                              "description": "a steady record at the steady record's speed and another load: the "
                                             "flanks' lead mismatch (lead_mismatch) fitted to how the spectrum's "
                                             "shape changes between the two loads, before the levels"},
        "path_sections": {"type": "integer", "minimum": 1, "maximum": 200,
                          "description": "second-order sections fitted to each measured path (default 32)"},
        "min_confidence": {"type": "number", "minimum": 0, "maximum": 1},
        "lscf": {"type": "boolean", "description": "also fit the hammer-test records named in modes_from together by the "
                                                   "poly-reference LSCF method (close modes one FRF hump hides; default false)"},
        "objectives": {"type": "array", "minItems": 1, "uniqueItems": True,
                       "items": {"enum": ["waveform", "correlation", "frequencies", "modes"]}},
        "algorithm": {"enum": ["mogoa", "nsga2"]},
        "pop_size": {"type": "integer", "minimum": 2},
        "n_gen": {"type": "integer", "minimum": 1},
        "record": {"type": "string"},
        "natural_frequencies": {"type": "array", "items": {"type": "number", "exclusiveMinimum": 0}, "minItems": 1},
        "foundation_modes": {"oneOf": [{"type": "array", "items": {"type": "number", "exclusiveMinimum": 0}},
                                       {"type": "string"}],
                             "description": "the foundation's modes, removed from the measured ones (paper: hammer "
                                            "test on the casing root): in Hz, or the name of a hammer-test record"},
        "record_duration": {"type": "number", "exclusiveMinimum": 0},
        "settle_time": {"type": "number", "minimum": 0},
        "band": {"type": "array", "items": {"type": "number", "minimum": 0}, "minItems": 2, "maxItems": 2},
        "refine": {"type": "boolean", "description": "polish the pick by least squares on the modes (default true)"},
        "pairing": {"enum": ["frequency", "shape"],
                    "description": "how measured modes are paired with model modes: frequency (the nearest visible "
                                   "model mode within 15 %, default) or shape (frequency, shape at the sensors and "
                                   "reach)"},
        "fit": {"enum": ["follow", "search"],
                "description": "how the modes are fitted: follow (the modes paired at the nominal set, followed "
                               "through a Levenberg-Marquardt descent, default) or search (CMA-ES, the modes "
                               "paired afresh at every candidate set, then that descent)"},
        "search_budget": {"type": "integer", "minimum": 8,
                          "description": "linearisations of the modes search (fit: search; default 160)"},
        "visibility": {"enum": list(VISIBILITY_RULES),
                       "description": "which excitations make a model mode visible (a pairing candidate): the "
                                      "mesh's alone (default) or any of a run-up's (mesh, drive and load torque, "
                                      "lateral forces at the gears, the process force); '+dominant': a mode that "
                                      "dominates such a response at its own frequency counts too, not only one "
                                      "that makes a peak"},
        "evaluation_timeout": {"type": "number", "exclusiveMinimum": 0,
                               "description": "s; an evaluation still running then is stopped and scored infeasible "
                                              "(default 600)"},
        "speed": {"type": "number", "exclusiveMinimum": 0,
                  "description": "Hz: operating speed of typed natural frequencies without a measurement file "
                                 "(default: the constant operating.speed)"},
        "load": {"type": "number", "minimum": 0,
                 "description": "N.m: operating load of typed natural frequencies without a measurement file "
                                "(default: the constant operating.load)"},
    },
}


SCHEMA: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "$id": "https://gear-twin.invalid/schemas/scenario-v1.json",
    "title": "gear-twin scenario",
    "type": "object",
    "additionalProperties": False,
    "required": ["version", "name", "fmu"],
    "properties": {
        "version": {"const": FORMAT_VERSION, "description": "Scenario format version."},
        "name": {"type": "string", "minLength": 1},
        "description": {"type": "string"},
        "fmu": {"type": "string", "minLength": 1,
                "description": "Path of an .fmu or of an .ssp with one FMU component and its parameter bindings "
                               "(relative to the scenario file), or a Modelica model name built from modelica/."},
        "start_time": {**_NONNEG, "description": "s; default: the model's default experiment, else 0"},
        "stop_time": {**_POS, "description": "s; default: the model's default experiment"},
        "communication_step": {**_POS, "description": "s; default: the whole number of output samples "
                                                      "nearest 0.01 s (at least one)"},
        "seed": {"type": "integer", "minimum": 0},
        "output": {
            "type": "object", "additionalProperties": False,
            "properties": {"sample_rate": {**_POS, "description": "Hz; default: 1 / the model's default "
                                                                  "experiment step (see twin info)"},
                           "variables": {"type": "array", "items": {"type": "string"}, "minItems": 1}},
        },
        "parameters": {**_VALUE_MAP, "description": "Parameter (and start) values by FMU variable name: numbers, "
                                                     "booleans, strings, enumeration items by name."},
        "structural": {**_NAME_MAP,
                       "description": "Build options of the model named in 'fmu': structural parameters (z1, z2, "
                                      "n_profile) and build-time defaults; the variant is built and cached "
                                      "(like `twin build MODEL --set NAME=VALUE`)."},
        "parameter_files": {"type": "array", "items": {"type": "string"},
                            "description": "JSON ({name: value}) or SSP .ssv parameter sets, applied in order before "
                                           "'parameters' (and after the bindings of an .ssp fmu); .ssv values are "
                                           "converted into the FMU's units."},
        "operating": {
            "type": "object", "additionalProperties": False,
            "properties": {"speed": {**_PROFILE, "description": "Shaft speed, Hz"},
                           "load": {**_PROFILE, "description": "Load torque, N.m"},
                           "speed_input": {"type": "string", "description": "FMU input that receives 2*pi*speed (rad/s)"},
                           "load_input": {"type": "string", "description": "FMU input that receives the load (N.m)"},
                           "inputs": {"type": "object", "additionalProperties": _INPUT_PROFILE,
                                      "description": "Other FMU inputs by name, in their own units"}},
        },
        "events": {
            "type": "array",
            "items": {"type": "object", "additionalProperties": False, "required": ["time"],
                      "minProperties": 2,
                      "properties": {"time": _NONNEG, "override": _VALUE_MAP, "bias": _NAME_MAP,
                                     "reset": {"type": "array", "items": {"type": "string"}}}},
        },
        "degradation": {
            "type": "object", "additionalProperties": False, "required": ["model"],
            "properties": {
                "model": {"enum": ["pitting", "wear"]},
                "coefficients": _NAME_MAP,
                "cycles_per_update": {**_POS, "description": "largest jump of pinion cycles between load re-samplings"},
                "max_increment": {**_POS, "description": "largest local damage increment per update (m of wear depth, or pitting density)"},
                "stop": {"type": "object", "additionalProperties": False, "minProperties": 1,
                         "properties": {"pitting_density": {"type": "number", "exclusiveMinimum": 0, "maximum": 1},
                                        "wear_depth": _POS, "cycles": _POS}},
                "max_updates": {"type": "integer", "minimum": 1},
                "load_window": {**_POS, "description": "s of co-simulation sampled to estimate the mesh load at each update"},
                "record_duration": {**_NONNEG, "description": "s of vibration stored at each update (0 = none)"},
                "pair_stiffness": {"enum": ["model", "contact"],
                                   "description": "wear: k_pair the model's or scenario's values ('model', default), or "
                                                  "the LTCA's single-pair secant stiffness at each update's mean mesh force "
                                                  "('contact': the pairs share the load with the compliance of the contact "
                                                  "analysis that wears the flanks)"},
                "tooth_scatter": {**_NONNEG, "description": "pitting: log-sd of the per-tooth pitting strength "
                                                           "factors (seeded by 'seed', as are the pit cells; default 0.58, "
                                                           "the Weibull life scatter of gear teeth; 0 = teeth alike)"},
                "pit_cluster_length": {**_NONNEG, "maximum": 0.1,
                                       "description": "pitting: correlation length [m] of the pit cells' strengths "
                                                      "across the flank (default 0: cells fail independently; "
                                                      "0.8e-3 is the size of a progressive pit, an opt-in)"},
            },
        },
        "archive": {
            "type": "object", "additionalProperties": False, "required": ["stages"],
            "properties": {
                "stages": {"type": "array", "minItems": 2, "items": _NONNEG,
                           "description": "Stage boundaries of the damage measure (pitting density or wear depth in m), ascending"},
                "records_per_stage": {"type": "integer", "minimum": 1},
                "record_duration": _POS,
                "speed_scatter": {**_NONNEG, "description": "relative standard deviation of the shaft speed"},
                "load_scatter": {**_NONNEG, "description": "relative standard deviation of the load"},
                "noise": {**_NONNEG, "description": "measurement noise, relative to the signal RMS"},
                "settle_time": {**_NONNEG, "description": "s simulated and discarded before each record"},
                "damage_sampling": {"enum": ["uniform", "snapshot"],
                                    "description": "uniform: damage drawn uniformly within each stage; snapshot: "
                                                   "around the stage centre, like records taken at inspection "
                                                   "points of an endurance test (the paper's stages)"},
                "damage_scatter": {**_NONNEG, "description": "snapshot sampling: standard deviation of the damage "
                                                            "as a fraction of the stage width (default 0.1)"},
                "pitch_error": {**_NONNEG, "description": "m: each record's pinion has per-tooth pitch errors with "
                                                         "an sd drawn uniformly up to this (default 0)"},
                "runout": {**_NONNEG, "description": "m: each record's pinion has a run-out, peak to peak, drawn "
                                                    "uniformly up to this (default 0)"},
                "tooth_damage_scatter": {**_NONNEG, "description": "relative sd of the damage from tooth to tooth "
                                                                  "(pitting: its depth; wear: the wear coefficient, the "
                                                                  "teeth worn under load sharing), drawn per record "
                                                                  "uniformly up to this (default 0)"},
                "wheel_pitch_error": {**_NONNEG, "description": "m: each record's gear (wheel) has single pitch "
                                                               "deviations with an sd drawn uniformly up to this; "
                                                               "its teeth sit at their cumulative sum (default 0)"},
                "wheel_runout": {**_NONNEG, "description": "m: each record's gear (wheel) has a run-out, peak to "
                                                          "peak, drawn uniformly up to this (default 0)"},
            },
        },
        "calibration": CALIBRATION_SCHEMA,
        "diagnosis": {
            "type": "object", "additionalProperties": False,
            "description": "Written by twin add-effect and twin improve.",
            "properties": {"calibrated": {**_NAME_MAP, "description": "calibrated values of the base parameters "
                                          "an added effect refitted; every later refit stays within the "
                                          "documented band around these, not around the moved values"}},
        },
        "executor": {
            "type": "object", "additionalProperties": False,
            "properties": {"type": {"enum": ["local", "dask"]},
                           "workers": {"type": "integer", "minimum": 1},
                           "address": {"type": "string"},
                           "timeout": {"type": "number", "exclusiveMinimum": 0,
                                       "description": "s per task; a task still running then is stopped and "
                                                      "reported (default 3600)"},
                           "retries": {"type": "integer", "minimum": 0,
                                       "description": "re-runs of a task whose worker process died (default 0)"}},
        },
    },
}
