"""Command-line shell ``twin``: build, inspect, simulate, demo.

The CLI only parses arguments and prints; all work lives in the library.
Library modules are imported inside each handler so ``twin --help`` does not
pay for numpy, fmpy or torch.
"""
from __future__ import annotations

import argparse
import importlib
import math
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType

from twin.errors import ParameterError, TwinError, TwinWarning, WorkerCrashError

DEFAULT_MODEL = "GearTwin.Gearbox21"
#: Measured natural frequencies [Hz] of the test rig (paper, Table 2).
MEASURED_MODES_HZ = (22.0, 87.0, 218.0, 430.0, 512.0, 767.0, 1248.0, 1927.0)


def _lib(name: str) -> ModuleType:
    # Resolved through sys.modules at call time, so tests can substitute a module.
    return importlib.import_module(name)


def parse_assignments(tokens: Sequence[str] | None, option: str) -> dict[str, str]:
    """Parse ``NAME=VALUE`` tokens into ``{name: text}``.

    The text is converted to the variable's type by the FMU (a number, ``true``/``false``, a
    string, an enumeration item by name), which refuses values that do not fit, by name.

    Raises
    ------
    ParameterError
        Missing ``=``, empty or blank-containing name, an empty value, or a name given twice;
        the message names the token.
    """
    out: dict[str, str] = {}
    for token in tokens or ():
        name, sep, text = token.partition("=")
        name = name.strip()
        if not sep or not name or any(c.isspace() for c in name):
            raise ParameterError(f"bad {option} '{token}': expected NAME=VALUE")
        if not text:
            raise ParameterError(f"bad {option} '{token}': no value after '='")
        if name in out:
            raise ParameterError(f"bad {option} '{token}': '{name}' given more than once")
        out[name] = text
    return out


def _numbers(assignments: dict[str, str], option: str) -> dict[str, float]:
    """``NAME=VALUE`` texts that must be finite numbers (build options), as floats."""
    out = {}
    for name, text in assignments.items():
        try:
            value = float(text)
        except ValueError:
            raise ParameterError(f"bad {option} '{name}={text}': '{text}' is not a number") from None
        if not math.isfinite(value):
            raise ParameterError(f"bad {option} '{name}={text}': value must be finite")
        out[name] = value
    return out


def _cmd_build(args: argparse.Namespace) -> int:
    fmu_build = _lib("fmu_build")
    # FMI 3.0 builds go to their own directory by default, so that they never replace the FMI 2.0 ones
    out = Path(args.out) if args.out else Path("build") / ("fmi3" if args.fmi == 3 else "")
    if args.fmi == 3 and not args.out:
        out.parent.mkdir(exist_ok=True)
    sets = _numbers(parse_assignments(args.set, "--set"), "--set")
    for model in args.models or [DEFAULT_MODEL]:
        options = {"fmi_version": 3} if args.fmi == 3 else {}
        if sets:
            path = _lib("twin.variants").build_variant(model, sets, modelica_dir=Path(args.modelica_dir),
                                                       out_dir=out, step_size=args.step_size,
                                                       force=args.force, **options)
        else:
            path = fmu_build.build_fmu(model, Path(args.modelica_dir), out, step_size=args.step_size,
                                       force=args.force, **options)
        print(path)
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    fmu = _lib("twin.fmu")
    print(fmu.describe(Path(args.fmu)))
    if args.measurements:
        return _info_against_measurements(args)
    if not args.modes:
        return 0                       # fast by default: no linearisation
    if not fmu.is_gearbox_model(Path(args.fmu)):
        return _info_model_modes(args)  # the paper's Table 2 belongs to the gearbox models only
    freqs = _lib("twin.linearize").natural_frequencies(Path(args.fmu), n=len(MEASURED_MODES_HZ))
    print()
    print("natural frequencies (linearised model vs. measured, paper Table 2)")
    print(f"{'mode':>4}  {'model [Hz]':>11}  {'measured [Hz]':>13}  {'diff [%]':>8}")
    for i, measured in enumerate(MEASURED_MODES_HZ):
        if i < len(freqs):
            model = float(freqs[i])
            print(f"{i + 1:>4}  {model:>11.1f}  {measured:>13.0f}  "
                  f"{100.0 * (model - measured) / measured:>+8.1f}")
        else:
            print(f"{i + 1:>4}  {'-':>11}  {measured:>13.0f}  {'-':>8}")
    return 0


