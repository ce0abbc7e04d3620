"""``twin calibrate``: a scenario's ``calibration:`` block, a measurement file, and a report.

Scenario block (every key but ``parameters`` optional)::

    calibration:
      parameters: auto            # or {kt12: [1000, 2500], I1: [3.0e-3, 6.0e-3]}: bounds in SI units
      modes_from: runup           # record whose run-up (or hammer test) gives the measured modes;
                                  # or a list read together: [runup, hammer_pinion, hammer_gear]
      min_confidence: 0.3         # modes of that record used for calibration
      lscf: false                 # also fit the hammer records together by poly-reference LSCF
      path_from: {hammer_pinion: bearing_force_input_y}   # hammer records struck at the housings: the
                                  # sensors read the bearing forces through the path they measured
      path_sections: 32           # second-order sections fitted to each measured path
      mesh_form: none             # or fit: the pinion's as-manufactured profile (slope, crowning)
                                  #   fitted to the measured mesh harmonics before the levels
      face_contact_from: light    # a steady record at the same speed and another load: the flanks'
                                  #   lead mismatch fitted to how the spectrum changes with load
      natural_frequencies: [22, 87, 218, 430]   # or typed by hand [Hz]
      foundation_modes: [13, 41]  # removed from the measured modes (paper: hammer test), in Hz
                                  #   or the name of a hammer-test record to read them from
      record: steady              # steady record for the signal objectives (default: the first other one)
      objectives: [correlation, modes]   # of waveform, correlation, frequencies, modes
      algorithm: mogoa            # or nsga2
      pop_size: 16
      n_gen: 8
      record_duration: 0.3        # s simulated per evaluation, after settle_time
      settle_time: 0.1
      band: [10, 5000]            # Hz, spectrum objective
      refine: true                # polish the pick by least squares on the modes (default)
      pairing: frequency          # measured to model modes: frequency (default) or shape (opt-in)
      visibility: mesh            # model modes a sensor shows: under the mesh (default) or any
                                  #   excitation of a run-up (run-up, opt-in); +dominant (opt-in):
                                  #   a mode dominating a response at its frequency counts too
      fit: follow                 # the modes fit: follow the nominal pairing (default) or search
                                  #   (CMA-ES, modes paired afresh at every set; opt-in)
      search_budget: 160          # linearisations of that search
      evaluation_timeout: 600     # s; an evaluation still running then is stopped, scored infeasible
      speed: 20                   # Hz and N.m: the operating point of typed modes without a measurement
      load: 20                    #   file (default: the scenario's constant operating speed and load)

``parameters: auto`` chooses the parameters the measured modes can identify, with bounds from
physics (:mod:`twin.calibration.sensitivity`). The default objectives are the paper's
(waveform, correlation, frequencies) with hand-typed modes and explicit parameters, and
(correlation, modes) otherwise. ``pairing: frequency`` (default) pairs each measured mode with the
nearest visible model mode within 15 %; ``pairing: shape`` pairs by frequency, shape at the
sensors and each model mode's reach (:mod:`twin.calibration.pairing`), an opt-in that scored
worse on the rigs. ``visibility`` (:data:`twin.calibration.model_modes.VISIBILITY`) says which
excitations make a model mode visible, i.e. a pairing candidate. ``fit``
(:mod:`twin.calibration.mode_search`) says how the modes are fitted with ``refine``.

Without a measurement file (``measurements=None``) the block must type ``natural_frequencies``
and have only the ``modes`` objective (the default then): a published table of modes calibrates
the twin alone. The operating point is ``speed``/``load`` of the block, else the scenario's
constant ``operating.speed``/``operating.load``; there is no level fit and no PSD overlay.

Outputs in ``out_dir``:
- ``calibrated.yaml``: the calibrated scenario, which ``twin compare``, ``diagnose``,
  ``archive`` (and every command taking a scenario) accept, valid wherever it is moved with
  its directory; ``calibrated.json`` and ``calibrated.ssv``: the parameter set (the ``.ssv`` in the FMU's
  units, with their definitions); ``calibrated.ssp``: a standard SSP package of the FMU bound to
  those values, which other SSP tools (OSP libcosim, ...) run as calibrated;
- ``knee.json``, ``pareto.csv``, ``checkpoint.json``;
- ``modes.json`` (modes read from a record), ``sensitivity.json`` (with ``parameters: auto``);
- ``report.html`` with the paper's Table 2 for this run, warnings (parameters ending on a bound)
  and PSD overlays before and after (``report_psd.png``, with a measurement file).
"""
from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from twin.calibration.measured import measured_modes, modes_records
from twin.errors import MeasurementError, ScenarioError
from twin.scenario_schema import CALIBRATION_SCHEMA


