"""``twin run``, ``archive`` and ``import``: scenario runs, the labelled archive, measurements in;
``schema`` and ``demo``."""
from __future__ import annotations

import argparse
from pathlib import Path

from twin.commands.common import lib, positive_int, positive_seconds, print_warnings, recording_warnings

def add_subcommands(sub) -> None:
    """Register ``run``, ``archive`` and ``import``."""
    p = sub.add_parser("run", help="run a scenario file through the co-simulation orchestrator")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml file, or an .ssp (its FMU, bindings and "
                                                        "default experiment)")
    p.add_argument("--output", help="result file, .h5/.hdf5 or .csv (default: <scenario name>.h5)")
    p.add_argument("--stop-time", type=float, help="override the scenario's stop time [s]")
    p.add_argument("--resume", action="store_true", help="degradation runs: continue from the last completed stage")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.add_argument("--timeout", type=positive_seconds, metavar="SECONDS",
                   help="stop the FMU and report an error if the run takes longer")
    p.set_defaults(handler=_cmd_run)

    p = sub.add_parser("archive", help="simulate the labelled degradation archive of a scenario")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml with degradation and archive blocks")
    p.add_argument("--out", help="archive HDF5 file (default: <scenario name>_archive.h5)")
    p.add_argument("--records-per-stage", type=int, help="override archive.records_per_stage")
    p.add_argument("--workers", type=positive_int, help="local worker processes (default: one per core)")
    p.add_argument("--scheduler", help="address of a dask.distributed scheduler (tcp://host:port)")
    p.add_argument("--seed", type=int, help="override the scenario's seed")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    p.set_defaults(handler=_cmd_archive)

    p = sub.add_parser("import", help="convert a CSV measurement (+ YAML/JSON sidecar) to HDF5")
    p.add_argument("csv", metavar="CSV", help="CSV file with a time column and channels")
    p.add_argument("--out", required=True, help="HDF5 file to write")
    p.add_argument("--sidecar", help="sidecar with the record attributes (default: next to the CSV)")
    p.add_argument("--fmu", help="the FMU that wrote the CSV (e.g. an fmpy result): units of the columns the "
                                 "sidecar does not give; no sidecar needed")
    p.add_argument("--channels", help="comma-separated channels to keep (default: every column)")
    p.set_defaults(handler=_cmd_import)


def add_schema_and_demo(sub) -> None:
    """Register ``schema`` and ``demo``."""
    p = sub.add_parser("schema", help="print the JSON Schema of scenario files")
    p.set_defaults(handler=_cmd_schema)

    p = sub.add_parser("demo", help="build, simulate and plot the reference gearbox")
    p.add_argument("--out", default="demo_out", help="output directory (default: demo_out)")
    p.add_argument("--stop-time", type=float, default=10.0,
                   help="simulated time [s] (default: 10)")
    p.add_argument("--rig-records", nargs="+", default=(), metavar="FILE",
                   help="pitting records of independent simulators (python -m rigs.lumped target ...) for step 9")
    p.add_argument("--calibration-records", nargs="+", default=(), metavar="FILE",
                   help="a steady and a run-up record of an independent simulator (python -m rigs.pedestal ...) "
                        "for step 6, and optionally hammer tests of the same gearbox at the pinion's and the gear's "
                        "pedestal, a steady record at another load, then another healthy steady record (STEADY RUNUP "
                        "[HAMMER [HAMMER_GEAR [LIGHT [STEADY_AGAIN]]]])")
    p.add_argument("--hidden-effect-records", nargs=2, default=(), metavar=("STEADY", "RUNUP"),
                   help="a steady and a run-up record of step 6's gearbox with one of the rig's own effects "
                        "(python -m rigs.pedestal ... --effect casing_resonance) for step 8")
    p.set_defaults(handler=_cmd_demo)


def _cmd_demo(args: argparse.Namespace) -> int:
    lib("twin.demo").run_demo(Path(args.out), stop_time=args.stop_time, rig_records=args.rig_records,
                               calibration_records=args.calibration_records,
                               hidden_effect_records=args.hidden_effect_records)
    return 0


def _cmd_schema(args: argparse.Namespace) -> int:
    print(lib("twin.scenario").schema_json())
    return 0