def _info_model_modes(args: argparse.Namespace, n: int = 8) -> int:
    """``twin info FMU --modes`` for a model other than the gearbox: its lowest natural frequencies."""
    freqs = _lib("twin.linearize").natural_frequencies(Path(args.fmu), n=n)
    print()
    print("natural frequencies (linearised model)")
    print(f"{'mode':>4}  {'model [Hz]':>11}")
    for i, f in enumerate(freqs):
        print(f"{i + 1:>4}  {float(f):>11.4g}")
    return 0


def _info_against_measurements(args: argparse.Namespace) -> int:
    """``twin info FMU --measurements M``: the linearised model's modes against a record's."""
    import numpy as np

    survey = _lib("twin.modes").survey_file(Path(args.measurements), args.record)
    measured = survey.frequencies(min_confidence=args.min_confidence)
    if measured.size == 0:
        raise _lib("twin.errors").MeasurementError(
            str(args.measurements), args.record, f"no mode with confidence >= {args.min_confidence} to compare with")
    from scipy.optimize import linear_sum_assignment

    freqs = np.asarray(_lib("twin.linearize").natural_frequencies(Path(args.fmu), n=measured.size + 4), float)
    partner: dict[int, int] = {}
    if freqs.size:
        # one-to-one, least total |ln(f_model / f_measured)|; a model with fewer modes leaves some unmatched
        rows, cols = linear_sum_assignment(np.abs(np.log(freqs[None, :] / measured[:, None])))
        partner = dict(zip(rows.tolist(), cols.tolist()))
    confidence = {m.frequency: m.confidence for m in survey.modes}
    print()
    print(f"natural frequencies: linearised model vs. {args.measurements} ({survey.method}, "
          f"{len(measured)} mode(s) with confidence >= {args.min_confidence:g})")
    print(f"{'mode':>4}  {'measured [Hz]':>13}  {'confidence':>10}  {'model [Hz]':>11}  {'diff [%]':>8}")
    diffs = []
    for i, m in enumerate(measured):
        conf = confidence.get(float(m), float("nan"))
        if i not in partner:
            print(f"{i + 1:>4}  {m:>13.1f}  {conf:>10.2f}  {'-':>11}  {'-':>8}")
            continue
        model = float(freqs[partner[i]])
        diffs.append(abs(model - m) / m)
        print(f"{i + 1:>4}  {m:>13.1f}  {conf:>10.2f}  {model:>11.1f}  {100.0 * (model - m) / m:>+8.1f}")
    if diffs:
        print(f"mean |diff| over {len(diffs)} matched mode(s): {100 * float(np.mean(diffs)):.1f} %")
    return 0


def _ssp_or_fmu(path: str, parameters: dict) -> tuple[Path, dict]:
    """An .ssp gives its FMU and its bound parameter values, which the command line's override."""
    if path.endswith(".ssp"):
        system = _lib("twin.ssp").read_ssp(Path(path))
        return system.fmu, {**system.parameters, **parameters}
    return Path(path), parameters


def _add_fmpy_simulate_options(p: argparse.ArgumentParser) -> None:
    """The options of ``fmpy simulate``, spelled as fmpy spells them."""
    g = p.add_argument_group("fmpy's options", "accepted as `fmpy simulate` spells them (--output-file is --output)")
    g.add_argument("--start-values", nargs="+", metavar="NAME VALUE",
                   help="name-value pairs of start values of parameters and inputs")
    g.add_argument("--input-file", help="CSV of inputs over time, fmpy's format: time first, one column per input "
                                        "(continuous inputs interpolated linearly, others held)")
    g.add_argument("--output-variables", nargs="+", metavar="NAME", help="variables to record (default: every output)")
    g.add_argument("--show-plot", action="store_true",
                   help="plot the recorded variables (at most 12) to <output>.png")
    g.add_argument("--validate", action="store_true", help="validate the FMU before simulating it")


def _fmpy_simulate_values(args: argparse.Namespace, parameters: dict, outputs: list | None) -> tuple[dict, list | None]:
    """Merge fmpy's --start-values and --output-variables into the twin's own options."""
    values = args.start_values or []
    if len(values) % 2:
        raise ParameterError(f"--start-values takes NAME VALUE pairs, got {len(values)} words: {' '.join(values)}")
    pairs = parse_assignments([f"{n}={v}" for n, v in zip(values[::2], values[1::2])], "--start-values")
    twice = sorted(set(pairs) & set(parameters))
    if twice:
        raise ParameterError(f"{', '.join(map(repr, twice))} given both by --param and --start-values")
    if args.output_variables:
        outputs = [*(outputs or []), *(n for n in args.output_variables if n not in (outputs or []))]
    return {**parameters, **pairs}, outputs


