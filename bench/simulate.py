"""Benchmark: 10 s of the 21-DOF gearbox at 100 kHz output, three ways, side by side.

    python bench/simulate.py [--stop-time 10] [--ivp-span 0.05]

1. the FMU through ``twin.fmu`` with every output captured (buffered inside the FMU);
2. the same FMU in one bare ``doStep`` with no outputs (the floor for the generated code);
3. ``scipy.integrate.solve_ivp`` on the independent numpy equations (``twin.reference``).
   solve_ivp is far slower, so it runs ``--ivp-span`` seconds and its time is scaled
   linearly to ``--stop-time`` (stated in the output).

A second table gives the bare ``doStep`` of the variant with the gear's own tooth errors
(``GearTwin.Variants.Gearbox21WheelErrors``) and of the model with broadband excitation and
sensor paths (``GearTwin.Gearbox21Measured``) against the base model's, in the same run.
``--against DIR [DIR ...]`` adds the base model and that variant built from other Modelica trees
(an older revision: ``git archive REV modelica | tar -x -C DIR``). On a shared machine wall times
of separate runs drift with the load, so these are compared by CPU time: all FMUs are loaded
at once and advanced in turn by 0.2 s chunks (25 rounds); the median chunk, scaled to the span.

Accuracy is measured over the first 0.1 s against a converged run of the same FMU with a
step of 6.25e-7 s (RK4 error at 1.25e-6 s is already < 1e-6, see the model readme).
Prints a Markdown table for BENCHMARKS.md.
"""
from __future__ import annotations

import argparse
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

PAPER_SIMULINK_S = 120.0   # "it takes 2 minutes to generate the corresponding responses"


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b ** 2)))


