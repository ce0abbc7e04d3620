"""The Reference FMUs (modelica/Reference-FMUs) through `twin simulate`, against fmpy.

Builds the FMUs from a source checkout with cmake and gcc, for FMI 2.0 and FMI 3.0, then runs
each as a new user would, `twin simulate MODEL.fmu --output r.h5` (and `r.csv`) with no other
option, and compares every output with `fmpy.simulate_fmu(MODEL.fmu)`: the sample times, and
every output's values and dtype (HDF5; the CSV's values at full precision). With no options both
take the output interval by fmpy's rule (FMI 3.0's `fixedInternalStepSize`, else `stepSize`,
doubled until the run has at most 1000 intervals).

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
            rows.append((model, f"{version}.0", f"{len(own[0])} / {len(ref)}",
                         "identical" if identical(own[0], ref) else "DIFFERENT",
                         "equal" if equal[1] and shared[1] == len(ref) == len(own[1]) else "DIFFERENT",
                         "yes" if own[0].ended_by_fmu else "no",
                         ", ".join(f"{k} [{u}]" for k, u in own[0].units.items() if u) or "-"))
    print(f"Reference FMUs, FMI 2.0 and 3.0 Co-Simulation, built with cmake/gcc; "
          f"{platform.processor() or platform.machine()}, {time.strftime('%Y-%m-%d')}")
    print()
    print("| model | FMI | samples twin / fmpy | HDF5 vs fmpy | CSV vs fmpy | ended by the FMU | units |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