def _simulate_in_child(args: argparse.Namespace, fmu: Path, options: dict, target: Path) -> str:
    results = _lib("twin.results")
    if args.input_file:
        inputs_lib = _lib("twin.inputs")
        result = inputs_lib.simulate_with_inputs(fmu, inputs_lib.InputTable.read(args.input_file), **options)
    else:
        result = _lib("twin.fmu").simulate_fmu(fmu, **options)
    load = options["inputs"].get("load_torque")     # text from --input, taken as a number by the FMU
    _lib("twin.plausibility").check_result(result, load=float(load) if load is not None else None,
                                           constant_inputs=not args.input_file)
    written = results.write_result(result, target)
    lines = []
    if args.show_plot:
        channels = list(result.signals)[:12]
        png = _lib("twin.plotting").plot_time(result, channels, Path(written).with_suffix(".png"),
                                              float(result.time[0]), float(result.time[-1]), title=result.model_name)
        lines.append(f"plot of {len(channels)} channel(s) -> {png}")
    n = len(result.time)
    span = f"t=[{result.time[0]:.6g}, {result.time[-1]:.6g}] s" if n else "no samples"
    lines.append(f"wrote {written}: {n} samples x {len(result.signals)} channels, "
                 f"{span}, {result.sample_rate:.6g} Hz")
    if result.ended_by_fmu:
        lines.append(f"the FMU ended the run itself: {result.end_reason}")
    return "\n".join(lines)


def _cmd_simulate(args: argparse.Namespace) -> int:
    given = parse_assignments(args.param, "--param")
    inputs = parse_assignments(args.input, "--input")
    outputs = [s.strip() for s in args.outputs.split(",") if s.strip()] if args.outputs else None
    parameters, outputs = _fmpy_simulate_values(args, given, outputs)
    results = _lib("twin.results")
    # Reject a bad output path, bad times and names before a possibly long simulation, not after it.
    target = results.check_output_path(args.output)
    fmu, parameters = _ssp_or_fmu(args.fmu, parameters)
    checks = _lib("twin.checks")
    checks.check_times(args.start_time, args.stop_time, args.output_interval,
                       n_channels=len(outputs) if outputs else None, fmu=fmu)
    checks.check_assignments(fmu, given, inputs, values=parameters)
    if args.validate:
        problems = _lib("twin.fmu").validate(fmu)
        if problems:
            raise _lib("twin.errors").FMUError(f"{fmu} is not valid ({len(problems)} problem(s)):\n  "
                                                + "\n  ".join(problems))
    options = dict(stop_time=args.stop_time, start_time=args.start_time, output_interval=args.output_interval,
                   outputs=outputs, parameters=parameters, inputs=inputs, progress=not args.no_progress)
    # the FMU runs in a child process: a crash inside it is reported, not fatal to the CLI
    text, notes = _lib("twin.isolation").run_isolated(_recording_warnings, _simulate_in_child, args, fmu, options,
                                                      target, what=f"FMU {fmu}", timeout=args.timeout)
    _print_warnings(notes)
    print(text)
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    _lib("twin.demo").run_demo(Path(args.out), stop_time=args.stop_time, rig_records=args.rig_records,
                               calibration_records=args.calibration_records,
                               hidden_effect_records=args.hidden_effect_records)
    return 0


def _cmd_schema(args: argparse.Namespace) -> int:
    print(_lib("twin.scenario").schema_json())
    return 0


def _run_in_child(scenario, out: Path, progress: bool, resume: bool) -> tuple[str, int]:
    if scenario.degradation is not None:
        run = _lib("twin.degradation_run").run_degradation(scenario, out, progress=progress, resume=resume)
        if not run.stages:
            return f"{scenario.name}: interrupted before the first stage; nothing written", 130
        where = out if run.complete else _lib("twin._atomic").partial_path(out)
        state = "complete" if run.complete else "not complete, kept for --resume"
        return f"{scenario.name}: {len(run.stages)} stages ({state}), {run.summary()} -> {where}", 0 if run.complete else 130
    rec = _lib("twin.orchestrator").run_scenario(scenario, out, progress=progress)
    state = ("complete" if rec.complete and not rec.result.ended_by_fmu
             else f"ended by the FMU: {rec.result.end_reason}" if rec.complete
             else f"interrupted; partial result kept beside, {out} unchanged")
    return (f"{scenario.name}: {rec.result.time.size} samples of {len(rec.result.signals)} channels "
            f"({state}) -> {rec.path}", 0 if rec.complete else 130)