def _interleaved(fmu_class, paths, step: float, span: float, chunk: float = 0.2, rounds: int = 25) -> list[float]:
    """CPU time [s] of a bare run over ``span`` for each FMU: all loaded at once and advanced in
    turn by ``chunk`` seconds, ``rounds`` times; the median chunk, scaled to ``span``."""
    fmus = [fmu_class(p).__enter__() for p in paths]
    try:
        times = [[] for _ in fmus]
        for fmu in fmus:
            fmu.setup(parameters={"solver.step_size": step})
        for _ in range(rounds):
            for fmu, t in zip(fmus, times):
                t0 = time.process_time()
                fmu.step(chunk)
                t.append(time.process_time() - t0)
        return [float(np.median(t)) * span / chunk for t in times]
    finally:
        for fmu in fmus:
            fmu.__exit__(None, None, None)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stop-time", type=float, default=10.0)
    ap.add_argument("--ivp-span", type=float, default=0.05)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--against", type=Path, nargs="+", default=[],
                    help="also time the models built from DIR/modelica (other revisions), interleaved")
    args = ap.parse_args()

    from fmu_build import build_fmu
    from twin.fmu import FMU, simulate_fmu
    from twin.reference import gearbox_numpy as ref

    fmu_path = build_fmu("GearTwin.Gearbox21", REPO / "modelica", REPO / "build")
    variant_path = build_fmu("GearTwin.Variants.Gearbox21WheelErrors", REPO / "modelica", REPO / "build")
    measured_path = build_fmu("GearTwin.Gearbox21Measured", REPO / "modelica", REPO / "build")
    T = args.stop_time
    rows = []
    for step in (5e-6, 1e-5):
        captured, bare, end_to_end = [], [], []
        for _ in range(args.repeats):
            with FMU(fmu_path) as fmu:                       # all 17 outputs at 100 kHz
                fmu.setup(parameters={"solver.step_size": step})
                t = time.perf_counter()
                fmu.run(T, 1e-5)
                captured.append(time.perf_counter() - t)
            with FMU(fmu_path) as fmu:
                fmu.setup(parameters={"solver.step_size": step})
                t = time.perf_counter()
                fmu.step(T)
                bare.append(time.perf_counter() - t)
            t = time.perf_counter()                          # + unzip, load, instantiate
            simulate_fmu(fmu_path, stop_time=T, output_interval=1e-5, step_size=step)
            end_to_end.append(time.perf_counter() - t)
        rows.append((step, min(captured), min(bare), min(end_to_end)))

    def bare_step(path, step):
        best = []
        for _ in range(args.repeats):
            with FMU(path) as fmu:
                fmu.setup(parameters={"solver.step_size": step})
                t = time.perf_counter()
                fmu.step(T)
                best.append(time.perf_counter() - t)
        return min(best)
    # interleaved, so that a change of machine load hits both models alike
    variant_rows = [(step, bare_step(fmu_path, step), bare_step(variant_path, step), bare_step(measured_path, step))
                    for step in (5e-6, 1e-5)]
    against_rows = []
    models = ("GearTwin.Gearbox21", "GearTwin.Variants.Gearbox21WheelErrors")
    for m, here in zip(models, (fmu_path, variant_path)):
        if args.against:
            others = [build_fmu(m, d / "modelica", REPO / "build" / "against" / str(k))
                      for k, d in enumerate(args.against)]
            against_rows.append((m, _interleaved(FMU, [here, *others], 5e-6, T)))

    # solve_ivp on the numpy equations (short span, scaled)
    params = ref.GearboxParams()
    inputs = {"motor_speed_ref": 2 * np.pi * 20, "drive_torque": 0.0, "load_torque": 20.0}
    t = time.perf_counter()
    t_ivp, y_ivp = ref.simulate_solve_ivp(params, inputs, args.ivp_span, 1e-5)
    ivp_span_wall = time.perf_counter() - t
    ivp_wall = ivp_span_wall * T / args.ivp_span

    # accuracy over 0.1 s against a converged FMU run
    span = min(0.1, args.ivp_span)
    truth = simulate_fmu(fmu_path, stop_time=span, output_interval=1e-5, step_size=6.25e-7)
    acc = {}
    for step, *_ in rows:
        r = simulate_fmu(fmu_path, stop_time=span, output_interval=1e-5, step_size=step)
        acc[step] = {n: _rel(r[n], truth[n]) for n in ("accel_pinion_casing", "mesh_force")}
    n_ivp = min(len(t_ivp), truth.time.size)
    acc_ivp = {n: _rel(np.asarray(y_ivp[n])[:n_ivp], truth[n][:n_ivp]) for n in ("accel_pinion_casing", "mesh_force")}

    cpu = "unknown"
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    gcc = subprocess.run(["gcc", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    print(f"Machine: {cpu}, {platform.machine()}, {len(__import__('os').sched_getaffinity(0))} cores, "
          f"Python {platform.python_version()}, {gcc}")
    print(f"Span: {T:g} s simulated, outputs every 1e-5 s (100 kHz), best of {args.repeats}\n")
    print("| run | internal step | wall time [s] | vs bare doStep | speed-up vs solve_ivp | speed-up vs paper's Simulink (120 s) | rel. RMS error accel / mesh force |")
    print("|---|---|---|---|---|---|---|")
    for step, cap, bare, e2e in rows:
        a = acc[step]
        print(f"| twin.fmu, outputs captured | {step:g} s | {cap:.2f} | {cap / bare:.2f}x | {ivp_wall / cap:.0f}x | "
              f"{PAPER_SIMULINK_S / cap:.0f}x | {a['accel_pinion_casing']:.1e} / {a['mesh_force']:.1e} |")
        print(f"| simulate_fmu end to end (unzip, load, run, outputs) | {step:g} s | {e2e:.2f} | {e2e / bare:.2f}x | "
              f"{ivp_wall / e2e:.0f}x | {PAPER_SIMULINK_S / e2e:.0f}x | same |")
        print(f"| bare doStep, no outputs | {step:g} s | {bare:.2f} | 1.00x | {ivp_wall / bare:.0f}x | "
              f"{PAPER_SIMULINK_S / bare:.0f}x | same |")
    print(f"| solve_ivp (numpy equations) | adaptive, rtol 1e-8 | {ivp_wall:.1f} (measured {ivp_span_wall:.2f} s for "
          f"{args.ivp_span:g} s, scaled) | - | 1x | {PAPER_SIMULINK_S / ivp_wall:.2f}x | "
          f"{acc_ivp['accel_pinion_casing']:.1e} / {acc_ivp['mesh_force']:.1e} |")
    print("\n| model, bare doStep | internal step | wall time [s] | vs GearTwin.Gearbox21 | speed-up vs paper's Simulink (120 s) |")
    print("|---|---|---|---|---|")
    for step, base, variant, measured in variant_rows:
        print(f"| GearTwin.Gearbox21 | {step:g} s | {base:.2f} | 1.00x | {PAPER_SIMULINK_S / base:.0f}x |")
        print(f"| GearTwin.Variants.Gearbox21WheelErrors | {step:g} s | {variant:.2f} | {variant / base:.2f}x | "
              f"{PAPER_SIMULINK_S / variant:.0f}x |")
        print(f"| GearTwin.Gearbox21Measured (broadband on, sensor paths) | {step:g} s | {measured:.2f} | "
              f"{measured / base:.2f}x | {PAPER_SIMULINK_S / measured:.0f}x |")
    if against_rows:
        trees = " | ".join(f"built from {d} [s]" for d in args.against)
        print(f"\n| model, bare doStep, 5e-06 s, CPU time | built from this tree [s] | {trees} |")
        print("|---|---|" + "---|" * len(args.against))
        for m, (here, *others) in against_rows:
            cells = " | ".join(f"{o:.2f} ({o / here:.2f}x)" for o in others)
            print(f"| {m} | {here:.2f} | {cells} |")

if __name__ == "__main__":
    main()