@dataclass(frozen=True)
class CalibrationReport:
    result: object                  # CalibrationResult
    measured_modes: np.ndarray      # (k,) Hz
    before_modes: np.ndarray        # (k,) matched model modes before (NaN: no model mode within reach)
    after_modes: np.ndarray         # (k,) matched model modes after
    objectives_before: np.ndarray   # (n_obj,)
    objectives_after: np.ndarray    # (n_obj,)
    out_dir: Path
    objectives: tuple[str, ...] = ("waveform", "correlation", "frequencies")
    warnings: tuple[str, ...] = ()
    sensitivity: object | None = None
    modes_source: str = "typed in the scenario"
    scenario_file: Path | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    pairing_warning: str | None = None   # also in warnings: most measured modes had no twin mode to pair with

    def table(self) -> str:
        """The paper's Table 2 for this run, as text."""
        rows = ["  measured [Hz]   before [Hz]  diff [%]   after [Hz]  diff [%]"]
        for m, b, a in zip(self.measured_modes, self.before_modes, self.after_modes):
            rows.append(f"  {m:13.1f} {_col(b, m)} {_col(a, m)}")
        return "\n".join(rows)


def _col(model: float, measured: float) -> str:
    if not np.isfinite(model):
        return f"{'none':>13s} {'':>9s}"
    return f"{model:13.1f} {100 * (model - measured) / measured:+9.1f}"


def _mesh_form(scenario, fmu, parameters, rec, channel, target, settle, fmax, source=None):
    """``mesh_form: fit``: the profile fit (:mod:`twin.calibration.mesh_form`) on the steady record."""
    from twin.calibration.levels import has_levels
    from twin.calibration.mesh_form import fit_mesh_form, has_profile
    if not (has_levels(fmu, channel) and has_profile(fmu)):
        raise ScenarioError([(str(scenario.source), "calibration.mesh_form", f"{Path(str(fmu)).name} has no sensor "
                              f"gain for {channel!r} or no profile_deviation; mesh_form: fit needs a model that reads "
                              "its casing sensors with the broadband sources (GearTwin.Gearbox21Measured and the "
                              "models on GearTwin.Gearbox21Casing)")])
    try:
        return fit_mesh_form(fmu, parameters, np.asarray(rec[channel], float), rec.sample_rate,
                             speed_hz=target.drive_hz, load_nm=target.load, channel=channel, fmax=fmax, settle=settle)
    except ValueError as exc:
        raise MeasurementError(str(source or "<measurements>"), rec.name, f"{exc} (calibration.mesh_form: fit)") from None


def _face_contact_record(scenario, mset, spec, rec, channel, source, measurements):
    """``face_contact_from``'s record, checked against the steady record ``rec``: one speed, two loads."""
    from twin.calibration.face_contact import load_pair_problem
    name = spec["face_contact_from"]
    if name not in mset.names:
        raise ScenarioError([(source, "calibration.face_contact_from", f"no record {name!r} in the measurements "
                              f"(records: {', '.join(mset.names)})")])
    other = _steady_record({"record": name}, mset, scenario, channel, 0.5, source, measurements)
    if problem := load_pair_problem(rec, other):
        raise ScenarioError([(source, "calibration.face_contact_from", problem)])
    return other


def _overridden(spec: Mapping | None, overrides: Mapping[str, object] | None) -> dict:
    """A copy of a calibration block (None: empty) with ``overrides`` (block key -> value) in place;
    an override of None leaves the key as the block has it."""
    given = {k: dict(v) if isinstance(v, Mapping) else v for k, v in (overrides or {}).items() if v is not None}
    return {**(spec or {}), **given}


