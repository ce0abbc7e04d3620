"""Remaining useful life from a time series of assessed wear stages (``twin rul``).

The method is described in :mod:`twin.rul.estimator`, the input formats in
:mod:`twin.rul.observations`; the model trajectory is :mod:`twin.rul.trajectory`, the JSON output,
plot and the whole ``twin rul`` pipeline :mod:`twin.rul.io`.  This package module registers the
command line (:func:`add_subcommands`) and forwards the public names lazily, so that
``twin --help`` does not import numpy.

Public API (from ``twin.rul``): :class:`Trajectory`, :func:`trajectory_from_scenario`,
:func:`read_trajectory`, :class:`Observation`, :class:`ObservationSet`,
:func:`read_observations`, :func:`observations_from_dict`, :class:`RULEstimator`,
:class:`RULEstimate`, :func:`run_rul`, :func:`write_json`, :func:`read_json`, :func:`plot_rul`,
:class:`RULError`.
"""
from __future__ import annotations

import argparse
import importlib
from pathlib import Path

# public name -> the module of twin.rul that defines it
_WHERE = {
    **dict.fromkeys(("RULError", "DAMAGE_KINDS", "RUL_FORMAT", "format_damage"), "base"),
    **dict.fromkeys(("Trajectory", "trajectory_from_scenario", "read_trajectory", "scenario_speed_hz",
                     "default_threshold"), "trajectory"),
    **dict.fromkeys(("Observation", "ObservationSet", "read_observations", "observations_from_dict",
                     "check_stages", "simulate_assessments"), "observations"),
    **dict.fromkeys(("RULEstimator", "RULEstimate", "weighted_quantile"), "estimator"),
    **dict.fromkeys(("run_rul", "write_json", "read_json", "plot_rul", "rul_document"), "io"),
}
_PUBLIC = tuple(_WHERE)

__all__ = [*_PUBLIC, "add_subcommands"]


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(importlib.import_module(f"twin.rul.{_WHERE[name]}"), name)
    raise AttributeError(f"module 'twin.rul' has no attribute {name!r}")


def _floats(text: str, option: str) -> list[float]:
    from twin.errors import ParameterError
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ParameterError(f"bad {option} '{text}': expected comma-separated numbers") from None


def _pair(text: str, option: str) -> tuple[float, float]:
    from twin.errors import ParameterError
    vals = _floats(text, option)
    if len(vals) != 2:
        raise ParameterError(f"bad {option} '{text}': expected two numbers lo,hi")
    return vals[0], vals[1]


def _cmd_rul(args: argparse.Namespace) -> int:
    scenario = importlib.import_module("twin.scenario").load_scenario(Path(args.scenario))
    rul_io = importlib.import_module("twin.rul.io")
    opts = {}
    if args.rate_range is not None:
        opts["rate_range"] = _pair(args.rate_range, "--rate-range")
    if args.offset_range is not None:
        opts["offset_range"] = _pair(args.offset_range, "--offset-range")
    if args.temperature is not None:
        opts["temperature"] = args.temperature
    if args.floor is not None:
        opts["floor"] = args.floor
    result, _ = rul_io.run_rul(scenario, Path(args.assessed), threshold=args.threshold,
                               stages=_floats(args.stages, "--stages") if args.stages else None,
                               cycles_file=Path(args.cycles) if args.cycles else None, speed_hz=args.speed,
                               trajectory=Path(args.trajectory) if args.trajectory else None,
                               method="static" if args.static else "cosim", now=args.now, sort=args.sort,
                               json_path=Path(args.json) if args.json else None,
                               plot_path=Path(args.plot) if args.plot else None,
                               progress=not args.no_progress, **opts)
    print(result.table())
    for what, p in (("estimate", args.json), ("plot", args.plot)):
        if p:
            print(f"{what} -> {p}")
    return 0


def add_subcommands(sub) -> None:
    """Register ``twin rul`` on an argparse sub-parser collection (``parser.add_subparsers()``)."""
    p = sub.add_parser("rul", help="remaining useful life from a time series of assessed wear stages",
                       description="Combine assessed stage probabilities (twin assess JSON, or JSON/CSV with "
                                   "record, cycles|time_s, probabilities) with the scenario's calibrated "
                                   "degradation model: current damage, cycles to the threshold, 5-95 %% band.")
    p.add_argument("scenario", help="scenario YAML with a degradation block (and archive stages)")
    p.add_argument("assessed", help="assessed records: JSON (twin assess output or a records list) or CSV")
    p.add_argument("--threshold", type=float, default=None,
                   help="end-of-life damage (pitting density 0-1, or mean wear depth in m); "
                        "default: the scenario's degradation stop criterion")
    p.add_argument("--stages", default=None,
                   help="stage boundaries b0,b1,..,bK (default: the file's, then the scenario's archive stages)")
    p.add_argument("--cycles", default=None,
                   help="cycles of the records: CSV (record,cycles|time_s) or JSON {record: cycles}")
    p.add_argument("--speed", type=float, default=None,
                   help="pinion speed [Hz] to convert time_s to cycles (default: the scenario's speed)")
    p.add_argument("--now", type=float, default=None, help="cycles at which to estimate (default: the last record)")
    p.add_argument("--sort", action="store_true", help="sort the records by cycles instead of rejecting disorder")
    p.add_argument("--trajectory", default=None,
                   help="HDF5 from 'twin run' or 'twin archive' to use as the model trajectory")
    p.add_argument("--static", action="store_true",
                   help="model trajectory from the quasi-static load (no FMU, fast; good for pitting only) "
                        "instead of the co-simulated degradation run")
    p.add_argument("--rate-range", default=None, help="lo,hi of the rate factor against the model (default 0.1,10)")
    p.add_argument("--offset-range", default=None,
                   help="lo,hi of the clock offset, a fraction of the model's life (default -0.2,0.2)")
    p.add_argument("--temperature", type=float, default=None, help="classifier temperature (default 1)")
    p.add_argument("--floor", type=float, default=None,
                   help="uniform floor mixed into the probabilities (default 0.05)")
    p.add_argument("--json", default=None, help="write the estimate to this .json")
    p.add_argument("--plot", default=None, help="write damage vs cycles with the band to this .png")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(handler=_cmd_rul)
