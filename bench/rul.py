"""Benchmark: RUL error against life fraction on simulated run-to-failure histories (twin rul).

    python bench/rul.py [--seeds 10] [--out bench_out/rul_RESULTS.md]

For the lubricated (pitting) and the dry (wear) scenario:

1. the model trajectory D_model(N) is the co-simulated degradation run (run_degradation, the
   FMU's dynamic load), also used as the *shape* of the true damage;
2. each history is a gearbox degrading as D_true(N) = D_model(max(0, s N + tau)) with a true rate
   factor s in {0.6, 0.8, 1.25, 1.6} and a clock offset tau = f N_model(threshold),
   f ~ U(-0.1, 0.1) (seeded); its true failure is N_fail = (N_model(threshold) - tau) / s;
3. it is inspected every 2 % of its true life; each record is assessed by a simulated imperfect
   classifier (twin.rul.simulate_assessments: 90-97 % correct, mistakes go to a neighbouring
   stage, softmax output with random sharpness);
4. at 20, 40, 60 and 80 % of life the estimator (default settings) is fitted to the records so far
   and its RUL compared with the true one.  "model only" is the RUL the calibrated model gives
   without records (N_model(threshold) - now, i.e. s = 1, tau = 0).

A third block estimates the lubricated histories with the quasi-static trajectory
(method="static") while the truth follows the co-simulated one: a model-form error of a few %.

Thresholds: the last stage boundary (20 % pitting density, 240 um mean wear depth).
Writes a Markdown report (figures measured by this run) to --out and prints it.
"""
from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

RATES = (0.6, 0.8, 1.25, 1.6)
FRACTIONS = (0.2, 0.4, 0.6, 0.8)


def machine() -> str:
    try:
        model = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        model = next((ln.split(":", 1)[1].strip() for ln in model.splitlines() if ln.startswith("Model name")), "?")
    except OSError:
        model = "?"
    return (f"{model}, nproc {len(os.sched_getaffinity(0))}, Python {platform.python_version()}, "
            f"numpy {np.__version__}")


def histories(truth, model_traj, stages, threshold, seeds: int, base_seed: int):
    """Yield per (rate, seed, fraction) the estimate, the truth and the model-only RUL."""
    from twin.rul import RULEstimator, simulate_assessments
    life_model_truth = truth.cycles_at(threshold)
    life_model_est = model_traj.cycles_at(threshold)
    for r_i, s in enumerate(RATES):
        for seed in range(seeds):
            rng = np.random.default_rng([base_seed, r_i, seed])
            f = rng.uniform(-0.1, 0.1)
            tau = f * life_model_truth
            n_fail = (life_model_truth - tau) / s
            cycles = np.arange(0.01, 1.0, 0.02) * n_fail
            obs = simulate_assessments(truth, stages, cycles, rate=s, offset_cycles=tau,
                                       seed=int(rng.integers(2**31)))
            for frac in FRACTIONS:
                now = frac * n_fail
                m = int(np.searchsorted(cycles, now, side="right"))
                t = time.perf_counter()
                est = RULEstimator(model_traj, stages, threshold).fit(obs.head(m)).estimate(now=now)
                dt = time.perf_counter() - t
                d_true = float(truth.damage_at(s * now + tau))
                yield dict(rate=s, seed=seed, frac=frac, n_obs=m, rul_true=n_fail - now, est=est,
                           d_true=d_true, model_only=max(0.0, life_model_est - now), fit_s=dt)