def _cmd_run(args: argparse.Namespace) -> int:
    scenarios = _lib("twin.scenario")
    if args.scenario.endswith(".ssp"):       # an SSP runs as it is, over its default experiment
        scenario = scenarios.scenario_from_ssp(Path(args.scenario), args.stop_time)
    else:
        scenario = scenarios.load_scenario(Path(args.scenario))
    if args.stop_time is not None:
        scenario = _lib("twin.checks").override_stop_time(scenario, args.stop_time)
    out = Path(args.output) if args.output else Path(f"{scenario.name}.h5")
    _lib("twin.results").check_output_path(out)
    if scenario.degradation is not None:      # before its FMU is built: a degradation run is HDF5 only
        _lib("twin.results").check_hdf5_path(out, "a degradation run")
    if args.resume and scenario.degradation is None:
        raise _lib("twin.errors").ResumeError("--resume continues degradation runs only; a plain run starts "
                                              "from its start time (its partial output is kept for inspection)")
    scenario.fmu_path()            # build or find the FMU here, so its errors are reported plainly
    (text, code), notes = _lib("twin.isolation").run_isolated(_recording_warnings, _run_in_child, scenario, out,
                                                              not args.no_progress, args.resume,
                                                              what=f"scenario {scenario.name}", timeout=args.timeout)
    _print_warnings(notes)
    print(text)
    return code


def _cmd_archive(args: argparse.Namespace) -> int:
    scenario = _lib("twin.scenario").load_scenario(Path(args.scenario))
    if scenario.archive is None:
        raise _lib("twin.errors").ScenarioError([(str(args.scenario), "archive", "the scenario has no archive block")])
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
    archive = _lib("twin.archive").build_archive(scenario, out, progress=not args.no_progress)
    print(f"{scenario.name}: {archive.labels.size} records in {len(archive.stages) - 1} stages "
          f"({archive.damage_kind}) -> {out}")
    return 0


def _cmd_import(args: argparse.Namespace) -> int:
    out = _lib("twin.measurements").import_csv(Path(args.csv), Path(args.out),
                                               sidecar=Path(args.sidecar) if args.sidecar else None,
                                               **_import_fmu_options(args))
    mset = _lib("twin.measurements").load_measurements(out)
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


def _cmd_calibrate(args: argparse.Namespace) -> int:
    scenario = _lib("twin.scenario").load_scenario(Path(args.scenario))
    if args.workers is not None:
        scenario = scenario.with_overrides(executor={"type": "local", "workers": args.workers})
    report = _lib("twin.calibration.run").run_calibration(scenario, Path(args.measurements), Path(args.out),
                                                          progress=not args.no_progress, seed=args.seed,
                                                          resume=args.resume, modes_from=args.modes_from,
                                                          pairing=args.pairing)
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
    scenario = _lib("twin.scenario").load_scenario(Path(args.scenario))
    sens = _lib("twin.calibration.run").scenario_sensitivity(
        scenario, Path(args.measurements) if args.measurements else None, modes_from=args.modes_from,
        n_modes=args.modes, executor=_executor(args.workers), pairing=args.pairing)
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
    p.add_argument("--modes-from", metavar="RECORD", help="run-up or hammer record of the measured modes")
    p.add_argument("--modes", type=int, default=8,
                   help="without measurements: the model's first N visible modes (default: 8)")
    p.add_argument("--workers", type=_positive_int, help="local worker processes (default: one)")
    p.add_argument("--json", type=Path, help="write the sensitivities and the choice here")
    _add_pairing_option(p)
    p.set_defaults(handler=_cmd_sensitivity)


def _add_pairing_option(p) -> None:
    p.add_argument("--pairing", choices=("frequency", "shape"),
                   help="pair measured with model modes by frequency (the nearest visible model mode within 15 %%; "
                        "default) or by frequency, shape at the sensors and reach; overrides calibration.pairing")


def _cmd_compare(args: argparse.Namespace) -> int:
    scenario = _lib("twin.scenario").load_scenario(Path(args.scenario))
    comp = _lib("twin.compare").compare(scenario, Path(args.measurements), Path(args.out), record=args.record,
                                        duration=args.duration)
    print(f"log-spectral distance {comp.lsd_db:.2f} dB; f1 {comp.f1:.4f}; f2 {comp.f2:.4f}")
    if not comp.findings:
        print("no localised discrepancy above the thresholds: nothing appears to be missing")
    for i, f in enumerate(comp.findings, 1):
        print(f"  {i:2d}. [{f.kind}] {f.description}  ({100 * f.share:.0f} % of the error)")
    print(f"report -> {Path(args.out) / 'compare.html'}")
    return 0


def _executor(workers):
    if workers is None:
        return None
    return _lib("twin.executor").make_executor({"type": "local", "workers": workers})


