"""``twin calibrate``, ``modes``, ``sensitivity`` and ``compare``: the model against measured modes
and spectra."""
from __future__ import annotations

import argparse
from pathlib import Path

from twin.commands.common import lib, local_executor, path_pair, positive_int


def add_subcommands(sub) -> None:
    """Register ``calibrate``, ``modes``, ``sensitivity`` and ``compare``."""
    p = sub.add_parser("calibrate", help="calibrate a scenario's FMU to measurements (NSGA-II or MOGOA)")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml with a calibration block")
    p.add_argument("--measurements", help="measurement HDF5 (or CSV + sidecar); without it the block's typed "
                                           "natural_frequencies alone, on the modes objective")
    p.add_argument("--out", default="calibration", help="output directory (default: calibration)")
    p.add_argument("--workers", type=positive_int, help="local worker processes for the evaluations")
    p.add_argument("--seed", type=int, help="override the scenario's seed")
    p.add_argument("--resume", action="store_true", help="continue from <out>/checkpoint.json")
    p.add_argument("--modes-from", metavar="RECORD[,RECORD...]", type=_record_list,
                   help="read the measured modes from this run-up or hammer record, or from several together "
                        "(comma-separated: a run-up and a hammer test per struck point; see twin modes); without "
                        "a calibration block the parameters are chosen automatically")
    p.add_argument("--foundation-from", metavar="RECORD",
                   help="hammer-test record of the foundation (casing root): its modes are left out of the "
                        "measured ones, as the paper does")
    p.add_argument("--path-from", metavar="RECORD=FORCE", type=path_pair, action="append",
                   help="a hammer record struck at a bearing housing and the model's bearing force its blow stands "
                        "for (e.g. hammer_pinion=bearing_force_input_y; repeat per record): the casing sensors then "
                        "read the model's bearing forces through the measured path (calibration.path_from)")
    p.add_argument("--face-contact-from", metavar="RECORD",
                   help="a steady record at the steady record's speed and another load: the flanks' lead mismatch "
                        "fitted to how the spectrum changes with load (calibration.face_contact_from)")
    _add_pairing_option(p)
    p.add_argument("--no-progress", action="store_true", help="quiet")
    p.set_defaults(handler=_cmd_calibrate)

    _add_modes_parser(sub)
    _add_sensitivity_parser(sub)

    p = sub.add_parser("compare", help="compare the model with a measurement and list where it fails")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml (FMU and parameters)")
    p.add_argument("--measurements", required=True, help="measurement HDF5 (or CSV + sidecar)")
    p.add_argument("--out", default="report", help="output directory (default: report)")
    p.add_argument("--record", help="record name (default: the first)")
    p.add_argument("--duration", type=float, help="use the last DURATION seconds of the record")
    p.set_defaults(handler=_cmd_compare)


def _cmd_calibrate(args: argparse.Namespace) -> int:
    scenario = lib("twin.scenario").load_scenario(Path(args.scenario))
    if args.workers is not None:
        scenario = scenario.with_overrides(executor={"type": "local", "workers": args.workers})
    measurements = Path(args.measurements) if args.measurements else None
    report = lib("twin.calibration.run").run_calibration(scenario, measurements, Path(args.out),
                                                          progress=not args.no_progress, seed=args.seed,
                                                          resume=args.resume, modes_from=args.modes_from,
                                                          pairing=args.pairing, visibility=args.visibility,
                                                          foundation_from=args.foundation_from,
                                                          path_from=dict(args.path_from) if args.path_from else None,
                                                          face_contact_from=args.face_contact_from)
    print(f"modes: {report.modes_source}")
    print(report.table())
    for n in report.notes:
        print(n)
    for w in report.warnings:
        print(f"warning: {w}")
    print(f"calibrated scenario -> {report.scenario_file} (parameters in calibrated.json and calibrated.ssv; "
          f"SSP package calibrated.ssp); "
          f"report -> {Path(args.out) / 'report.html'}")
    return 0


def _cmd_sensitivity(args: argparse.Namespace) -> int:
    from twin._atomic import atomic_path, check_parent
    if args.json is not None:
        check_parent(args.json)
    scenario = lib("twin.scenario").load_scenario(Path(args.scenario))
    sens = lib("twin.calibration.run").scenario_sensitivity(
        scenario, Path(args.measurements) if args.measurements else None, modes_from=args.modes_from,
        n_modes=args.modes, executor=local_executor(args.workers), pairing=args.pairing,
        visibility=args.visibility)
    print(sens.table())
    if args.json is not None:
        import json
        with atomic_path(args.json) as tmp:
            Path(tmp).write_text(json.dumps(sens.to_dict(), indent=2))
        print(f"sensitivities -> {args.json}")
    return 0


