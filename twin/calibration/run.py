"""``twin calibrate``: a scenario's ``calibration:`` block, a measurement file, and a report.

Scenario block::

    calibration:
      parameters: {kt12: [1000, 2500], I1: [3.0e-3, 6.0e-3]}   # bounds in SI units
      algorithm: mogoa            # or nsga2
      pop_size: 16
      n_gen: 8
      record: healthy             # record name in the measurement file (default: the first)
      natural_frequencies: [22, 87, 218, 430, 512, 767, 1248, 1927]   # measured modes [Hz]
      foundation_modes: [13, 41]  # removed from natural_frequencies (paper: hammer test)
      record_duration: 0.3        # s simulated per evaluation, after settle_time
      settle_time: 0.1
      band: [10, 5000]            # Hz, spectrum objective
      refine: true                # polish the pick by least squares on the modes (default)

Outputs in ``out_dir``:
- ``calibrated.json`` and ``calibrated.ssv``: the least-crowded pick (paper Eq. 9);
- ``knee.json``;
- ``pareto.csv``;
- ``checkpoint.json``;
- ``report.html``, with the paper's Table 2 for this run and PSD overlays before and after
  (``report_psd.png``).
"""
from __future__ import annotations

import csv
import html
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twin.errors import ScenarioError
from twin.scenario import CALIBRATION_SCHEMA

@dataclass(frozen=True)
class CalibrationReport:
    result: object                  # CalibrationResult
    measured_modes: np.ndarray      # (k,) Hz
    before_modes: np.ndarray        # (k,) matched model modes before
    after_modes: np.ndarray         # (k,) matched model modes after
    objectives_before: np.ndarray   # (3,)
    objectives_after: np.ndarray    # (3,)
    out_dir: Path

    def table(self) -> str:
        """The paper's Table 2 for this run, as text."""
        rows = ["  measured [Hz]   before [Hz]  diff [%]   after [Hz]  diff [%]"]
        for m, b, a in zip(self.measured_modes, self.before_modes, self.after_modes):
            rows.append(f"  {m:13.1f} {b:13.1f} {100 * (b - m) / m:+9.1f} {a:12.1f} {100 * (a - m) / m:+9.1f}")
        return "\n".join(rows)


def run_calibration(scenario, measurements: str | Path, out_dir: str | Path, *, executor=None,
                    progress: bool = True, seed: int | None = None, resume: bool = False) -> CalibrationReport:
    """Calibrate the scenario's FMU to one measured record (see the module docstring)."""
    import jsonschema

    from twin.calibration.objectives import match_modes
    from twin.calibration.problem import (CalibrationTarget, EvalTask, ParameterSpace, calibrate,
                                          evaluate_candidate, write_parameter_set)
    from twin.executor import make_executor
    from twin.measurements import load_measurements
    from twin.signals import remove_foundation_modes

    spec = scenario.raw.get("calibration")
    if spec is None:
        raise ScenarioError([(str(scenario.source), "calibration", "the scenario has no calibration block")])
    errors = [(str(scenario.source), "calibration." + ".".join(map(str, e.absolute_path)), e.message)
              for e in jsonschema.Draft202012Validator(CALIBRATION_SCHEMA).iter_errors(spec)]
    if errors:
        raise ScenarioError(errors)
    out_dir = Path(out_dir)
    if not out_dir.parent.exists():
        from twin.errors import OutputPathError
        raise OutputPathError(f"parent directory {out_dir.parent} does not exist")
    out_dir.mkdir(exist_ok=True)

    duration = float(spec.get("record_duration", 0.3))
    settle = float(spec.get("settle_time", 0.1))
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    mset = load_measurements(measurements, min_duration=duration, channels=[channel],
                             resample_to=scenario.sample_rate)
    for note in mset.notes:
        print(f"note: {note}")
    rec = mset[spec["record"]] if "record" in spec else mset[0]
    if rec.nominal_speed is None or rec.load is None:
        raise ScenarioError([(str(measurements), f"records.{rec.name}",
                              "calibration needs the record attributes nominal_speed [Hz] and load [N.m]")])
    modes_measured = np.asarray(spec.get("natural_frequencies", []), float)
    if modes_measured.size == 0:
        raise ScenarioError([(str(scenario.source), "calibration.natural_frequencies",
                              "give the measured natural frequencies (e.g. from a run-up and a hammer test)")])
    if spec.get("foundation_modes"):
        modes_measured, removed = remove_foundation_modes(modes_measured, np.asarray(spec["foundation_modes"]))
        print(f"removed foundation modes {list(np.round(removed, 1))} Hz from the measured list")
    band = spec.get("band", [10.0, 5000.0])
    n = int(round(duration * rec.sample_rate))
    target = CalibrationTarget(np.asarray(rec[channel][-n:], float), rec.sample_rate, float(rec.nominal_speed),
                               float(rec.load), modes_measured, channel=channel, fmin=band[0], fmax=band[1])
    space = ParameterSpace.from_bounds(spec["parameters"])
    fmu = scenario.fmu_path()
    fixed = {k: v for k, v in scenario.parameters.items() if k not in space.names}
    ex = executor or make_executor(scenario.executor)
    try:
        shaft = target.measured_shaft_hz
        before, before_info = evaluate_candidate(EvalTask(str(fmu), dict(fixed), target, settle, duration, shaft))
        result = calibrate(fmu, space, target, algorithm=spec.get("algorithm", "mogoa"),
                           pop_size=int(spec.get("pop_size", 16)), n_gen=int(spec.get("n_gen", 8)),
                           seed=scenario.seed if seed is None else seed, executor=ex,
                           checkpoint=out_dir / "checkpoint.json", settle=settle, duration=duration, fixed=fixed,
                           verbose=progress, resume=resume, refine=bool(spec.get("refine", True)))
        after, after_info = evaluate_candidate(EvalTask(str(fmu), {**fixed, **result.chosen}, target, settle,
                                                        duration, shaft))
    finally:
        if executor is None:
            ex.close()
    write_parameter_set({**fixed, **result.chosen}, out_dir / "calibrated.json")
    write_parameter_set({**fixed, **result.chosen}, out_dir / "calibrated.ssv", name=f"{scenario.name}-calibrated")
    write_parameter_set({**fixed, **result.knee}, out_dir / "knee.json")
    _write_pareto(result, out_dir / "pareto.csv")
    mb = np.asarray(before_info["natural_frequencies"])
    ma = np.asarray(after_info["natural_frequencies"])
    report = CalibrationReport(result, modes_measured, mb[match_modes(mb, modes_measured)],
                               ma[match_modes(ma, modes_measured)], before, after, out_dir)
    _psd_overlay(fmu, target, fixed, result.chosen, settle, duration, out_dir / "report_psd.png")
    _write_html(report, scenario, measurements, out_dir / "report.html")
    return report


