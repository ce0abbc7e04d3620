"""The Reference FMUs (modelica/Reference-FMUs) through `twin simulate`, against fmpy.

Builds the FMUs from a source checkout with cmake and gcc, for FMI 2.0 and FMI 3.0, then runs
each as a new user would, `twin simulate MODEL.fmu --output r.h5` (and `r.csv`) with no other
option, and compares every output with `fmpy.simulate_fmu(MODEL.fmu)`:

- on the twin's own sample grid (the model's `stepSize`), the samples whose times fmpy also has;
- with `--output-interval` set to the interval fmpy picks (it doubles `stepSize`, or FMI 3.0's
  `fixedInternalStepSize`, until the run has at most 1000 intervals), the whole result.

    python bench/reference_fmus.py --source PATH/TO/Reference-FMUs [--out bench_out/reference_fmus]
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
MODELS = ["BouncingBall", "Dahlquist", "VanDerPol", "Feedthrough", "Resource", "Stair"]
TWIN = str(Path(sys.executable).parent / "twin")


def build(source: Path, out: Path, version: int) -> Path:
    """cmake build of the Reference FMUs for one FMI version -> the folder of the .fmu files."""
    where = out / f"build{version}"
    # gcc 12+ warns about a strncpy in Resource/model.c, and the project builds with -Werror
    subprocess.run(["cmake", "-S", str(source), "-B", str(where), f"-DFMI_VERSION={version}",
                    "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_C_FLAGS=-Wno-error=stringop-truncation"],
                   check=True, capture_output=True)
    subprocess.run(["cmake", "--build", str(where)], check=True, capture_output=True)
    return where / "fmus"


def fmpy_interval(fmu: Path) -> float | None:
    """The output interval fmpy.simulate_fmu picks for a Co-Simulation run with no options from
    the model's step (None: the model gives none, and fmpy and the twin both use fmpy's
    automatic interval)."""
    from fmpy import read_model_description
    md = read_model_description(str(fmu))
    ex = md.defaultExperiment
    start, stop = float(ex.startTime or 0.0), float(ex.stopTime)
    fixed = getattr(md.coSimulation, "fixedInternalStepSize", None)
    if fixed is None and ex.stepSize is None:
        return None
    interval = float(fixed) if fixed is not None else float(ex.stepSize)
    while (stop - start) / interval > 1000:
        interval *= 2
    return interval


def twin_simulate(fmu: Path, out: Path, *extra: str):
    from twin.results import read_result
    proc = subprocess.run([TWIN, "simulate", str(fmu), "--output", str(out), "--no-progress", *extra],
                          capture_output=True, text=True)
    if proc.returncode:
        raise RuntimeError(f"twin simulate {fmu.name} {' '.join(extra)}: exit {proc.returncode}: {proc.stderr}")
    return read_result(out)


def same_on_shared_times(result, ref) -> tuple[int, bool]:
    shared = np.intersect1d(result.time, ref["time"])
    ia, ib = np.searchsorted(result.time, shared), np.searchsorted(ref["time"], shared)
    return len(shared), all(np.array_equal(result[n][ia], ref[n][ib]) for n in ref.dtype.names[1:])


def identical(result, ref) -> bool:
    return (np.array_equal(result.time, ref["time"])
            and all(np.array_equal(result[n], ref[n]) and result[n].dtype == ref[n].dtype
                    for n in ref.dtype.names[1:]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source", required=True, help="a checkout of github.com/modelica/Reference-FMUs")
    ap.add_argument("--out", default=str(REPO / "bench_out" / "reference_fmus"))
    args = ap.parse_args()
    from fmpy import simulate_fmu

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for version in (2, 3):
        fmus = build(Path(args.source), out, version)
        for model in MODELS:
            fmu = fmus / f"{model}.fmu"
            ref = simulate_fmu(str(fmu))
            own = [twin_simulate(fmu, out / f"{model}{version}{suffix}") for suffix in (".h5", ".csv")]
            shared, equal = zip(*(same_on_shared_times(r, ref) for r in own))
            interval = fmpy_interval(fmu)
            on_fmpy_grid = own[0] if interval is None else twin_simulate(
                fmu, out / f"{model}{version}_fmpy_grid.h5", "--output-interval", repr(interval))
            rows.append((model, f"{version}.0", f"{len(own[0])} / {len(ref)}",
                         f"{shared[0]}: {'equal' if all(equal) else 'DIFFERENT'}",
                         "identical" if identical(on_fmpy_grid, ref) else "DIFFERENT",
                         "yes" if own[0].ended_by_fmu else "no",
                         ", ".join(f"{k} [{u}]" for k, u in own[0].units.items() if u) or "-"))
    print(f"Reference FMUs, FMI 2.0 and 3.0 Co-Simulation, built with cmake/gcc; "
          f"{platform.processor() or platform.machine()}, {time.strftime('%Y-%m-%d')}")
    print()
    print("| model | FMI | samples twin / fmpy | shared times: outputs (HDF5 and CSV) | "
          "on fmpy's grid | ended by the FMU | units |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
