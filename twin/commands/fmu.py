"""``twin build``, ``info``, ``simulate`` (with fmpy's options), ``validate`` and ``export-ssp``:
one FMU at a time."""
from __future__ import annotations

import argparse
from pathlib import Path

from twin.commands.common import (lib, numbers, parse_assignments, positive_seconds, print_warnings,
                                  recording_warnings)
from twin.errors import ParameterError

DEFAULT_MODEL = "GearTwin.Gearbox21"
#: Measured natural frequencies [Hz] of the test rig (paper, Table 2).
MEASURED_MODES_HZ = (22.0, 87.0, 218.0, 430.0, 512.0, 767.0, 1248.0, 1927.0)


def add_subcommands(sub) -> None:
    """Register ``build``, ``info`` and ``simulate``."""
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
    p.add_argument("--timeout", type=positive_seconds, metavar="SECONDS",
                   help="stop the FMU and report an error if the run takes longer")
    _add_fmpy_simulate_options(p)
    p.set_defaults(handler=_cmd_simulate)


def add_ssp_subcommands(sub) -> None:
    """Register ``validate`` and ``export-ssp``."""
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


def _cmd_build(args: argparse.Namespace) -> int:
    fmu_build = lib("fmu_build")
    # FMI 3.0 builds go to their own directory by default, so that they never replace the FMI 2.0 ones
    out = Path(args.out) if args.out else Path("build") / ("fmi3" if args.fmi == 3 else "")
    if args.fmi == 3 and not args.out:
        out.parent.mkdir(exist_ok=True)
    sets = numbers(parse_assignments(args.set, "--set"), "--set")
    for model in args.models or [DEFAULT_MODEL]:
        options = {"fmi_version": 3} if args.fmi == 3 else {}
        if sets:
            path = lib("twin.variants").build_variant(model, sets, modelica_dir=Path(args.modelica_dir),
                                                       out_dir=out, step_size=args.step_size,
                                                       force=args.force, **options)
        else:
            path = fmu_build.build_fmu(model, Path(args.modelica_dir), out, step_size=args.step_size,
                                       force=args.force, **options)
        print(path)
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    fmu = lib("twin.fmu")
    print(fmu.describe(Path(args.fmu)))
    if args.measurements:
        return _info_against_measurements(args)
    if not args.modes:
        return 0                       # fast by default: no linearisation
    if not fmu.is_gearbox_model(Path(args.fmu)):
        return _info_model_modes(args)  # the paper's Table 2 belongs to the gearbox models only
    freqs = lib("twin.linearize").natural_frequencies(Path(args.fmu), n=len(MEASURED_MODES_HZ))
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
    freqs = lib("twin.linearize").natural_frequencies(Path(args.fmu), n=n)
    print()
    print("natural frequencies (linearised model)")
    print(f"{'mode':>4}  {'model [Hz]':>11}")
    for i, f in enumerate(freqs):
        print(f"{i + 1:>4}  {float(f):>11.4g}")
    return 0


def _info_against_measurements(args: argparse.Namespace) -> int:
    """``twin info FMU --measurements M``: the linearised model's modes against a record's."""
    import numpy as np

    survey = lib("twin.modes").survey_file(Path(args.measurements), args.record)
    measured = survey.frequencies(min_confidence=args.min_confidence)
    if measured.size == 0:
        raise lib("twin.errors").MeasurementError(
            str(args.measurements), args.record, f"no mode with confidence >= {args.min_confidence} to compare with")
    from scipy.optimize import linear_sum_assignment

    freqs = np.asarray(lib("twin.linearize").natural_frequencies(Path(args.fmu), n=measured.size + 4), float)
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
        system = lib("twin.ssp").read_ssp(Path(path))
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
    results = lib("twin.results")
    if args.input_file:
        inputs_lib = lib("twin.inputs")
        result = inputs_lib.simulate_with_inputs(fmu, inputs_lib.InputTable.read(args.input_file), **options)
    else:
        result = lib("twin.fmu").simulate_fmu(fmu, **options)
    load = options["inputs"].get("load_torque")     # text from --input, taken as a number by the FMU
    lib("twin.plausibility").check_result(result, load=float(load) if load is not None else None,
                                           constant_inputs=not args.input_file)
    written = results.write_result(result, target)
    lines = []
    if args.show_plot:
        channels = list(result.signals)[:12]
        png = lib("twin.plotting").plot_time(result, channels, Path(written).with_suffix(".png"),
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
    results = lib("twin.results")
    # Reject a bad output path, bad times and names before a possibly long simulation, not after it.
    target = results.check_output_path(args.output)
    fmu, parameters = _ssp_or_fmu(args.fmu, parameters)
    checks = lib("twin.checks")
    checks.check_times(args.start_time, args.stop_time, args.output_interval,
                       n_channels=len(outputs) if outputs else None, fmu=fmu)
    checks.check_assignments(fmu, given, inputs, values=parameters)
    if args.validate:
        problems = lib("twin.fmu").validate(fmu)
        if problems:
            raise lib("twin.errors").FMUError(f"{fmu} is not valid ({len(problems)} problem(s)):\n  "
                                                + "\n  ".join(problems))
    options = dict(stop_time=args.stop_time, start_time=args.start_time, output_interval=args.output_interval,
                   outputs=outputs, parameters=parameters, inputs=inputs, progress=not args.no_progress)
    # the FMU runs in a child process: a crash inside it is reported, not fatal to the CLI
    text, notes = lib("twin.isolation").run_isolated(recording_warnings, _simulate_in_child, args, fmu, options,
                                                      target, what=f"FMU {fmu}", timeout=args.timeout)
    print_warnings(notes)
    print(text)
    return 0


def _cmd_export_ssp(args: argparse.Namespace) -> int:
    fmu = Path(args.fmu)
    values: dict = {}
    for f in args.parameters or ():
        values.update(lib("twin.scenario").read_parameter_file(Path(f), fmu=fmu))
    values.update(parse_assignments(args.param, "--param"))
    out = lib("twin.ssp").write_ssp(fmu, values, Path(args.out), name=args.name,
                                     description=args.description or "")
    print(f"wrote {out}: {fmu.name} bound to {len(values)} parameter value(s)")
    return 0


def _cmd_validate(args: argparse.Namespace) -> int:
    path = Path(args.file)
    problems = (lib("twin.ssp").validate_ssp(path) if path.suffix == ".ssp"
                else lib("twin.fmu").validate(path))
    if not problems:
        print("No problems found.")
        return 0
    print(f"{len(problems)} problem{'s were' if len(problems) != 1 else ' was'} found:")
    for message in problems:
        print()
        print(message)
    return 1