def _write_pareto(result, path: Path) -> None:
    from twin._atomic import atomic_path
    with atomic_path(path) as tmp:
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow([*result.names, "f1_waveform", "f2_spectrum", "f3_frequencies_Hz2"])
            for x, fv in zip(result.X, result.F):
                w.writerow([*map(repr, map(float, x)), *map(repr, map(float, fv))])


def _simulate(fmu, target, params, settle, duration):
    from twin.operating import simulate_operating_point
    return simulate_operating_point(fmu, target.drive_hz, target.load, parameters=params, settle=settle,
                                    duration=duration, channels=[target.channel],
                                    output_interval=1 / target.sample_rate)[:, 0]


def _psd_overlay(fmu, target, fixed, chosen, settle, duration, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from twin._atomic import atomic_path
    from twin.signals import welch_psd
    res = max(2.0, 4.0 * target.sample_rate / target.signal.size)
    fig, ax = plt.subplots(figsize=(10, 4.5))
    for label, x, style in (("measured", target.signal, dict(color="k", lw=1.2)),
                            ("model before", _simulate(fmu, target, fixed, settle, duration), dict(color="tab:red", lw=0.8)),
                            ("model after", _simulate(fmu, target, {**fixed, **chosen}, settle, duration),
                             dict(color="tab:blue", lw=0.8))):
        f, p = welch_psd(x, target.sample_rate, resolution=res)
        band = (f >= target.fmin) & (f <= target.fmax)
        ax.semilogy(f[band], p[band], label=label, **style)
    for m in target.natural_frequencies:
        ax.axvline(m, color="0.6", ls=":", lw=0.8)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"PSD of {target.channel} [(m/s2)^2/Hz]")
    ax.set_title("Calibration: PSD before and after (dotted: measured natural frequencies)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def _write_html(report: CalibrationReport, scenario, measurements, path: Path) -> None:
    from twin._atomic import atomic_path
    r = report.result
    rows = "".join(
        f"<tr><td>{m:.1f}</td><td>{b:.1f}</td><td>{100 * (b - m) / m:+.1f}</td><td>{a:.1f}</td>"
        f"<td>{100 * (a - m) / m:+.1f}</td></tr>"
        for m, b, a in zip(report.measured_modes, report.before_modes, report.after_modes))
    params = "".join(f"<tr><td>{html.escape(k)}</td><td>{v:.6g}</td><td>{r.knee[k]:.6g}</td></tr>"
                     for k, v in r.chosen.items())
    ob, oa = report.objectives_before, report.objectives_after
    doc = f"""<!doctype html><html><head><meta charset="utf-8"><title>Calibration: {html.escape(scenario.name)}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:.25em .6em;text-align:right}}</style></head><body>
<h1>Calibration of {html.escape(scenario.fmu)} ({html.escape(scenario.name)})</h1>
<p>Measurements: {html.escape(str(measurements))}. Algorithm: {r.algorithm}, {r.n_evals} evaluations
({r.failed_evals} failed and scored infeasible). Final pick: least-crowded member of the Pareto front (paper Eq. 9).</p>
<h2>Natural frequencies (paper Table 2 for this run)</h2>
<table><tr><th>measured [Hz]</th><th>model before [Hz]</th><th>diff [%]</th><th>model after [Hz]</th><th>diff [%]</th></tr>{rows}</table>
<h2>Objectives</h2>
<table><tr><th></th><th>f1 = 1 - corr(waveforms)</th><th>f2 = 1 - corr(spectra)</th><th>f3 [Hz&sup2;]</th></tr>
<tr><td>before</td><td>{ob[0]:.4f}</td><td>{ob[1]:.4f}</td><td>{ob[2]:.4g}</td></tr>
<tr><td>after</td><td>{oa[0]:.4f}</td><td>{oa[1]:.4f}</td><td>{oa[2]:.4g}</td></tr></table>
<h2>Calibrated parameters</h2>
<table><tr><th>parameter</th><th>least-crowded pick</th><th>knee point</th></tr>{params}</table>
<p>Files: calibrated.json, calibrated.ssv (SSP parameter values), knee.json, pareto.csv, checkpoint.json.</p>
<h2>PSD before and after</h2><img src="report_psd.png" style="max-width:100%">
</body></html>"""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(doc)