def _effects_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--effects", metavar="ID,ID", help="the candidate effects tried, comma-separated catalogue ids "
                                                      "(default: every one the model lacks; see twin effects)")


def _effect_ids(text: str | None) -> list[str] | None:
    """``--effects a,b``: the catalogue ids tried (None: all); unknown ids are refused by the loop."""
    if text is None:
        return None
    ids = [e.strip() for e in text.split(",") if e.strip()]
    if not ids:
        raise _lib("twin.errors").ParameterError(f"--effects names no effect: {text!r}")
    return ids


def _cmd_diagnose(args: argparse.Namespace) -> int:
    scenario = _lib("twin.scenario").load_scenario(Path(args.scenario))
    diag = _lib("twin.effects.loop").diagnose_scenario(scenario, Path(args.measurements), record=args.record,
                                                       all_records=args.all_records, json_path=args.json, executor=_executor(args.workers),
                                                       duration=args.duration, effects=_effect_ids(args.effects))
    print(diag.table())
    for c in diag.candidates[:1]:
        for e in c.evidence:
            print(f"  explains [{e.kind}] {e.finding}: {e.reason}")
    if args.json:
        print(f"diagnosis -> {args.json}")
    return 0


def _cmd_add_effect(args: argparse.Namespace) -> int:
    scenario = _lib("twin.scenario").load_scenario(Path(args.scenario))
    add = _lib("twin.effects.loop").add_effect(scenario, Path(args.measurements), args.effect, Path(args.out),
                                               record=args.record, modelica_dir=args.modelica_dir,
                                               duration=args.duration)
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
    scenario = _lib("twin.scenario").load_scenario(Path(args.scenario))
    loop = _lib("twin.effects.loop")
    history = loop.improve(scenario, Path(args.measurements), Path(args.out), record=args.record,
                           all_records=args.all_records, diagnosis=args.from_diagnosis, max_steps=args.max_steps, executor=_executor(args.workers),
                           modelica_dir=args.modelica_dir, duration=args.duration,
                           effects=_effect_ids(args.effects))
    print(loop.history_table(history))
    print(f"history -> {Path(args.out) / 'history.csv'}, plot -> {Path(args.out) / 'history.png'}")
    return 0


def _cmd_effects(args: argparse.Namespace) -> int:
    effects = _lib("twin.effects")
    if args.write_candidates:
        for base in effects.BASE_MODELS:
            model, path = effects.write_variant(effects.candidates_source(base), args.modelica_dir)
            print(f"{model} -> {path}")
        return 0
    for e in effects.CATALOGUE.values():
        fit = ", ".join(f"{p.name} [{p.lower:g}, {p.upper:g}]" for p in e.fit)
        print(f"{e.id:<24} {e.component:<40} fits: {fit}")
    return 0


def _cmd_modes(args: argparse.Namespace) -> int:
    from twin._atomic import check_parent
    modes = _lib("twin.modes")
    for path in (args.json, args.plot):           # refuse a bad output path before the analysis
        if path is not None:
            check_parent(path)
    survey = modes.survey_file(Path(args.measurements), args.record, channels=args.channel, fmin=args.fmin,
                               fmax=args.fmax, resolution=args.resolution)
    print(modes.survey_table(survey, args.min_confidence))
    if args.json:
        modes.write_survey_json(survey, args.json, file=str(args.measurements), record=args.record,
                                min_confidence=args.min_confidence)
        print(f"modes -> {args.json}")
    if args.plot:
        _lib("twin.plotting").plot_modal_survey(survey, args.plot)
        print(f"Campbell diagram -> {args.plot}")
    return 0


def _add_modes_parser(sub) -> None:
    p = sub.add_parser("modes", help="natural frequencies of a run-up or hammer record (orders and fixed lines "
                                     "set apart)")
    p.add_argument("measurements", metavar="MEAS", help="measurement HDF5 (or CSV + sidecar)")
    p.add_argument("--record", help="record name (default: the first)")
    p.add_argument("--channel", action="append", help="vibration channel (repeatable; default: every one)")
    p.add_argument("--fmin", type=float, help="lowest frequency [Hz] (default: 4 bins)")
    p.add_argument("--fmax", type=float, help="highest frequency [Hz] (default: min(0.4 fs, 10 kHz))")
    p.add_argument("--resolution", type=float, help="bin spacing [Hz] (default: from the record length)")
    p.add_argument("--min-confidence", type=float, default=0.3,
                   help="confidence a mode needs to be used for calibration (default: 0.3)")
    p.add_argument("--json", type=Path, help="write the modes, lines and orders here")
    p.add_argument("--plot", type=Path, help="write a Campbell diagram (PNG) here")
    p.set_defaults(handler=_cmd_modes)


