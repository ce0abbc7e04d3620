"""The files of a calibration: Pareto front (CSV), PSD overlay (PNG) and the HTML report."""
from __future__ import annotations

import csv
import html
from pathlib import Path

import numpy as np


def write_pareto(result, objectives, path: Path) -> None:
    from twin._atomic import atomic_path
    with atomic_path(path) as tmp:
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow([*result.names, *objectives])
            for x, fv in zip(result.X, result.F):
                w.writerow([*map(repr, map(float, x)), *map(repr, map(float, fv))])


def _simulate(fmu, target, params, settle, duration):
    from twin.operating import simulate_operating_point
    return simulate_operating_point(fmu, target.drive_hz, target.load, parameters=params, settle=settle,
                                    duration=duration, channels=[target.channel],
                                    output_interval=1 / target.sample_rate)[:, 0]


def psd_overlay(fmu, target, fixed, chosen, settle, duration, path: Path) -> None:
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


LABELS = {"waveform": "f1 = 1 - corr(waveforms)", "correlation": "f2 = 1 - corr(spectra)",
          "frequencies": "f3 [Hz\u00b2]", "modes": "mean squared mode error [sd\u00b2]"}


def _cell(model: float, measured: float) -> str:
    if not np.isfinite(model):
        return "<td>none within 15 %</td><td></td>"
    return f"<td>{model:.1f}</td><td>{100 * (model - measured) / measured:+.1f}</td>"


def write_html(report, scenario, measurements, path: Path) -> None:
    from twin._atomic import atomic_path
    r = report.result
    rows = "".join(f"<tr><td>{m:.1f}</td>{_cell(b, m)}{_cell(a, m)}</tr>"
                   for m, b, a in zip(report.measured_modes, report.before_modes, report.after_modes))
    params = "".join(f"<tr><td>{html.escape(k)}</td><td>{v:.6g}</td><td>{r.knee[k]:.6g}</td></tr>"
                     for k, v in r.chosen.items())
    ob, oa = report.objectives_before, report.objectives_after
    heads = "".join(f"<th>{html.escape(LABELS.get(o, o))}</th>" for o in report.objectives)
    before = "".join(f"<td>{v:.4g}</td>" for v in ob)
    after = "".join(f"<td>{v:.4g}</td>" for v in oa)
    warn = "".join(f"<li>{html.escape(w)}</li>" for w in report.warnings)
    warn = f"<h2>Warnings</h2><ul>{warn}</ul>" if warn else ""
    sens = ""
    if report.sensitivity is not None:
        sens = ("<h2>Parameters chosen for the modes (sensitivity.json)</h2><pre>"
                + html.escape(report.sensitivity.table()) + "</pre>")
    source = html.escape(report.modes_source)
    notes = "".join(f"<p>{html.escape(n)}</p>" for n in report.notes)
    psd = ('<h2>PSD before and after</h2><img src="report_psd.png" style="max-width:100%">'
           if measurements is not None else "")
    doc = f"""<!doctype html><html><head><meta charset="utf-8"><title>Calibration: {html.escape(scenario.name)}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:.25em .6em;text-align:right}}</style></head><body>
<h1>Calibration of {html.escape(scenario.fmu)} ({html.escape(scenario.name)})</h1>
<p>Measurements: {html.escape(str(measurements) if measurements is not None else "none (typed modes only)")}. Modes: {source}. Algorithm: {r.algorithm}, {r.n_evals} evaluations
({r.failed_evals} failed and scored infeasible), then a least-squares polish on the modes.</p>
{warn}{notes}
<h2>Natural frequencies (paper Table 2 for this run)</h2>
<table><tr><th>measured [Hz]</th><th>model before [Hz]</th><th>diff [%]</th><th>model after [Hz]</th><th>diff [%]</th></tr>{rows}</table>
<h2>Objectives</h2>
<table><tr><th></th>{heads}</tr><tr><td>before</td>{before}</tr><tr><td>after</td>{after}</tr></table>
<h2>Calibrated parameters</h2>
<table><tr><th>parameter</th><th>calibrated</th><th>knee point</th></tr>{params}</table>
{sens}
<p>Files: calibrated.yaml (the calibrated scenario), calibrated.json, calibrated.ssv (SSP parameter values),
calibrated.ssp (SSP package: the FMU bound to the calibrated values), knee.json,
pareto.csv, checkpoint.json.</p>
{psd}
</body></html>"""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(doc)