def _run_in_child(scenario, out: Path, progress: bool, resume: bool) -> tuple[str, int]:
    if scenario.degradation is not None:
        run = lib("twin.degradation_run").run_degradation(scenario, out, progress=progress, resume=resume)
        if not run.stages:
            return f"{scenario.name}: interrupted before the first stage; nothing written", 130
        where = out if run.complete else lib("twin._atomic").partial_path(out)
        state = "complete" if run.complete else "not complete, kept for --resume"
        return f"{scenario.name}: {len(run.stages)} stages ({state}), {run.summary()} -> {where}", 0 if run.complete else 130
    rec = lib("twin.orchestrator").run_scenario(scenario, out, progress=progress)
    state = ("complete" if rec.complete and not rec.result.ended_by_fmu
             else f"ended by the FMU: {rec.result.end_reason}" if rec.complete
             else f"interrupted; partial result kept beside, {out} unchanged")
    return (f"{scenario.name}: {rec.result.time.size} samples of {len(rec.result.signals)} channels "
            f"({state}) -> {rec.path}", 0 if rec.complete else 130)


def _cmd_run(args: argparse.Namespace) -> int:
    scenarios = lib("twin.scenario")
    if args.scenario.endswith(".ssp"):       # an SSP runs as it is, over its default experiment
        scenario = scenarios.scenario_from_ssp(Path(args.scenario), args.stop_time)
    else:
        scenario = scenarios.load_scenario(Path(args.scenario))
    if args.stop_time is not None:
        scenario = lib("twin.checks").override_stop_time(scenario, args.stop_time)
    out = Path(args.output) if args.output else Path(f"{scenario.name}.h5")
    lib("twin.results").check_output_path(out)
    if scenario.degradation is not None:      # before its FMU is built: a degradation run is HDF5 only
        lib("twin.results").check_hdf5_path(out, "a degradation run")
    if args.resume and scenario.degradation is None:
        raise lib("twin.errors").ResumeError("--resume continues degradation runs only; a plain run starts "
                                              "from its start time (its partial output is kept for inspection)")
    scenario.fmu_path()            # build or find the FMU here, so its errors are reported plainly
    (text, code), notes = lib("twin.isolation").run_isolated(recording_warnings, _run_in_child, scenario, out,
                                                              not args.no_progress, args.resume,
                                                              what=f"scenario {scenario.name}", timeout=args.timeout)
    print_warnings(notes)
    print(text)
    return code


def _cmd_archive(args: argparse.Namespace) -> int:
    scenario = lib("twin.scenario").load_scenario(Path(args.scenario))
    if scenario.archive is None:
        raise lib("twin.errors").ScenarioError([(str(args.scenario), "archive", "the scenario has no archive block")])
    arc = dict(scenario.archive)
    if args.records_per_stage is not None:
        arc["records_per_stage"] = args.records_per_stage
    executor = dict(scenario.executor)
    if args.workers is not None:
        executor["workers"] = args.workers
    if args.scheduler:
        executor = {"type": "dask", "address": args.scheduler}
    scenario = scenario.with_overrides(archive=arc, executor=executor,
                                       seed=args.seed if args.seed is not None else scenario.seed)
    out = Path(args.out) if args.out else Path(f"{scenario.name}_archive.h5")
    archive = lib("twin.archive").build_archive(scenario, out, progress=not args.no_progress)
    print(f"{scenario.name}: {archive.labels.size} records in {len(archive.stages) - 1} stages "
          f"({archive.damage_kind}) -> {out}")
    return 0


def _cmd_import(args: argparse.Namespace) -> int:
    out = lib("twin.measurements").import_csv(Path(args.csv), Path(args.out),
                                               sidecar=Path(args.sidecar) if args.sidecar else None,
                                               **_import_fmu_options(args))
    mset = lib("twin.measurements").load_measurements(out)
    print(f"{args.csv} -> {out}: {len(mset)} record(s), channels {', '.join(mset[0].channel_names)}")
    return 0


def _import_fmu_options(args: argparse.Namespace) -> dict:
    """``twin import --fmu/--channels``: units of a result CSV (fmpy's or the twin's) from its FMU."""
    options = {}
    if args.fmu:
        options["fmu"] = Path(args.fmu)
    if args.channels:
        options["channels"] = [c.strip() for c in args.channels.split(",") if c.strip()]
    return options
