"""Interoperability figures: the twin's FMUs and SSP packages in other FMI/SSP tools.

Builds GearTwin.Gearbox21 as FMI 2.0 and FMI 3.0, then measures side by side in one run:

- fmpy validate on both FMUs;
- fmpy's simulation of the FMI 3.0 build against the FMI 2.0 build (largest difference of any
  output relative to its range);
- OSP libcosim running the FMI 2.0 FMU, and an .ssp of it with three parameter values, against
  twin.fmu with the same values (same measure).

Accuracy only: wall times here would compare an unzip and setup with a bare stepping loop.

    python bench/interop.py [--stop-time 0.1] [--step 1e-4] [--out bench_out/interop]
"""
from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
VALUES = {"kt12": 1800.0, "c_mesh": 900.0, "mesh_stiffness_scale": 0.9}


def max_rel(a: np.ndarray, b: np.ndarray) -> float:
    scale = np.abs(b).max(axis=0)
    scale[scale == 0] = 1.0
    return float((np.abs(a - b).max(axis=0) / scale).max())


def twin_run(fmu, names, stop, step, values=None):
    from twin.fmu import FMU
    with FMU(fmu) as f:
        f.setup(0.0, parameters=values)
        r = f.run(stop, step)
    return np.column_stack([r.signals[n] for n in names])[1:]


def libcosim_run(execution, names, steps):
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimObserver import CosimObserver
    obs = CosimObserver.create_last_value()
    execution.add_observer(obs)
    reals = {v.name.decode(): v.reference for v in execution.slave_variables(0)
             if v.type == CosimVariableType.REAL.value}
    refs = [reals[n] for n in names]
    rows = []
    for _ in range(steps):
        execution.step(1)
        rows.append(obs.last_real_values(0, refs))
    return np.array(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stop-time", type=float, default=0.1)
    ap.add_argument("--step", type=float, default=1e-4)
    ap.add_argument("--out", default=str(REPO / "bench_out" / "interop"))
    args = ap.parse_args()
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimSlave import CosimLocalSlave

    from fmu_build import build_fmu
    from twin.fmu import FMU
    from twin.ssp import write_ssp

    log_output_level(CosimLogLevel.ERROR)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fmu2 = build_fmu("GearTwin.Gearbox21", REPO / "modelica", out)
    fmu3 = build_fmu("GearTwin.Gearbox21", REPO / "modelica", out / "fmi3", fmi_version=3)
    steps = int(round(args.stop_time / args.step))
    rows = [("fmpy validate, FMI 2.0", f"{len(validate_fmu(str(fmu2)))} problems"),
            ("fmpy validate, FMI 3.0", f"{len(validate_fmu(str(fmu3)))} problems")]
    r2 = simulate_fmu(str(fmu2), stop_time=args.stop_time, output_interval=args.step, step_size=args.step)
    r3 = simulate_fmu(str(fmu3), stop_time=args.stop_time, output_interval=args.step, step_size=args.step)
    names = [n for n in r2.dtype.names if n != "time"]
    a = np.column_stack([r3[n] for n in names])
    b = np.column_stack([r2[n] for n in names])
    rows.append(("fmpy simulate, FMI 3.0 vs FMI 2.0", f"{max_rel(a, b):.1e}"))
    with FMU(fmu2) as f:
        outputs = [v.name for v in f.outputs]
    ours = twin_run(fmu2, outputs, args.stop_time, args.step)
    ex = CosimExecution.from_step_size(step_size=int(round(args.step * 1e9)))
    ex.add_local_slave(CosimLocalSlave(fmu_path=str(fmu2), instance_name="gearbox"))
    rows.append(("libcosim FMU vs twin.fmu", f"{max_rel(libcosim_run(ex, outputs, steps), ours):.1e}"))
    ssp = write_ssp(fmu2, VALUES, out / "gearbox.ssp")
    ours = twin_run(fmu2, outputs, args.stop_time, args.step, VALUES)
    theirs = libcosim_run(CosimExecution.from_ssp_file(str(ssp)), outputs, steps)
    rows.append((f"libcosim .ssp ({', '.join(VALUES)}) vs twin.fmu", f"{max_rel(theirs, ours):.1e}"))
    print(f"GearTwin.Gearbox21, {args.stop_time} s at a {args.step:g} s communication step, {len(outputs)} outputs; "
          f"{platform.processor() or platform.machine()}, {time.strftime('%Y-%m-%d')}")
    print()
    print("| check | max relative difference (or result) |")
    print("|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} |")


if __name__ == "__main__":
    main()