def _block(scenario, overrides: Mapping[str, object] | None = None) -> dict:
    """The scenario's calibration block with ``overrides`` (block key -> value; None leaves the key
    as the block has it) in place, checked against the schema (:class:`ScenarioError` naming each
    bad key)."""
    import jsonschema

    spec = scenario.raw.get("calibration")
    if spec is None:
        if (overrides or {}).get("modes_from") is None:
            raise ScenarioError([(str(scenario.source), "calibration", "the scenario has no calibration block "
                                  "(add one, or give --modes-from RECORD to calibrate the parameters chosen "
                                  "automatically to that record's modes)")])
        spec = {"parameters": "auto"}
    spec = _overridden(spec, overrides)
    errors = [(str(scenario.source), "calibration." + ".".join(map(str, e.absolute_path)),
               "must be 'auto' or a mapping of parameter name to [lower, upper]"
               if e.validator == "oneOf" else e.message)
              for e in jsonschema.Draft202012Validator(CALIBRATION_SCHEMA).iter_errors(spec)]
    if errors:
        raise ScenarioError(errors)
    return spec


def run_calibration(scenario, measurements: str | Path | None, out_dir: str | Path, *, executor=None,
                    progress: bool = True, seed: int | None = None, resume: bool = False,
                    modes_from: str | list[str] | None = None, pairing: str | None = None,
                    foundation_from: str | None = None, path_from: dict[str, str] | None = None,
                    face_contact_from: str | None = None, visibility: str | None = None) -> CalibrationReport:
    """Calibrate the scenario's FMU to a measurement file, or with ``measurements=None`` to the
    block's typed natural frequencies alone (see the module docstring); ``modes_from``,
    ``pairing``, ``visibility``, ``foundation_from`` (a hammer record: ``foundation_modes``),
    ``path_from`` ({hammer record: bearing force}) and ``face_contact_from`` (a steady record at
    another load) override the calibration block's keys."""
    from twin._atomic import check_output_dir
    from twin.calibration.levels import fit_levels_and_panels, has_levels
    from twin.calibration.modal_fit import mode_errors, on_bounds
    from twin.calibration.mode_search import SEARCH_BUDGET
    from twin.calibration.objectives import match_modes
    from twin.calibration.output import write_calibrated_scenario
    from twin.calibration.problem import (CalibrationTarget, EvalTask, ParameterSpace, calibrate,
                                          check_calibration_parameters, evaluate_candidate, write_parameter_set)
    from twin.calibration.report import psd_overlay, write_html, write_pareto
    from twin.calibration.model_modes import model_modes
    from twin.calibration.sensitivity import mode_sensitivity
    from twin.calibration.sensor_path import casing_path
    from twin.calibration.typed_modes import modes_only_objectives, typed_operating_point
    from twin.executor import make_executor
    from twin.measurements import load_measurements

    source = str(scenario.source)
    if measurements is None and scenario.raw.get("calibration") is None:
        raise ScenarioError([(source, "calibration", "the scenario has no calibration block: without --measurements "
                              "it must type the measured natural_frequencies [Hz]")])
    spec = _block(scenario, {"modes_from": modes_from, "pairing": pairing, "visibility": visibility,
                             "foundation_modes": foundation_from, "path_from": path_from,
                             "face_contact_from": face_contact_from})
    pairing = spec.get("pairing", "frequency")
    visibility = spec.get("visibility", "mesh")
    fit = spec.get("fit", "follow")
    if measurements is None:       # refused before anything is written
        if spec.get("path_from"):
            raise ScenarioError([(source, "calibration.path_from", "a measured path needs the measurement file "
                                  "that holds its hammer records (--measurements)")])
        if spec.get("face_contact_from"):
            raise ScenarioError([(source, "calibration.face_contact_from", "a load pair needs the measurement file "
                                  "that holds its records (--measurements)")])
        objectives = modes_only_objectives(spec, source)
        speed_hz, load_nm = typed_operating_point(scenario, spec)
    with_path = bool(scenario.structural.get("n_path_sections"))
    if with_path:       # refused before anything is written when the block cannot fit the path again
        from twin.calibration.transfer_path import mechanical_model
        fmu = mechanical_model(scenario, spec, source)
    else:
        fmu = scenario.fmu_path()
    out_dir = check_output_dir(out_dir, "calibration output", create=True)
    duration = float(spec.get("record_duration", 0.3))
    settle = float(spec.get("settle_time", 0.1))
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    auto = spec["parameters"] == "auto"
    # the model's modes are read at the sensors the measured ones were seen by (those it has)
    outputs = _outputs(fmu)
    rec, light = None, None
    if measurements is None:
        freqs, rel_sd, modes_what, damping, confidence, seen_by, shapes = measured_modes(spec, None, source, out_dir,
                                                                                         with_damping=True)
        signal, sample_rate = np.zeros(0), scenario.sample_rate
    else:
        mset = load_measurements(measurements)
        for note in mset.notes:
            print(f"note: {note}")
        freqs, rel_sd, modes_what, damping, confidence, seen_by, shapes = measured_modes(spec, mset, source, out_dir,
                                                                                         with_damping=True)
        rec = _steady_record(spec, mset, scenario, channel, duration, source, measurements)
        light = (_face_contact_record(scenario, mset, spec, rec, channel, source, measurements)
                 if spec.get("face_contact_from") else None)     # refused before the modes fit
        if spec.get("path_from"):     # refused before the modes fit
            from twin.calibration.transfer_path import check_path_from
            path_channels = check_path_from(scenario, mset, spec, source, outputs)
        default_obj = (["waveform", "correlation", "frequencies"]
                       if not auto and not spec.get("modes_from") else ["correlation", "modes"])
        objectives = tuple(spec.get("objectives", default_obj))
        n = int(round(duration * rec.sample_rate))
        signal, sample_rate = np.asarray(rec[channel][-n:], float), rec.sample_rate
        speed_hz, load_nm = float(rec.nominal_speed), float(rec.load)
    band = spec.get("band", [10.0, 5000.0])
    mode_channels = tuple(c for c in seen_by if c in outputs) or (channel,)
    target = CalibrationTarget(signal, sample_rate, speed_hz, load_nm, freqs, channel=channel, fmin=band[0],
                               fmax=band[1], objectives=objectives, mode_rel_sd=rel_sd, mode_channels=mode_channels,
                               mode_shapes=_pairing_shapes(shapes, len(mode_channels), pairing),
                               pairing=pairing, visibility=visibility, fit=fit,
                               search_budget=int(spec.get("search_budget", SEARCH_BUDGET)))
    fixed = dict(scenario.parameters)
    if with_path:          # fitted again from the hammer records
        from twin.calibration.transfer_path import without_path
        fixed = without_path(fixed)
    if not auto:       # unknown or non-physical names and bounds: refused before the first evaluation
        check_calibration_parameters(fmu, ParameterSpace.from_bounds(spec["parameters"]),
                                     {k: v for k, v in fixed.items() if k not in spec["parameters"]})
    timeout = float(spec.get("evaluation_timeout", scenario.executor.get("timeout", 600.0)))
    ex = executor or make_executor({**scenario.executor, "timeout": timeout})
    path_note, attributed = None, []
    try:
        sensitivity = None
        if auto:
            sensitivity = mode_sensitivity(fmu, fixed, freqs, speed_hz=target.drive_hz, load_nm=target.load,
                                           rel_sd=rel_sd, channels=mode_channels, executor=ex,
                                           shapes=target.mode_shapes, pairing=pairing, visibility=visibility)
            target = replace(target, mode_pairing=sensitivity.pairing)
            if not sensitivity.chosen:
                (out_dir / "sensitivity.json").write_text(json.dumps(sensitivity.to_dict(), indent=2))
                raise ScenarioError([(source, "calibration.parameters", "no parameter is identifiable from the "
                                      "measured modes:\n" + sensitivity.table())])
            if progress:
                print(sensitivity.table())
            bounds = sensitivity.bounds()
            nominal = {c.name: c.nominal for c in sensitivity.candidates}
            path = {}
            for ch in mode_channels:
                path.update(casing_path(fmu, ch, sensitivity.unmatched_hz, freqs, damping, confidence,
                                        shared=len(mode_channels)))
            attributed = sorted({v for k, v in path.items() if "panel_frequency" in k})
            if path:
                fixed.update(path)
                path_note = ("attributed to casing panel modes in the sensor path (no gearbox mode paired): "
                             + ", ".join(f"{f:.1f} Hz" for f in attributed))
                if progress:
                    print(path_note)
            (out_dir / "sensitivity.json").write_text(json.dumps(sensitivity.to_dict(sensor_path_hz=attributed),
                                                                 indent=2))
        else:
            bounds = spec["parameters"]
            nominal = {}
        space = ParameterSpace.from_bounds(bounds)
        fixed = {k: v for k, v in fixed.items() if k not in space.names}
        kw = dict(speed_hz=target.drive_hz, load_nm=target.load, channels=mode_channels, visibility=visibility)
        shaft = target.measured_shaft_hz if target.needs_simulation else target.drive_hz
        before, _ = evaluate_candidate(EvalTask(str(fmu), {**fixed, **nominal}, target, settle, duration, shaft))
        result = calibrate(fmu, space, target, algorithm=spec.get("algorithm", "mogoa"),
                           pop_size=int(spec.get("pop_size", 16)), n_gen=int(spec.get("n_gen", 8)),
                           seed=scenario.seed if seed is None else seed, executor=ex,
                           checkpoint=out_dir / "checkpoint.json", settle=settle, duration=duration, fixed=fixed,
                           verbose=progress, resume=resume, refine=bool(spec.get("refine", True)),
                           nominal=nominal or None)
        chosen = dict(result.chosen)
        levels, measured_path, spectrum_fmu = None, None, fmu
        if rec is not None and spec.get("path_from"):
            # the sensors read the bearing forces through the path the hammer tests measured; the
            # modes above were fitted on the model without it (its sections are not gearbox modes)
            from twin.calibration.transfer_path import attach_measured_path
            measured_path = attach_measured_path(scenario, mset, spec, source, path_channels, fmin=band[0],
                                                 fmax=min(band[1], 0.45 * rec.sample_rate))
            spectrum_fmu = measured_path.fmu_path
            chosen.update(measured_path.parameters)
            if progress:
                print(measured_path.describe())
        form = None
        if rec is not None and spec.get("mesh_form", "none") == "fit":
            form = _mesh_form(scenario, spectrum_fmu, {**fixed, **chosen}, rec, channel, target, settle,
                              min(band[1], 0.45 * rec.sample_rate), source)
            chosen.update(form.parameters)
            if progress:
                print(form.describe())
        contact = None
        if rec is not None and light is not None:
            # the flanks' lead mismatch from how the spectrum changes with load (path and gain divide out)
            from twin.calibration.face_contact import fit_face_contact
            contact = fit_face_contact(spectrum_fmu, {**fixed, **chosen},
                                       [(np.asarray(rec[channel], float), rec.load),
                                        (np.asarray(light[channel], float), light.load)],
                                       channel, rec.sample_rate, target.drive_hz, executor=ex, progress=progress)
            chosen.update(contact.parameters)
            if progress:
                print(contact.describe())
        if rec is not None and has_levels(spectrum_fmu, channel):
            # the level of the spectrum: sensor gain, roughness and process-force levels (three runs)
            level_kw = dict(speed_hz=target.drive_hz, load_nm=target.load, channel=channel, fmin=band[0],
                            fmax=min(band[1], 0.45 * rec.sample_rate), settle=settle)
            levels, updates = fit_levels_and_panels(spectrum_fmu, {**fixed, **chosen}, np.asarray(rec[channel], float),
                                                    rec.sample_rate, **level_kw)
            chosen.update(updates)
            if progress:
                print(f"levels: {levels.describe()}")
        path_values = measured_path.parameters if measured_path is not None else {}
        mechanical = {k: v for k, v in chosen.items() if k not in path_values}
        after, _ = evaluate_candidate(EvalTask(str(fmu), {**fixed, **mechanical}, target, settle, duration, shaft))
    finally:
        if executor is None:
            ex.close()
    warnings = [f"{n} = {chosen[n]:.6g} ended on a bound of [{lo:.6g}, {hi:.6g}]: the measured modes pull it "
                "beyond what physics allows, so the model's structure may lack something the rig has"
                for n, lo, hi in zip(space.names, space.lower, space.upper)
                if n in on_bounds(space.names, [chosen[k] for k in space.names], space.lower, space.upper)]
    few = sensitivity.pairing_warning(attributed) if sensitivity is not None else None
    if few:
        warnings.append(few)
    if levels is not None and (held := levels.warning()):
        warnings.append(held)
    if form is not None and form.on_bound():
        from twin.calibration.mesh_form import BOUND
        warnings.append(f"{form.describe()}: on the bound of +-{1e6 * BOUND:g} um (about ISO 1328-1 grade 9); "
                        "the mesh harmonics ask for more than a gear's profile deviation")
    if contact is not None and contact.on_bound():
        warnings.append(f"{contact.describe()}: on the bound of {1e6 * max(contact.grid):g} um; the load dependence "
                        "asks for more than a misaligned pair")
    notes = tuple(n for n in (path_note, measured_path.describe() if measured_path is not None else None,
                              form.describe() if form is not None else None,
                              contact.describe() if contact is not None else None,
                              f"levels: {levels.describe()}" if levels is not None else None) if n)
    if progress:
        for w in warnings:
            print(f"warning: {w}")
    full = {**fixed, **chosen}
    against = (f"{Path(measurements).name}, {modes_what}" if measurements is not None
               else f"modes {modes_what} at {speed_hz:g} Hz, {load_nm:g} N.m")
    write_parameter_set(full, out_dir / "calibrated.json")
    write_parameter_set(full, out_dir / "calibrated.ssv", name=f"{scenario.name}-calibrated", fmu=spectrum_fmu)
    from twin.ssp import write_ssp
    write_ssp(spectrum_fmu, full, out_dir / "calibrated.ssp", name=f"{scenario.name}-calibrated",
              description=f"{scenario.name}: parameters calibrated to {against}")
    write_parameter_set({**fixed, **result.knee}, out_dir / "knee.json")
    write_pareto(result, objectives, out_dir / "pareto.csv")
    structural = ({**dict(scenario.structural), "n_path_sections": measured_path.n_sections}
                  if measured_path is not None else None)
    scenario_file = write_calibrated_scenario(scenario, out_dir / "calibrated.yaml", "calibrated.json",
                                              note=against, calibrated=mechanical, structural=structural)
    full_mechanical = {**fixed, **mechanical}
    if "modes" in objectives:
        mb = mode_errors(model_modes(fmu, {**fixed, **nominal}, **kw), freqs, target.rel_sd, target.mode_shapes,
                         pairing=pairing)[1]
        ma = mode_errors(model_modes(fmu, full_mechanical, **kw), freqs, target.rel_sd, target.mode_shapes,
                         pairing=pairing)[1]
    else:
        from twin.linearize import natural_frequencies
        b = natural_frequencies(fmu, n=freqs.size + 4, parameters={**fixed, **nominal, **_start(target)})
        a = natural_frequencies(fmu, n=freqs.size + 4, parameters={**full_mechanical, **_start(target)})
        mb, ma = b[match_modes(b, freqs)], a[match_modes(a, freqs)]
    report = CalibrationReport(result, freqs, mb, ma, before, after, out_dir, objectives, tuple(warnings),
                               sensitivity, modes_what, scenario_file, notes, few)
    if rec is not None:       # before: the nominal parameters (with the measured path when there is one)
        psd_overlay(spectrum_fmu, target, {**fixed, **nominal, **path_values}, chosen, settle, duration,
                    out_dir / "report_psd.png")
    write_html(report, scenario, measurements, out_dir / "report.html")
    return report