def summarise(rows, kind: str) -> list[str]:
    from twin.rul import format_damage
    out = ["| life fraction | records | median abs. rel. error | 90th pct abs. rel. error | median signed error "
           "| 90 % band coverage | median band width / true RUL "
           "| median abs. error of current damage (density points / um) | model-only median abs. rel. error |",
           "|---|---|---|---|---|---|---|---|---|"]
    for frac in FRACTIONS:
        sel = [r for r in rows if r["frac"] == frac]
        rel = np.array([(r["est"].rul_cycles - r["rul_true"]) / r["rul_true"] for r in sel])
        cover = np.mean([r["est"].rul_band[0] <= r["rul_true"] <= r["est"].rul_band[1] for r in sel])
        width = np.array([(r["est"].rul_band[1] - r["est"].rul_band[0]) / r["rul_true"] for r in sel])
        derr = np.array([abs(r["est"].current_damage - r["d_true"]) for r in sel])
        model = np.array([abs(r["model_only"] - r["rul_true"]) / r["rul_true"] for r in sel])
        out.append(f"| {100 * frac:.0f} % | {np.median([r['n_obs'] for r in sel]):.0f} "
                   f"| {100 * np.median(np.abs(rel)):.1f} % | {100 * np.percentile(np.abs(rel), 90):.1f} % "
                   f"| {100 * np.median(rel):+.1f} % | {100 * cover:.0f} % ({len(sel)}) "
                   f"| {np.median(width):.2f} | {format_damage(float(np.median(derr)), kind)} "
                   f"| {100 * np.median(model):.1f} % |")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=10, help="histories per true rate factor")
    ap.add_argument("--out", default=str(REPO / "bench_out" / "rul_RESULTS.md"))
    args = ap.parse_args()
    from twin.rul import trajectory_from_scenario
    from twin.scenario import load_scenario

    lines = ["# `twin rul`: RUL error against life fraction (bench/rul.py)", "",
             f"Machine: {machine()}.", "",
             f"Histories: true rate factor s in {list(RATES)} x {args.seeds} seeds = "
             f"{len(RATES) * args.seeds} per scenario; clock offset f ~ U(-0.1, 0.1) of the model life; "
             "one record every 2 % of the true life, assessed by a simulated classifier 90-97 % correct "
             "(mistakes to a neighbouring stage). Estimator: default settings (prior ln s ~ N(0, ln 2) on "
             "[0.1, 10], f ~ U(-0.2, 0.2), floor 0.05, temperature 1, boundary width 0.1 stage). "
             "Errors are (estimated median RUL - true RUL) / true RUL; the band is the 5-95 % interval. "
             "'model only' is the calibrated model's RUL without records (s = 1, f = 0).", ""]
    timings = []
    static_lub = None
    for name in ("lubricated", "dry"):
        sc = load_scenario(REPO / "scenarios" / f"{name}.yaml")
        t = time.perf_counter()
        truth = trajectory_from_scenario(sc, method="cosim")
        timings.append(f"co-simulated trajectory '{name}': {time.perf_counter() - t:.1f} s "
                       f"({truth.cycles.size} points)")
        stages = tuple(float(b) for b in sc.archive["stages"])
        threshold = stages[-1]
        rows = list(histories(truth, truth, stages, threshold, args.seeds, base_seed=1 if name == "dry" else 0))
        fit = np.array([r["fit_s"] for r in rows])
        timings.append(f"fit + estimate '{name}': median {1e3 * np.median(fit):.0f} ms, "
                       f"max {1e3 * fit.max():.0f} ms ({fit.size} fits)")
        title = ("Lubricated (pitting density, 6 stages, threshold 20 %)" if name == "lubricated"
                 else "Dry (mean wear depth, 4 stages, threshold 240 um)")
        lines += [f"## {title}", "", f"Model life to the threshold: {truth.cycles_at(threshold):.3g} cycles.", ""]
        lines += summarise(rows, truth.kind) + [""]
        if name == "lubricated":
            t = time.perf_counter()
            static_lub = trajectory_from_scenario(sc, method="static")
            timings.append(f"quasi-static trajectory '{name}': {time.perf_counter() - t:.1f} s")
            mis = list(histories(truth, static_lub, stages, threshold, args.seeds, base_seed=0))
            lines += ["### Lubricated, estimated with the quasi-static trajectory (model-form error)", "",
                      f"Quasi-static model life {static_lub.cycles_at(threshold):.3g} cycles against "
                      f"{truth.cycles_at(threshold):.3g} co-simulated; same histories as above.", ""]
            lines += summarise(mis, truth.kind) + [""]
    lines += ["## Timing", ""] + [f"- {t}" for t in timings] + [""]
    lines += ["## Reading", "",
              "- Records only say which stage the damage is in, so the RUL is pinned down by stage "
              "transitions: before the first one (early life) the band is mostly the prior on the rate "
              "factor; each transition seen narrows it.",
              "- The quasi-static block measures a model-form error: the truth follows the co-simulated "
              "shape, the estimator a slightly different one, and the band does not account for that.", ""]
    text = "\n".join(lines)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(text)
    print(text)


if __name__ == "__main__":
    main()
