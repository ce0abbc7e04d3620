"""``twin diagnose``, ``add-effect``, ``improve`` and ``effects``: which physical effect the model
lacks, and adding it."""
from __future__ import annotations

import argparse
from pathlib import Path

from twin.commands.common import lib, local_executor, positive_int

def add_subcommands(sub) -> None:
    """Register ``diagnose``, ``add-effect``, ``improve`` and ``effects``."""
    p = sub.add_parser("diagnose", help="rank the catalogue effects the model may be missing, by trying each")
    _loop_arguments(p, out=False, several=True)
    p.add_argument("--json", type=Path, help="write the diagnosis here")
    p.add_argument("--workers", type=positive_int, help="local worker processes (default: one per core)")
    _effects_argument(p)
    p.set_defaults(handler=_cmd_diagnose)

    p = sub.add_parser("add-effect", help="write a model variant with an effect, build it, recalibrate, report")
    p.add_argument("effect", help="catalogue id (see twin effects)")
    _loop_arguments(p, out=True)
    p.set_defaults(handler=_cmd_add_effect)

    p = sub.add_parser("improve", help="diagnose -> add-effect -> recalibrate until nothing improves the fit")
    _loop_arguments(p, out=True, several=True)
    p.add_argument("--from-diagnosis", type=Path, metavar="JSON",
                   help="start from this twin diagnose --json of the same scenario and records instead of "
                        "diagnosing again")
    p.add_argument("--max-steps", type=int, default=4)
    p.add_argument("--workers", type=positive_int, help="local worker processes (default: one per core)")
    _effects_argument(p)
    p.set_defaults(handler=_cmd_improve)

    p = sub.add_parser("effects", help="list the effect catalogue")
    p.add_argument("--write-candidates", action="store_true",
                   help="regenerate the candidate models (GearTwin.Variants.<Base>Candidates, one per base "
                        "model) from the catalogue")
    p.add_argument("--modelica-dir", type=Path, default=None)
    p.set_defaults(handler=_cmd_effects)


def _effects_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--effects", metavar="ID,ID", help="the candidate effects tried, comma-separated catalogue ids "
                                                      "(default: every one the model lacks; see twin effects)")


def _effect_ids(text: str | None) -> list[str] | None:
    """``--effects a,b``: the catalogue ids tried (None: all); unknown ids are refused by the loop."""
    if text is None:
        return None
    ids = [e.strip() for e in text.split(",") if e.strip()]
    if not ids:
        raise lib("twin.errors").ParameterError(f"--effects names no effect: {text!r}")
    return ids


def _baseline(args: argparse.Namespace, scenario):
    """``--baseline FILE [--baseline-record NAME ...]``: the baseline records, or None."""
    if args.baseline is None:
        return None
    return lib("twin.effects.loop").read_baseline(args.baseline, scenario, args.baseline_record, args.record)


def _cmd_diagnose(args: argparse.Namespace) -> int:
    scenario = lib("twin.scenario").load_scenario(Path(args.scenario))
    loop = lib("twin.effects.loop")
    diag = loop.diagnose_scenario(scenario, Path(args.measurements), record=args.record,
                                  all_records=args.all_records, json_path=args.json, executor=local_executor(args.workers),
                                  duration=args.duration, effects=_effect_ids(args.effects),
                                  baseline=_baseline(args, scenario), encoder=args.encoder)
    print(diag.table())
    for c in diag.candidates[:1]:
        for e in c.evidence:
            print(f"  explains [{e.kind}] {e.finding}: {e.reason}")
    if args.json:
        print(f"diagnosis -> {args.json}")
    return 0


def _cmd_add_effect(args: argparse.Namespace) -> int:
    scenario = lib("twin.scenario").load_scenario(Path(args.scenario))
    add = lib("twin.effects.loop").add_effect(scenario, Path(args.measurements), args.effect, Path(args.out),
                                               record=args.record, modelica_dir=args.modelica_dir,
                                               duration=args.duration, baseline=_baseline(args, scenario),
                                               encoder=args.encoder)
    print(f"variant {add.model} -> {add.modelica_file}")
    print(f"FMU -> {add.fmu}")
    print("fitted: " + ", ".join(f"{k} = {v:.4g}" for k, v in add.fitted.items()))
    print(f"log-spectral distance {add.lsd_before_db:.2f} dB -> {add.lsd_after_db:.2f} dB "
          f"({100 * add.reduction:.0f} % less)")
    for desc, b, a in add.per_finding:
        print(f"  {desc}: squared dB error {b:.0f} -> {a:.0f}")
    print(f"scenario for the variant -> {add.scenario_file}")
    return 0


def _cmd_improve(args: argparse.Namespace) -> int:
    scenario = lib("twin.scenario").load_scenario(Path(args.scenario))
    loop = lib("twin.effects.loop")
    history = loop.improve(scenario, Path(args.measurements), Path(args.out), record=args.record,
                           all_records=args.all_records, diagnosis=args.from_diagnosis, max_steps=args.max_steps, executor=local_executor(args.workers),
                           modelica_dir=args.modelica_dir, duration=args.duration,
                           effects=_effect_ids(args.effects), baseline=_baseline(args, scenario),
                           encoder=args.encoder)
    print(loop.history_table(history))
    print(f"history -> {Path(args.out) / 'history.csv'}, plot -> {Path(args.out) / 'history.png'}")
    return 0


def _cmd_effects(args: argparse.Namespace) -> int:
    effects = lib("twin.effects")
    if args.write_candidates:
        for base in effects.BASE_MODELS:
            model, path = effects.write_variant(effects.candidates_source(base), args.modelica_dir)
            print(f"{model} -> {path}")
        return 0
    for e in effects.CATALOGUE.values():
        fit = ", ".join(f"{p.name} [{p.lower:g}, {p.upper:g}]" for p in e.fit)
        print(f"{e.id:<24} {e.component:<40} fits: {fit}")
    return 0


def _loop_arguments(p: argparse.ArgumentParser, *, out: bool, several: bool = False) -> None:
    p.add_argument("scenario", help="scenario file (its model and calibrated parameters)")
    p.add_argument("--measurements", required=True, help="measurement file (HDF5 or CSV + sidecar)")
    if several:
        p.add_argument("--record", action="append",
                       help="record name, repeatable: --record steady --record runup (default: the first); the "
                            "effects are fitted on the first steady record and must hold on the others")
        p.add_argument("--all-records", action="store_true", help="every record of the file")
    else:
        p.add_argument("--record", help="record name (default: the first)")
    p.add_argument("--duration", type=float, default=2.0, help="seconds of the record compared (default: 2)")
    p.add_argument("--baseline", type=Path, metavar="FILE",
                   help="measurement file of the gearbox as the scenario's model was calibrated on it (before the "
                        "effect sought): the model's discrepancy on it is taken out of the compared levels first")
    p.add_argument("--baseline-record", action="append", metavar="NAME",
                   help="record of --baseline, repeatable (default: those named like --record); a further "
                        "steady record at the same operating point is a repeat of the healthy gearbox: what the "
                        "two differ by raises the threshold of a line finding there")
    p.add_argument("--no-encoder", dest="encoder", action="store_false",
                   help="compare the casing channel alone, not the records' pinion encoder angle as well "
                        "(default: both, where every record has an angle encoder)")
    if out:
        p.add_argument("--out", required=True, help="output directory")
        p.add_argument("--modelica-dir", type=Path, default=None,
                       help="Modelica root the variant is written to (default: the repository's modelica/)")