def _steady_record(spec: dict, mset, scenario, channel: str, duration: float, source: str, measurements):
    """The steady record of the signal objectives, resampled to the scenario's rate, checked."""
    from twin.measurements.resample import resample_record

    # the first record that neither gives the modes nor is the foundation's hammer test
    not_steady = {*modes_records(spec), spec.get("foundation_modes") if isinstance(spec.get("foundation_modes"), str)
                  else None, spec.get("face_contact_from")}
    steady_name = spec.get("record") or next((n for n in mset.names if n not in not_steady), mset.names[0])
    if steady_name not in mset.names:
        raise ScenarioError([(source, "calibration.record", f"no record {steady_name!r} in the measurements")])
    rec = mset[steady_name]
    if channel not in rec:
        raise ScenarioError([(source, "output.variables", f"record {rec.name!r} has no channel {channel!r} "
                              f"(it has {', '.join(rec.channel_names)})")])
    if rec.sample_rate != scenario.sample_rate:
        rec, note = resample_record(rec, scenario.sample_rate)
        if note:
            print(f"note: {note}")
    if rec.nominal_speed is None or rec.load is None:
        raise ScenarioError([(str(measurements), f"records.{rec.name}",
                              "calibration needs the record attributes nominal_speed [Hz] and load [N.m]")])
    if rec.duration < duration:
        raise ScenarioError([(str(measurements), f"records.{rec.name}",
                              f"the record lasts {rec.duration:.3g} s, shorter than record_duration {duration:g} s")])
    return rec