def _add_sensitivity_parser(sub) -> None:
    p = sub.add_parser("sensitivity", help="which parameters the measured modes identify (what parameters: auto "
                                           "calibrates), with bounds from physics")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml (model and parameters)")
    p.add_argument("--measurements", help="measurement HDF5 with the record the modes are read from")
    p.add_argument("--modes-from", metavar="RECORD[,RECORD...]", type=_record_list,
                   help="run-up or hammer record(s) of the measured modes, comma-separated")
    p.add_argument("--modes", type=int, default=8,
                   help="without measurements: the model's first N visible modes (default: 8)")
    p.add_argument("--workers", type=positive_int, help="local worker processes (default: one)")
    p.add_argument("--json", type=Path, help="write the sensitivities and the choice here")
    _add_pairing_option(p)
    p.set_defaults(handler=_cmd_sensitivity)


def _record_list(text: str):
    """``--modes-from``: one record name, or several comma-separated (a list)."""
    names = [n.strip() for n in text.split(",")]
    if not all(names):
        raise argparse.ArgumentTypeError(f"empty record name in {text!r}")
    return names[0] if len(names) == 1 else names


def _add_pairing_option(p) -> None:
    from twin.scenario_schema import VISIBILITY_RULES
    p.add_argument("--pairing", choices=("frequency", "shape"),
                   help="pair measured with model modes by frequency (the nearest visible model mode within 15 %%; "
                        "default) or by frequency, shape at the sensors and reach; overrides calibration.pairing")
    p.add_argument("--visibility", choices=VISIBILITY_RULES,
                   help="which model modes are pairing candidates: those the mesh shows at the sensor (mesh, the "
                        "default) or any of a run-up's forces (run-up); +dominant also counts a mode that dominates "
                        "a response at its own frequency; overrides calibration.visibility")


def _cmd_compare(args: argparse.Namespace) -> int:
    scenario = lib("twin.scenario").load_scenario(Path(args.scenario))
    comp = lib("twin.compare").compare(scenario, Path(args.measurements), Path(args.out), record=args.record,
                                        duration=args.duration)
    print(f"log-spectral distance {comp.lsd_db:.2f} dB; f1 {comp.f1:.4f}; f2 {comp.f2:.4f}")
    if not comp.findings:
        print("no localised discrepancy above the thresholds: nothing appears to be missing")
    for i, f in enumerate(comp.findings, 1):
        # a series in the envelope is measured there, not as a share of the spectral error
        where = "in the envelope" if f.kind == "envelope_line" else f"{100 * f.share:.0f} % of the error"
        print(f"  {i:2d}. [{f.kind}] {f.description}  ({where})")
    print(f"report -> {Path(args.out) / 'compare.html'}")
    return 0


def _cmd_modes(args: argparse.Namespace) -> int:
    from twin._atomic import check_parent
    modes = lib("twin.modes")
    for path in (args.json, args.plot):           # refuse a bad output path before the analysis
        if path is not None:
            check_parent(path)
    record = args.record[0] if args.record and len(args.record) == 1 else args.record
    survey = modes.survey_file(Path(args.measurements), record, channels=args.channel, fmin=args.fmin,
                               fmax=args.fmax, resolution=args.resolution, fdd=args.fdd, lscf=args.lscf)
    print(modes.survey_table(survey, args.min_confidence))
    if args.json:
        modes.write_survey_json(survey, args.json, file=str(args.measurements), record=record,
                                min_confidence=args.min_confidence)
        print(f"modes -> {args.json}")
    if args.plot:
        lib("twin.plotting").plot_modal_survey(survey, args.plot)
        print(f"Campbell diagram -> {args.plot}")
    return 0


def _add_modes_parser(sub) -> None:
    p = sub.add_parser("modes", help="natural frequencies of a run-up or hammer record (orders and fixed lines "
                                     "set apart)")
    p.add_argument("measurements", metavar="MEAS", help="measurement HDF5 (or CSV + sidecar)")
    p.add_argument("--record", action="append",
                   help="record name (default: the first); repeatable: --record runup --record hammer_a surveys "
                        "the records together, a mode seen in any of them being a mode of the structure")
    p.add_argument("--channel", action="append", help="vibration channel (repeatable; default: every one)")
    p.add_argument("--fmin", type=float, help="lowest frequency [Hz] (default: 4 bins)")
    p.add_argument("--fmax", type=float, help="highest frequency [Hz] (default: min(0.4 fs, 10 kHz))")
    p.add_argument("--resolution", type=float, help="bin spacing [Hz] (default: from the record length)")
    p.add_argument("--fdd", action=argparse.BooleanOptionalAction, default=None,
                   help="with two or more vibration channels, also read their cross-spectral matrix for close modes "
                        "of different shapes (frequency-domain decomposition; default: on)")
    p.add_argument("--lscf", action=argparse.BooleanOptionalAction, default=None,
                   help="fit the hammer records' FRFs (every struck point and channel) together by the poly-reference "
                        "LSCF method for modes whose humps overlap (default: off)")
    p.add_argument("--min-confidence", type=float, default=0.3,
                   help="confidence a mode needs to be used for calibration (default: 0.3)")
    p.add_argument("--json", type=Path, help="write the modes, lines and orders here")
    p.add_argument("--plot", type=Path, help="write a Campbell diagram (PNG) here")
    p.set_defaults(handler=_cmd_modes)
