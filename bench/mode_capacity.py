"""Diagnostic: can a twin model put modes on a rig gearbox's first six observable modes at all?

    python bench/mode_capacity.py [--rigs beam pedestal] [--seeds 56 57 58 59 60]
                                  [--models GearTwin.Gearbox21Overhangs GearTwin.Gearbox21Shafts]
                                  [--budget 300]

`bench/calibration_rigs.py` scores what `twin calibrate` reaches from a rig's records. This script
asks the question before it, with the rig's truth: for one gearbox (``Rig().scattered(seed, 0.12)``)
and the rig's first six observable modes (its own linearisation, observability >= 0.02, 10 Hz-5 kHz),
is there a parameter set within the twin's physical bounds (``candidate_parameters``, as
``parameters: auto`` draws from) whose modes meet all six, one twin mode to each rig mode?

Every oscillatory twin mode below 6 kHz counts (visible at the sensor or not, any class; not the
sensor path's), and the rig's modes are assigned to the twin's one to one (Hungarian) on the
absolute log-frequency error, capped at 0.3 so that one far mode does not dominate. CMA-ES (``cma``,
seed 1, start at the nominal values, step 0.15 of each log-range) minimises the sum of squares
within ``--budget`` evaluations. Reported per gearbox: the six errors, the twin's frequencies and the
parameters left within 1 % of the log-range of a bound. A pass here says only that the model's
frequencies can get there; it says nothing of the mode shapes, of visibility, or of what the records
let a calibration identify.
"""
from __future__ import annotations

import argparse
import importlib
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

KW = dict(speed_hz=20.0, load_nm=20.0, channels=("accel_pinion_casing", "accel_gear_casing"), fmax=6000.0)
#: Motor and brake inertias: they set modes far below the rig's first six, and the rig's have no
#: counterpart in its observable list.
LEFT_OUT = ("I1", "I13")


def one_gearbox(rig_name: str, seed: int, fmu: Path, budget: int) -> dict:
    import cma
    from scipy.optimize import linear_sum_assignment

    from calibration_rigs import observable_modes

    from twin.calibration.model_modes import model_modes
    from twin.calibration.sensitivity import candidate_parameters

    box = importlib.import_module(f"rigs.{rig_name}").Rig().scattered(seed, 0.12)
    target = observable_modes(box)[:6]
    cands = [c for c in candidate_parameters(fmu) if c.name not in LEFT_OUT]
    lo, hi = np.log([c.lower for c in cands]), np.log([c.upper for c in cands])
    nominal = np.log([c.nominal for c in cands])

    def frequencies(u):
        z = lo + (hi - lo) * np.clip(u, 0.0, 1.0)
        mm = model_modes(fmu, {c.name: float(np.exp(v)) for c, v in zip(cands, z)}, **KW)
        return mm.frequency[[i for i, c in enumerate(mm.classes) if c.name != "sensor path"]]

    def assign(f):
        e = np.abs(np.log(f[None, :] / target[:, None]))
        r, c = linear_sum_assignment(np.minimum(e, 0.3))
        return e[r, c], f[c]

    def cost(u):
        e, _ = assign(frequencies(u))
        return float(np.sum(np.minimum(e, 0.3) ** 2))

    t0 = time.time()
    es = cma.CMAEvolutionStrategy((nominal - lo) / (hi - lo), 0.15,
                                  {"bounds": [0, 1], "maxfevals": budget, "seed": 1, "verbose": -9})
    while not es.stop():
        xs = es.ask()
        es.tell(xs, [cost(x) for x in xs])
    u = np.asarray(es.result.xbest)
    e, f = assign(frequencies(u))
    return {"rig": rig_name, "seed": seed, "model": fmu.stem, "target_hz": np.round(target, 1).tolist(),
            "twin_hz": np.round(f, 1).tolist(), "errors_pc": np.round(100 * (np.exp(e) - 1), 2).tolist(),
            "on_bounds": [c.name for c, v in zip(cands, u) if v < 0.01 or v > 0.99],
            "parameters": len(cands), "evaluations": int(es.result.evaluations), "wall_s": round(time.time() - t0)}


def _pc(e: float) -> str:
    """An error as printed: beyond the cap of the assignment (log 0.3, 35 %) no mode was near."""
    return f"{e:.1f}" if e <= 100 * (np.exp(0.3) - 1) else "> 35"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rigs", nargs="+", default=["beam", "pedestal"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[56, 57, 58, 59, 60])
    ap.add_argument("--models", nargs="+", default=["GearTwin.Gearbox21Overhangs", "GearTwin.Gearbox21Shafts"])
    ap.add_argument("--budget", type=int, default=300, help="CMA-ES evaluations per gearbox and model")
    ap.add_argument("--out", type=Path, default=REPO / "bench_out" / "mode_capacity.json")
    args = ap.parse_args(argv)
    from fmu_build import build_fmu

    fmus = {m: Path(build_fmu(m, REPO / "modelica", REPO / "build")) for m in args.models}
    rows = []
    for rig in args.rigs:
        for seed in args.seeds:
            for m, fmu in fmus.items():
                r = one_gearbox(rig, seed, fmu, args.budget)
                rows.append(r)
                print(f"{rig} {seed} {m}: max {_pc(max(r['errors_pc']))} %, on bounds {r['on_bounds']}, "
                      f"{r['wall_s']} s", flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(rows, indent=1))
    print("\n| rig | model | gearboxes with all six within 3 % | ... and no parameter on a bound | "
          "largest error per gearbox [%] |\n|---|---|---|---|---|")
    for rig in args.rigs:
        for m in args.models:
            rs = [r for r in rows if r["rig"] == rig and r["model"] == m]
            ok = [max(r["errors_pc"]) <= 3.0 for r in rs]
            free = [o and not r["on_bounds"] for o, r in zip(ok, rs)]
            print(f"| {rig} | `{m}` | {sum(ok)}/{len(rs)} | {sum(free)}/{len(rs)} | "
                  + ", ".join(_pc(max(r["errors_pc"])) for r in rs) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