def _cmd_export_ssp(args: argparse.Namespace) -> int:
    fmu = Path(args.fmu)
    values: dict = {}
    for f in args.parameters or ():
        values.update(_lib("twin.scenario").read_parameter_file(Path(f), fmu=fmu))
    values.update(parse_assignments(args.param, "--param"))
    out = _lib("twin.ssp").write_ssp(fmu, values, Path(args.out), name=args.name,
                                     description=args.description or "")
    print(f"wrote {out}: {fmu.name} bound to {len(values)} parameter value(s)")
    return 0


def _cmd_validate(args: argparse.Namespace) -> int:
    path = Path(args.file)
    problems = (_lib("twin.ssp").validate_ssp(path) if path.suffix == ".ssp"
                else _lib("twin.fmu").validate(path))
    if not problems:
        print("No problems found.")
        return 0
    print(f"{len(problems)} problem{'s were' if len(problems) != 1 else ' was'} found:")
    for message in problems:
        print()
        print(message)
    return 1


def _add_ssp_commands(sub) -> None:
    p = sub.add_parser("validate", help="validate an FMU (like fmpy validate) or an .ssp (SSP 1.0 schemas, its FMU)")
    p.add_argument("file", metavar="FMU|SSP", help="path to the .fmu or .ssp file")
    p.set_defaults(handler=_cmd_validate)

    p = sub.add_parser("export-ssp", help="pack an FMU and a parameter set into a standard SSP package (.ssp)")
    p.add_argument("fmu", metavar="FMU", help="path to the .fmu file")
    p.add_argument("--parameters", action="append", metavar="P.json|P.ssv",
                   help="parameter set (JSON or SSP .ssv, converted to the FMU's units); repeatable, later win")
    p.add_argument("--param", action="append", metavar="NAME=VALUE", help="set a parameter (repeatable; wins)")
    p.add_argument("--out", required=True, help="the .ssp file to write")
    p.add_argument("--name", help="name of the system and parameter set (default: the file name)")
    p.add_argument("--description", help="description written to the .ssd and .ssv")
    p.set_defaults(handler=_cmd_export_ssp)


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
    if out:
        p.add_argument("--out", required=True, help="output directory")
        p.add_argument("--modelica-dir", type=Path, default=None,
                       help="Modelica root the variant is written to (default: the repository's modelica/)")


def _positive_seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of seconds") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive finite number of seconds, got '{text}'")
    return value


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got '{text}'")
    return value