def _outputs(fmu) -> set[str]:
    from twin.fmu import FMU
    with FMU(fmu) as f:
        return {v.name for v in f.outputs}


def _start(target) -> dict:
    from twin.operating import operating_point
    return operating_point(target.drive_hz, target.load)[0]


def scenario_sensitivity(scenario, measurements: str | Path | None = None, *, modes_from: str | list[str] | None = None,
                         n_modes: int = 8, executor=None, pairing: str | None = None,
                         visibility: str | None = None):
    """The sensitivity study ``parameters: auto`` runs (:class:`twin.calibration.sensitivity.Sensitivity`).

    Measured modes from ``modes_from`` (or the scenario's calibration block) when measurements
    are given, else the block's typed ``natural_frequencies``; otherwise the model's own first
    ``n_modes`` visible modes, i.e. what a run-up of a rig exactly like the model would identify.
    The operating point is the steady record's, else the block's ``speed`` and ``load``, else the
    scenario's speed and load at its start time (20 Hz, 20 N.m when it has none).
    ``pairing`` (default: the block's ``pairing``, else ``"frequency"``) and ``visibility`` (the
    block's, else ``"mesh"``) as in ``twin calibrate``.
    """
    import tempfile

    from twin.calibration.model_modes import check_visibility, model_modes
    from twin.calibration.sensitivity import mode_sensitivity
    from twin.measurements import load_measurements

    spec = _overridden(scenario.raw.get("calibration"),
                       {"modes_from": modes_from, "pairing": pairing, "visibility": visibility})
    pairing = spec.get("pairing", "frequency")
    visibility = check_visibility(spec.get("visibility", "mesh"))
    speed = scenario.inputs.get("motor_speed_ref")
    load = scenario.inputs.get("load_torque")
    speed_hz = speed(scenario.start_time) / (2 * np.pi) if speed is not None else 20.0
    load_nm = load(scenario.start_time) if load is not None else 20.0
    speed_hz, load_nm = float(spec.get("speed", speed_hz)), float(spec.get("load", load_nm))
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    fmu = scenario.fmu_path()
    values = dict(scenario.parameters)
    if scenario.structural.get("n_path_sections"):
        # a scenario that reads a measured path: the modes are the gearbox's, not the path's sections
        from twin.calibration.transfer_path import model_without_path, without_path
        fmu, values = model_without_path(scenario), without_path(values)
    channels, shapes = (channel,), None
    if measurements is not None and (spec.get("modes_from") or spec.get("natural_frequencies")):
        mset = load_measurements(measurements)
        with tempfile.TemporaryDirectory() as tmp:
            freqs, rel, _, _, _, seen_by, shapes = measured_modes(spec, mset, str(scenario.source), Path(tmp),
                                                                  with_damping=True)
        channels = tuple(c for c in seen_by if c in _outputs(fmu)) or (channel,)
        steady = [r for r in mset if r.name not in modes_records(spec) and r.nominal_speed and r.load is not None]
        if steady:
            speed_hz, load_nm = float(steady[0].nominal_speed), float(steady[0].load)
    elif spec.get("natural_frequencies"):
        freqs = np.asarray(spec["natural_frequencies"], float)
        rel = np.zeros(freqs.size)
    else:
        mm = model_modes(fmu, values, speed_hz=speed_hz, load_nm=load_nm, channels=(channel,), visibility=visibility)
        freqs = mm.frequency[mm.visible][:n_modes]
        rel = np.zeros(freqs.size)
    return mode_sensitivity(fmu, values, freqs, speed_hz=speed_hz, load_nm=load_nm, rel_sd=rel, channels=channels,
                            executor=executor, shapes=_pairing_shapes(shapes, len(channels), "shape"), pairing=pairing,
                            visibility=visibility)


def _pairing_shapes(shapes, n_channels: int, pairing: str):
    """What the pairing reads of the measured modes: their shapes at the sensors (shape pairing, two
    channels or more) and their struck levels (either rule, when ``struck_shafts`` names them)."""
    if shapes is None:
        return None
    if (pairing == "shape" and n_channels > 1) or shapes.side_db is not None:
        return shapes
    return None