def build_parser() -> argparse.ArgumentParser:
    """Return the ``twin`` argument parser (one sub-parser per command)."""
    parser = argparse.ArgumentParser(
        prog="twin", description="FMU co-simulation digital twin of a spur gearbox.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("build", help="export Modelica models to FMUs")
    p.add_argument("models", nargs="*", metavar="MODEL",
                   help=f"fully qualified model name(s) (default: {DEFAULT_MODEL})")
    p.add_argument("--modelica-dir", default="modelica", help="Modelica source directory")
    p.add_argument("--out", help="output directory for the .fmu files (default: build, or build/fmi3 with --fmi 3)")
    p.add_argument("--step-size", type=float, default=5e-6,
                   help="fixed solver step size [s] (default: 5e-6)")
    p.add_argument("--force", action="store_true", help="rebuild even if up to date")
    p.add_argument("--fmi", type=int, choices=(2, 3), default=2,
                   help="FMI version of the FMU: 2 (FMI 2.0, default) or 3 (FMI 3.0 Co-Simulation and Model Exchange)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="build option (repeatable): a structural parameter such as z1, z2, n_profile, or a "
                        "parameter default; a changed gear geometry also recomputes the default k_pair")
    p.set_defaults(handler=_cmd_build)

    p = sub.add_parser("info", help="describe an FMU (fast); --modes or --measurements add its natural frequencies")
    p.add_argument("fmu", metavar="FMU", help="path to the .fmu file")
    p.add_argument("--modes", action="store_true",
                   help="linearise: the natural frequencies, compared with the paper's Table 2 for the gearbox models")
    p.add_argument("--measurements", metavar="MEAS",
                   help="linearise and compare with the modes of a record (run-up or hammer test, see twin modes)")
    p.add_argument("--record", help="record of --measurements (default: the first)")
    p.add_argument("--min-confidence", type=float, default=0.3,
                   help="confidence a measured mode needs to be compared (default: 0.3)")
    p.add_argument("--no-modes", action="store_true", help=argparse.SUPPRESS)   # the default now; kept for scripts
    p.set_defaults(handler=_cmd_info)

    p = sub.add_parser("simulate", help="run an FMU (or an .ssp with one FMU) and write its outputs")
    p.add_argument("fmu", metavar="FMU", help="path to the .fmu file, or an .ssp with one FMU component and "
                                              "its parameter bindings")
    p.add_argument("--stop-time", type=float, help="stop time [s] (default: the model's default experiment)")
    p.add_argument("--start-time", type=float, help="start time [s] (default: the model's default experiment, else 0)")
    p.add_argument("--output-interval", type=float,
                   help="output sample interval [s] (default: the model's default experiment step)")
    p.add_argument("--output", "--output-file", default="out.h5", help="result file, .h5/.hdf5 or .csv")
    p.add_argument("--outputs", help="comma-separated variables to record (default: every output)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="set a parameter or start value (repeatable): a number, true/false, a string, "
                        "an enumeration item")
    p.add_argument("--input", action="append", metavar="NAME=VALUE",
                   help="hold an input at a constant value (repeatable)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.add_argument("--timeout", type=_positive_seconds, metavar="SECONDS",
                   help="stop the FMU and report an error if the run takes longer")
    _add_fmpy_simulate_options(p)
    p.set_defaults(handler=_cmd_simulate)

    p = sub.add_parser("run", help="run a scenario file through the co-simulation orchestrator")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml file, or an .ssp (its FMU, bindings and "
                                                        "default experiment)")
    p.add_argument("--output", help="result file, .h5/.hdf5 or .csv (default: <scenario name>.h5)")
    p.add_argument("--stop-time", type=float, help="override the scenario's stop time [s]")
    p.add_argument("--resume", action="store_true", help="degradation runs: continue from the last completed stage")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.add_argument("--timeout", type=_positive_seconds, metavar="SECONDS",
                   help="stop the FMU and report an error if the run takes longer")
    p.set_defaults(handler=_cmd_run)

    p = sub.add_parser("archive", help="simulate the labelled degradation archive of a scenario")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml with degradation and archive blocks")
    p.add_argument("--out", help="archive HDF5 file (default: <scenario name>_archive.h5)")
    p.add_argument("--records-per-stage", type=int, help="override archive.records_per_stage")
    p.add_argument("--workers", type=_positive_int, help="local worker processes (default: one per core)")
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

    p = sub.add_parser("calibrate", help="calibrate a scenario's FMU to measurements (NSGA-II or MOGOA)")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario .yaml with a calibration block")
    p.add_argument("--measurements", required=True, help="measurement HDF5 (or CSV + sidecar)")
    p.add_argument("--out", default="calibration", help="output directory (default: calibration)")
    p.add_argument("--workers", type=_positive_int, help="local worker processes for the evaluations")
    p.add_argument("--seed", type=int, help="override the scenario's seed")
    p.add_argument("--resume", action="store_true", help="continue from <out>/checkpoint.json")
    p.add_argument("--modes-from", metavar="RECORD",
                   help="read the measured modes from this run-up or hammer record (see twin modes); without a "
                        "calibration block the parameters are chosen automatically")
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

    p = sub.add_parser("diagnose", help="rank the catalogue effects the model may be missing, by trying each")
    _loop_arguments(p, out=False, several=True)
    p.add_argument("--json", type=Path, help="write the diagnosis here")
    p.add_argument("--workers", type=_positive_int, help="local worker processes (default: one per core)")
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
    p.add_argument("--workers", type=_positive_int, help="local worker processes (default: one per core)")
    _effects_argument(p)
    p.set_defaults(handler=_cmd_improve)

    p = sub.add_parser("effects", help="list the effect catalogue")
    p.add_argument("--write-candidates", action="store_true",
                   help="regenerate GearTwin.Variants.Gearbox21Candidates from the catalogue")
    p.add_argument("--modelica-dir", type=Path, default=None)
    p.set_defaults(handler=_cmd_effects)

    _add_ssp_commands(sub)

    from twin.transfer.cli import add_subcommands as add_transfer
    add_transfer(sub)

    from twin.rul import add_subcommands as add_rul
    add_rul(sub)

    from twin.pipeline import add_subcommands as add_pipeline
    add_pipeline(sub)

    p = sub.add_parser("schema", help="print the JSON Schema of scenario files")
    p.set_defaults(handler=_cmd_schema)

    p = sub.add_parser("demo", help="build, simulate and plot the reference gearbox")
    p.add_argument("--out", default="demo_out", help="output directory (default: demo_out)")
    p.add_argument("--stop-time", type=float, default=10.0,
                   help="simulated time [s] (default: 10)")
    p.add_argument("--rig-records", nargs="+", default=(), metavar="FILE",
                   help="pitting records of independent simulators (python -m rigs.lumped target ...) for step 9")
    p.add_argument("--calibration-records", nargs=2, default=(), metavar=("STEADY", "RUNUP"),
                   help="a steady and a run-up record of an independent simulator (python -m rigs.pedestal ...) "
                        "for step 6")
    p.add_argument("--hidden-effect-records", nargs=2, default=(), metavar=("STEADY", "RUNUP"),
                   help="a steady and a run-up record of step 6's gearbox with one of the rig's own effects "
                        "(python -m rigs.pedestal ... --effect casing_resonance) for step 8")
    p.set_defaults(handler=_cmd_demo)
    return parser


def _os_error_message(exc: OSError) -> str:
    """One line for an OS error on a path: what went wrong and which path."""
    what = (exc.strerror or str(exc)).rstrip(".")
    what = what[:1].lower() + what[1:]
    if exc.filename is not None and exc.filename2 is not None:
        return f"{what}: '{exc.filename}' -> '{exc.filename2}'"
    if exc.filename is not None:
        return f"{what}: '{exc.filename}'"
    return what


def _add_debug_option(parser: argparse.ArgumentParser) -> None:
    """``--debug`` on the main parser and on every sub-command (so it may come anywhere)."""
    parser.add_argument("--debug", action="store_true",
                        help="show the Python traceback of an error instead of one line")
    for action in parser._subparsers._group_actions if parser._subparsers else ():
        for sub in getattr(action, "choices", {}).values():
            sub.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                             help="show the Python traceback of an error instead of one line")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; return the exit code.

    0 success; 2 usage error or bad input (:class:`TwinError`, an OS error on a path: one
    ``twin: error:`` line naming the value or the path); 130 interrupted by Ctrl-C (or SIGTERM);
    1 anything else, which is a bug: one line naming the exception and a hint to re-run with
    ``--debug`` (or ``TWIN_DEBUG=1``) for the traceback.
    """
    import os

    from twin import _interrupt

    parser = build_parser()
    _add_debug_option(parser)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help or a usage error; argparse already printed
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    debug = bool(getattr(args, "debug", False)) or os.environ.get("TWIN_DEBUG", "") not in ("", "0")
    _interrupt.install()
    try:
        with warnings.catch_warnings():
            _one_line_warnings()          # set before the FMU's child process forks, which inherits it
            code = args.handler(args)
    except KeyboardInterrupt:
        if debug:
            import traceback
            traceback.print_exc()
        print("twin: interrupted; results written before the interruption are unchanged", file=sys.stderr)
        return 130
    except TwinError as exc:
        if debug:
            raise
        if isinstance(exc, WorkerCrashError) and not getattr(args, "no_progress", True):
            print(file=sys.stderr)      # the dead process's progress bar may have left a line open
        print(f"twin: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        if debug:
            raise
        print(f"twin: error: {_os_error_message(exc)}", file=sys.stderr)
        return 2
    except MemoryError as exc:
        if debug:
            raise
        print(f"twin: error: out of memory{': ' + str(exc) if str(exc) else ''}", file=sys.stderr)
        return 2
    except Exception as exc:  # the last line of defence: a bug, reported in one line
        if debug:
            raise
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        print(f"twin: error: internal error {type(exc).__name__}{': ' + text if text else ''} "
              "(re-run with --debug for the traceback)", file=sys.stderr)
        return 1
    finally:
        interrupted = _interrupt.requested()
        _interrupt.uninstall()
    if interrupted:  # the request arrived where nothing checked it: still honoured
        print("twin: interrupted", file=sys.stderr)
        return 130
    return code


def _recording_warnings(fn, *args):
    """``fn(*args)`` with the library's warnings recorded: (its value, their messages).  Used in
    the child process that runs an FMU, whose own stderr the caller may not see."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", TwinWarning)
        value = fn(*args)
    return value, [str(w.message) for w in caught if issubclass(w.category, TwinWarning)]


def _print_warnings(notes) -> None:
    for note in notes:
        print(f"twin: warning: {note}", file=sys.stderr)


def _one_line_warnings() -> None:
    """Show the library's own warnings (:class:`TwinWarning`) as one line each, every time; any
    other warning as Python shows it.  Call inside ``warnings.catch_warnings()``."""
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, TwinWarning):
            print(f"twin: warning: {message}", file=sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)
    warnings.showwarning = show
    warnings.simplefilter("always", TwinWarning)


if __name__ == "__main__":
    sys.exit(main())
