"""Benchmark: degradation physics against published trends and the independent LTCA rig.

    python bench/degradation_trends.py build            # variant build times (18/35, 25/61)
    python bench/degradation_trends.py wear [--depth 1e-3]
    python bench/degradation_trends.py nodes            # convergence with n_profile
    python bench/degradation_trends.py pitting          # signature against rigs.ltca (black box)
    python bench/degradation_trends.py speed            # lubricated to 20 %, dry to 240 um
    python bench/degradation_trends.py rigs [--kind pitting] [--model M]   # the same features on rigs.pedestal, rigs.beam

``wear``: an 18/35 module-3 pair at 15 Hz / 10 N.m (light load), profile form deviation of
ISO 1328-1 class 7, coupled wear run to about 1 mm of mean pinion wear depth on 41 profile
nodes, the pairs' stiffness the LTCA's at the load (``pair_stiffness: contact``); at every stage
the casing RMS of 0.4 s records of a pinion with class-6 pitch deviations and run-out, worn in
under the load sharing as the flanks wear (:func:`worn_in`; so in ``rigs``).  Prints the RMS against depth, the Spearman rank correlation
after run-in (from the RMS minimum on), the worn/healthy ratio, and the contact-loss check at
eight stages: which pairs the FMU leaves unloaded against the LTCA of the same worn flanks at
each sample's elastic mesh force and roll positions
(:func:`twin.degradation.contact_check.contact_check`), at 15 Hz and quasi-statically (1 Hz),
beside the static LTCA at the mean force.

``pitting``: the lubricated test (19/52, 20 Hz / 20 N.m).  At pit densities 0..20 % the twin
(stage parameters of its coupled pitting run) and ``rigs.ltca`` (its own pitting physics, run
as a black box through the rigs interface) each give 2 s of casing acceleration; the features
are the levels of the first three mesh harmonics and their +-1, +-2 pinion-order sidebands,
in dB re. the healthy record of the same simulator, computed here (not by twin code).  At each
stage the Spearman rank correlation of the twin's 15 feature changes with the rig's.

``rigs``: the full-rig simulators ``rigs.pedestal`` and ``rigs.beam`` (black boxes through their
common interface, nominal gearbox, committed defaults) at the centres of their own wear stages
(10 Hz / 5 N.m, dry, 0-240 um) and pitting stages (20 Hz / 20 N.m, 2-20 %), and the twin (base
19/52 model, coupled runs of ``scenarios/dry.yaml`` and ``scenarios/lubricated.yaml``) at the same
damage (``--model``: another twin model for those runs, e.g. ``GearTwin.Gearbox21Measured`` with its
flank roughness and broadband excitation): casing RMS, mesh-harmonic level (first three) and pinion-order sideband level, each
against damage (Spearman, worn/healthy), and the per-stage Spearman of the 15 harmonic and
sideband changes of the twin against each rig's.

Prints Markdown for BENCHMARKS.md; writes bench_out/degradation_trends_<part>.json.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
OUT = REPO / "bench_out"


def machine() -> str:
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    load = os.getloadavg()[0]
    return (f"{cpu}, {len(os.sched_getaffinity(0))} cores, load average {load:.1f} at start, "
            f"Python {platform.python_version()}, {time.strftime('%Y-%m-%d')}")


def spearman(a, b) -> float:
    """Spearman rank correlation (average ranks for ties), implemented here."""
    def ranks(x):
        x = np.asarray(x, dtype=float)
        order = np.argsort(x, kind="mergesort")
        r = np.empty(x.size)
        r[order] = np.arange(x.size, dtype=float)
        for v in np.unique(x):
            tie = x == v
            r[tie] = r[tie].mean()
        return r
    ra, rb = ranks(a), ranks(b)
    ra, rb = ra - ra.mean(), rb - rb.mean()
    den = math.sqrt(float(np.sum(ra * ra) * np.sum(rb * rb)))
    return float(np.sum(ra * rb) / den) if den > 0 else float("nan")


def rms(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(np.sqrt(np.mean((x - x.mean()) ** 2)))


def pinion_errors(seed: int, teeth: int) -> dict:
    """Seeded pitch deviations and run-out of a real pinion, of the order of ISO 1328-1 class 6
    (single pitch deviations sd 2 um, run-out 10 um peak to peak), as ``tooth_deviation_offset``
    values; the same at every stage of a run."""
    rng = np.random.default_rng(seed)
    j = np.arange(teeth)
    errors = 2e-6 * rng.standard_normal(teeth) + 5e-6 * (1 + np.cos(2 * np.pi * j / teeth + rng.uniform(0, 2 * np.pi)))
    errors -= errors.min()
    return {f"tooth_deviation_offset[{k + 1}]": float(v) for k, v in enumerate(errors)}


def worn_in(manufacturing: dict, run, stage, load: float) -> dict:
    """``manufacturing``'s tooth offsets after ``stage``'s mean wear depth, worn under the record's
    quasi-static load sharing at the brake torque ``load`` [N.m] (as the twin's archive wears a
    pinion, twin.archive.load_sharing): each tooth's rigid part and its flank along the path
    (``tooth_pit_field``); unchanged at zero depth or for a pitting run."""
    from twin.archive import load_sharing
    from twin.record_gears import tooth_field_parameters
    sharing = load_sharing(run, stage.parameters, load)
    if sharing is None or stage.damage <= 0:
        return manufacturing
    teeth = len(manufacturing)
    offsets = np.array([manufacturing[f"tooth_deviation_offset[{k + 1}]"] for k in range(teeth)])
    return tooth_field_parameters(sharing.wear(offsets, np.ones(teeth), stage.damage))


# ---- build -----------------------------------------------------------------------------------
def part_build(args) -> dict:
    import tempfile

    from fmu_build import build_fmu
    from twin.variants import build_variant
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        build_fmu("GearTwin.Gearbox21", REPO / "modelica", Path(tmp), force=True)
        rows.append(("GearTwin.Gearbox21 (19/52, base)", time.perf_counter() - t, None))
        for sets in ({"z1": 18, "z2": 35}, {"z1": 25, "z2": 61}, {"z1": 18, "z2": 35, "n_profile": 41}):
            t = time.perf_counter()
            path = build_variant("GearTwin.Gearbox21", sets, out_dir=Path(tmp), force=True)
            wall = time.perf_counter() - t
            t = time.perf_counter()
            again = build_variant("GearTwin.Gearbox21", sets, out_dir=Path(tmp))
            cached = time.perf_counter() - t
            assert again == path
            rows.append((", ".join(f"{k}={v}" for k, v in sets.items()), wall, cached))
    print(f"Machine: {machine()}\n")
    print("| build | wall time [s] | cached [s] |")
    print("|---|---|---|")
    for name, wall, cached in rows:
        print(f"| {name} | {wall:.1f} | {'' if cached is None else f'{cached:.2f}'} |")
    return {"rows": rows}


# ---- wear ------------------------------------------------------------------------------------
def _wear_scenario(depth: float, n_profile: int, record: float):
    from twin.degradation.wear import iso1328_profile_form
    from twin.scenario import scenario_from_dict
    form = iso1328_profile_form(3e-3, 54e-3, 7)
    return scenario_from_dict({
        "version": 1, "name": "wear-18-35", "fmu": "GearTwin.Gearbox21", "stop_time": 1.0,
        "structural": {"z1": 18, "z2": 35, "n_profile": n_profile},
        "output": {"sample_rate": 50000, "variables": ["accel_pinion_casing"]},
        "operating": {"speed": {"constant": 15}, "load": {"constant": 10}},
        "degradation": {"model": "wear", "max_increment": 2.0e-5, "stop": {"wear_depth": depth}, "pair_stiffness": "contact",
                        "max_updates": 600, "load_window": 0.1, "record_duration": record,
                        "coefficients": {"form_deviation": form}},
        "seed": 0}, source=REPO / "scenarios" / "wear-18-35.yaml"), form


def contact_record(fmu_path: Path, parameters: dict, speed_hz: float, load: float, duration: float = 0.4):
    """Roll positions and elastic forces of the pairs, (m, 3) each, in a steady co-simulation with
    ``parameters`` after 0.2 s of settling."""
    from twin.fmu import FMU
    from twin.operating import consistent_start
    inputs = {"motor_speed_ref": 2 * math.pi * speed_hz, "load_torque": load}
    names = [f"roll[{i}]" for i in (1, 2, 3)] + [f"pair_force[{i}]" for i in (1, 2, 3)]
    with FMU(fmu_path) as fmu:
        fmu.setup(0.0, parameters=consistent_start(parameters, inputs, [v.name for v in fmu.parameters]),
                  inputs=inputs)
        fmu.capture(0.2, 2e-5, ["mesh_force"])
        block = fmu.capture(0.2 + duration, 2e-5, names)
    return block[:, :3], block[:, 3:]


def steady_rms(fmu_path: Path, parameters: dict, speed_hz: float, load: float, duration: float = 0.4) -> float:
    """Casing RMS [m/s2] of a steady record at ``speed_hz`` / ``load`` after 0.3 s of settling."""
    from twin.fmu import FMU
    from twin.operating import consistent_start
    inputs = {"motor_speed_ref": 2 * math.pi * speed_hz, "load_torque": load}
    with FMU(fmu_path) as fmu:
        fmu.setup(0.0, parameters=consistent_start(parameters, inputs, [v.name for v in fmu.parameters]),
                  inputs=inputs)
        fmu.capture(0.3, 2e-5, ["mesh_force"])
        return rms(fmu.capture(0.3 + duration, 2e-5, ["accel_pinion_casing"])[:, 0])


def part_wear(args) -> dict:
    from twin.degradation import WearState
    from twin.degradation.contact_check import contact_check
    from twin.degradation.ltca import contact_for
    from twin.degradation.wear import FlankWear
    from twin.degradation_run import run_degradation
    sc, form = _wear_scenario(args.depth, 41, 0.0)
    fmu = sc.fmu_path()
    t = time.perf_counter()
    run = run_degradation(sc, None, fmu_path=fmu, progress=True)
    wall = time.perf_counter() - t
    geometry = None
    rows = []
    model = FlankWear(form_deviation=form)
    from twin.degradation import GearPair
    geometry = GearPair(z1=18, z2=35)
    fresh = model.initial_state(geometry)
    force = 10.0 * 18 / 35 / geometry.base_radius_pinion
    check = set(np.unique(np.linspace(0, len(run.stages) - 1, 8).astype(int)))
    # the RMS records are of a real pinion: its pitch deviations and run-out (as in ``pitting``
    # and ``rigs``), worn in as the flanks wear (the load sharing levels the teeth); the contact
    # check keeps the teeth alike, as the LTCA has them
    manufacturing = pinion_errors(args.seed, 18)
    for i, s in enumerate(run.stages):
        teeth = worn_in(manufacturing, run, s, 10.0)
        row = {"cycles": s.cycles, "depth": s.damage, "max_depth": s.max_damage,
               "gear_max_depth": float(np.max(s.gear_field)) if s.gear_field is not None else 0.0,
               # as an inspection would: several records at slightly different speed and load
               "rms": float(np.mean([steady_rms(fmu, {**s.parameters, **teeth}, 15.0 * (1 + ds),
                                                10.0 * (1 + dl))
                                     for ds, dl in ((0.0, 0.0), (0.01, -0.05), (-0.01, 0.05))]))}
        if i in check:
            state = WearState(s.cycles, s.field_xi, s.field, geometry, s.gear_field,
                              fresh.pinion_form, fresh.gear_form)
            damage = FlankWear.damage(state)
            cycle = contact_for(geometry).mesh_cycle(force, damage, n_positions=64)
            inside = np.isfinite(cycle.slot_xi) & (cycle.slot_xi >= 0.02) & (cycle.slot_xi <= 0.98)
            row["ltca_pair_unloaded"] = float(np.sum(cycle.unloaded & inside) / np.sum(inside))
            row["ltca_te_p2p"] = cycle.te_peak_to_peak()
            # like with like: the LTCA at each sample's elastic mesh force and roll positions, at
            # speed (15 Hz) and quasi-static (1 Hz: mesh frequency 18 Hz, far below the mesh modes)
            for tag, hz in (("dyn", 15.0), ("qs", 1.0)):
                chk = contact_check(geometry, damage, *contact_record(fmu, s.parameters, hz, 10.0))
                row.update({f"{tag}_{k}": getattr(chk, k) for k in
                            ("no_pair", "fmu_unloaded", "ltca_unloaded", "unexplained", "missed", "agreement")})
        rows.append(row)
    depth = np.array([r["depth"] for r in rows])
    level = np.array([r["rms"] for r in rows])
    early = depth <= 0.1 * depth.max()
    start = int(np.argmin(np.where(early, level, np.inf)))
    rho = spearman(depth[start:], level[start:])
    ratio = level[-1] / level[0]
    print(f"Machine: {machine()}\n")
    print(f"18/35, module 3, 15 Hz / 10 N.m, form deviation {form * 1e6:.1f} um (ISO 1328-1 class 7), "
          f"{len(rows)} stages in {wall:.0f} s (coupled run); RMS: mean of three 0.4 s records (6 pinion "
          f"revolutions) at 15 Hz / 10 N.m, +1 % / -5 %, -1 % / +5 %, pinion with class-6 pitch deviations and run-out "
          f"worn in under load sharing\n")
    print("Pairs unloaded: share of pair-in-path samples with load; FMU / LTCA at each sample's elastic mesh "
          "force and roll positions / FMU unloaded where that LTCA loads (unexplained)\n")
    print("| mean depth [um] | max depth pinion / gear [um] | casing RMS [m/s2] | 15 Hz: no pair touching | "
          "15 Hz: pairs unloaded FMU / LTCA / unexplained | 1 Hz: the same | static LTCA at the mean force | "
          "LTCA static TE p-p [um] |")
    print("|---|---|---|---|---|---|---|---|")
    pct = lambda v: f"{100 * v:.1f}"  # noqa: E731
    for r in rows:
        if "ltca_pair_unloaded" not in r:
            continue
        print(f"| {r['depth'] * 1e6:.0f} | {r['max_depth'] * 1e6:.0f} / {r['gear_max_depth'] * 1e6:.0f} | "
              f"{r['rms']:.2f} | {pct(r['dyn_no_pair'])} % | {pct(r['dyn_fmu_unloaded'])} / "
              f"{pct(r['dyn_ltca_unloaded'])} / {pct(r['dyn_unexplained'])} % | {pct(r['qs_fmu_unloaded'])} / "
              f"{pct(r['qs_ltca_unloaded'])} / {pct(r['qs_unexplained'])} % | {pct(r['ltca_pair_unloaded'])} % | "
              f"{r['ltca_te_p2p'] * 1e6:.1f} |")
    print(f"\nRun-in ends at {depth[start] * 1e6:.0f} um (RMS minimum {level[start]:.2f} m/s2, healthy "
          f"{level[0]:.2f}); Spearman(RMS, depth) after it: {rho:.3f} over {len(rows) - start} stages; "
          f"worn/healthy RMS at {depth[-1] * 1e6:.0f} um: {ratio:.2f}")
    return {"rows": rows, "run_in_stage": start, "spearman": rho, "worn_over_healthy": ratio, "wall_s": wall}


# ---- nodes -----------------------------------------------------------------------------------
def part_nodes(args) -> dict:
    """The same worn flanks (a static LTCA wear loop to ~300 um) on 11, 21, 41, 81 nodes: the
    node fit's largest error and the casing RMS of a 0.4 s record.  The pair law is the LTCA's
    secant stiffness at the load, as in ``wear`` (``pair_stiffness: contact``)."""
    from twin.degradation import GearPair, TransmittedLoad, contact_k_pair, mesh_parameters
    from twin.degradation.wear import FlankWear, iso1328_profile_form
    from twin.fmu import FMU
    from twin.operating import consistent_start
    from twin.variants import build_variant
    g = GearPair(z1=18, z2=35)
    form = iso1328_profile_form(3e-3, 54e-3, 7)
    model = FlankWear(form_deviation=form)
    state = model.initial_state(g)
    load = TransmittedLoad(10.0 * 18 / 35 / g.base_radius_pinion)
    while state.mean_depth < args.depth:
        state = model.advance(state, load, model.cycles_for_increment(state, load, 94.0, 1e-5), 94.0)
    rows = []
    inputs = {"motor_speed_ref": 2 * math.pi * 15, "load_torque": 10.0}
    for n in (11, 21, 41, 81):
        fmu = build_variant("GearTwin.Gearbox21", {"z1": 18, "z2": 35, "n_profile": n})
        upd = mesh_parameters(g, wear=state, k_pair_healthy=contact_k_pair(g, load.force, n), n_nodes=n,
                              force=load.force)
        with FMU(fmu) as f:
            f.setup(0.0, parameters=consistent_start(upd.parameters, inputs, [v.name for v in f.parameters]),
                    inputs=inputs)
            f.capture(0.2, 2e-5, ["mesh_force"])
            x = f.capture(0.6, 2e-5, ["accel_pinion_casing"])[:, 0]
        rows.append((n, upd.truncation_error["profile_deviation"], rms(x)))
    print(f"Machine: {machine()}\n")
    print(f"Worn 18/35 flanks at {state.mean_depth * 1e6:.0f} um mean depth, 15 Hz / 10 N.m\n")
    print("| n_profile | largest node-fit error [um] | casing RMS [m/s2] |")
    print("|---|---|---|")
    for n, err, level in rows:
        print(f"| {n} | {err * 1e6:.2f} | {level:.2f} |")
    return {"rows": rows, "mean_depth": state.mean_depth}


# ---- pitting ---------------------------------------------------------------------------------
DENSITIES = (0.0, 0.033, 0.067, 0.1, 0.133, 0.167, 0.2)


def signature(x: np.ndarray, fs: float, nominal_hz: float, teeth: int) -> np.ndarray:
    """Levels [dB re 1 m/s2] of mesh harmonics 1-3 and their +-1, +-2 shaft-order sidebands.

    The shaft speed is read from the first mesh harmonic's peak near teeth x nominal; each level
    is the largest Hann-windowed amplitude within +-0.25 shaft orders of its frequency."""
    x = np.asarray(x, dtype=float) - np.mean(x)
    w = np.hanning(x.size)
    spec = np.abs(np.fft.rfft(x * w)) * 2 / w.sum()
    f = np.fft.rfftfreq(x.size, 1 / fs)
    band = (f > teeth * nominal_hz * 0.95) & (f < teeth * nominal_hz * 1.05)
    shaft = f[band][np.argmax(spec[band])] / teeth
    out = []
    for k in (1, 2, 3):
        for j in (0, -1, 1, -2, 2):
            target = k * teeth * shaft + j * shaft
            sel = np.abs(f - target) <= 0.25 * shaft
            out.append(20 * np.log10(max(float(spec[sel].max()), 1e-12)))
    return np.array(out)


def part_pitting(args) -> dict:
    from twin.degradation_run import run_degradation
    from twin.fmu import FMU
    from twin.operating import consistent_start
    from twin.scenario import load_scenario
    try:
        from rigs.ltca import LtcaRig, simulate_ltca
    except ImportError as exc:
        raise SystemExit(f"rigs.ltca is not available here ({exc})") from None
    sc = load_scenario(REPO / "scenarios" / "lubricated.yaml")
    d = {**sc.degradation, "stop": {"pitting_density": max(DENSITIES) + 0.005}, "record_duration": 0.0}
    fmu = sc.fmu_path()
    run = run_degradation(sc.with_overrides(degradation=d), None, fmu_path=fmu, progress=True)
    damage = run.damage
    inputs = {"motor_speed_ref": 2 * math.pi * 20, "load_torque": 20.0}
    twin_sig, rig_sig = [], []
    rig = LtcaRig()
    n = len(DENSITIES)
    # the rig as a black box through its public function: casing acceleration per record
    rig_records = simulate_ltca(rig, np.full(n, 20.0), np.full(n, 20.0), np.array(DENSITIES), "pitting_density",
                                2.0, gear_seed=args.seed, nominal_load=20.0, settle=0.3)
    # every real pinion has pitch deviations and run-out, the same at every stage
    manufacturing = pinion_errors(args.seed, 19)
    for r_i, dens in enumerate(DENSITIES):
        i = int(np.argmin(np.abs(damage - dens)))
        params = {**run.stages[i].parameters, **manufacturing}
        with FMU(fmu) as f:
            f.setup(0.0, parameters=consistent_start(params, inputs, [v.name for v in f.parameters]), inputs=inputs)
            f.capture(0.3, 2e-5, ["mesh_force"])
            x = f.capture(2.3, 2e-5, ["accel_pinion_casing"])[:, 0]
        twin_sig.append(signature(x, 50000.0, 20.0, 19))
        rig_sig.append(signature(rig_records[r_i], rig.sample_rate, 20.0, 19))
    twin_sig, rig_sig = np.array(twin_sig), np.array(rig_sig)
    dt, dr = twin_sig - twin_sig[0], rig_sig - rig_sig[0]
    per_stage = [spearman(dt[s], dr[s]) for s in range(1, len(DENSITIES))]
    names = [f"{k}x{'' if j == 0 else f'{j:+d}'}" for k in (1, 2, 3) for j in (0, -1, 1, -2, 2)]
    per_feature = {n: spearman(dt[:, c], dr[:, c]) for c, n in enumerate(names)}
    # The metric's ceiling: other gearboxes of the same rig (same physics, their own pitch errors,
    # run-outs and pits) scored against the scored one exactly as the twin is.
    others = {}
    for other in range(args.seed + 1, args.seed + 4):
        recs = simulate_ltca(rig, np.full(n, 20.0), np.full(n, 20.0), np.array(DENSITIES), "pitting_density",
                             2.0, gear_seed=other, nominal_load=20.0, settle=0.3)
        sig = np.array([signature(x, rig.sample_rate, 20.0, 19) for x in recs])
        d_o = sig - sig[0]
        others[other] = {"per_stage": [spearman(d_o[s], dr[s]) for s in range(1, n)],
                         "per_feature": [spearman(d_o[:, c], dr[:, c]) for c in range(len(names))]}
    print(f"Machine: {machine()}\n")
    print("| pit density | Spearman(twin, rig) over the 15 feature changes | another gearbox of the rig "
          f"(seeds {', '.join(map(str, others))}) against it |")
    print("|---|---|---|")
    for s, (dens, r) in enumerate(zip(DENSITIES[1:], per_stage)):
        row = ", ".join(f"{o['per_stage'][s]:.2f}" for o in others.values())
        print(f"| {100 * dens:.1f} % | {r:.2f} | {row} |")
    medians = ", ".join(f"{np.median(o['per_feature']):.2f}" for o in others.values())
    print("\nPer-feature Spearman over the densities, median of the 15: twin "
          f"{np.median(list(per_feature.values())):.2f}; the rig's other gearboxes {medians}\n")
    print("\n| feature | twin change at 20 % [dB] | rig change at 20 % [dB] | Spearman over densities |")
    print("|---|---|---|---|")
    for c, n in enumerate(names):
        print(f"| {n} | {dt[-1, c]:+.1f} | {dr[-1, c]:+.1f} | {per_feature[n]:.2f} |")
    return {"densities": DENSITIES, "twin": twin_sig.tolist(), "rig": rig_sig.tolist(), "per_stage": per_stage,
            "per_feature": per_feature, "rig_other_gearboxes": others}


# ---- rigs ------------------------------------------------------------------------------------
RIG_POINTS = {
    # kind: (damages at the centres of the rigs' stages plus healthy, speed [Hz], load [N m], scenario)
    "wear": ((0.0, 30e-6, 90e-6, 150e-6, 210e-6), 10.0, 5.0, "dry"),
    "pitting": ((0.0, 0.035, 0.065, 0.095, 0.125, 0.155, 0.185), 20.0, 20.0, "lubricated"),
}


def band_levels(sig: np.ndarray) -> tuple[float, float]:
    """Mesh-harmonic and sideband levels [dB re 1 m/s2] from a 15-feature ``signature`` row:
    energy sums of the three harmonics and of their +-1, +-2 shaft-order sidebands."""
    amp = 10 ** (np.asarray(sig) / 20)
    mesh = amp[0::5]
    side = np.concatenate([amp[k * 5 + 1:k * 5 + 5] for k in range(3)])
    return 10 * np.log10(np.sum(mesh ** 2)), 10 * np.log10(np.sum(side ** 2))


def _twin_stage_records(kind: str, damages, speed: float, load: float, scenario: str, duration: float,
                        manufacturing: dict, model: str | None = None) -> list[np.ndarray]:
    from twin.degradation_run import run_degradation
    from twin.fmu import FMU
    from twin.operating import consistent_start
    from twin.scenario import load_scenario
    sc = load_scenario(REPO / "scenarios" / f"{scenario}.yaml")
    if model:
        sc = sc.with_overrides(fmu=model)
    key = "wear_depth" if kind == "wear" else "pitting_density"
    d = {**sc.degradation, "stop": {key: max(damages) * 1.03}, "record_duration": 0.0}
    fmu = sc.fmu_path()
    run = run_degradation(sc.with_overrides(degradation=d), None, fmu_path=fmu, progress=False)
    inputs = {"motor_speed_ref": 2 * math.pi * speed, "load_torque": load}
    out = []
    for dmg in damages:
        i = int(np.argmin(np.abs(run.damage - dmg)))
        params = {**run.stages[i].parameters, **worn_in(manufacturing, run, run.stages[i], load)}
        with FMU(fmu) as f:
            f.setup(0.0, parameters=consistent_start(params, inputs, [v.name for v in f.parameters]),
                    inputs=inputs)
            f.capture(0.3, 2e-5, ["mesh_force"])
            out.append(f.capture(0.3 + duration, 2e-5, ["accel_pinion_casing"])[:, 0])
    return out


def part_rigs(args) -> dict:
    from rigs import beam, pedestal
    duration = 1.0
    # the twin gets the same seeded pitch deviations and run-out as in ``pitting`` (ISO 1328-1
    # class 6 order): a healthy real pinion has them, and without them it has no sidebands
    manufacturing = pinion_errors(args.seed, 19)
    result = {}
    print(f"Machine: {machine()}\n")
    for kind, (damages, speed, load, scenario) in RIG_POINTS.items():
        if args.kind and kind not in args.kind:
            continue
        t = time.perf_counter()
        sources = {"twin": [(x, 50000.0) for x in
                            _twin_stage_records(kind, damages, speed, load, scenario, duration, manufacturing,
                                                args.model)]}
        ped, bm = pedestal.Rig(), beam.Rig()
        sources["pedestal"] = []
        sources["beam"] = []
        for j, dmg in enumerate(damages):
            r = ped.steady(speed, load, duration, damage=None if dmg == 0 else (kind, dmg), seed=100 + j,
                           lubricated=kind == "pitting")
            sources["pedestal"].append((r["accel_pinion_casing"], r.sample_rate))
            r = bm.steady(speed, load, duration, damage=None if dmg == 0 else {kind: dmg}, seed=100 + j,
                          lubricated=kind == "pitting")
            sources["beam"].append((r.channels["accel_pinion_casing"], r.sample_rate))
        feats = {}
        for name, recs in sources.items():
            sig = np.array([signature(x, fs, speed, 19) for x, fs in recs])
            levels = np.array([band_levels(s) for s in sig])
            feats[name] = {"rms": [rms(x) for x, _ in recs], "mesh_db": levels[:, 0].tolist(),
                           "side_db": levels[:, 1].tolist(), "sig": sig.tolist()}
        wall = time.perf_counter() - t
        unit, scale = ("um", 1e6) if kind == "wear" else ("%", 100.0)
        print(f"**{kind}** ({speed:g} Hz / {load:g} N.m, {'dry' if kind == 'wear' else 'oil'}; "
              f"1 s records, pinion-side casing sensor; {wall:.0f} s)\n")
        print(f"| damage [{unit}] | " + " | ".join(f"{n} RMS [m/s2] / mesh / sidebands [dB]" for n in feats) + " |")
        print("|---" * (1 + len(feats)) + "|")
        for j, dmg in enumerate(damages):
            cells = [f"{f['rms'][j]:.2f} / {f['mesh_db'][j]:.1f} / {f['side_db'][j]:.1f}" for f in feats.values()]
            print(f"| {dmg * scale:.1f} | " + " | ".join(cells) + " |")
        summary = {}
        for n, f in feats.items():
            summary[n] = {"rho_rms": spearman(damages, f["rms"]), "rho_mesh": spearman(damages, f["mesh_db"]),
                          "rho_side": spearman(damages, f["side_db"]),
                          "rms_ratio": f["rms"][-1] / f["rms"][0],
                          "mesh_change_db": f["mesh_db"][-1] - f["mesh_db"][0],
                          "side_change_db": f["side_db"][-1] - f["side_db"][0]}
        print("\n| simulator | Spearman vs damage: RMS / mesh / sidebands | worn/healthy RMS | "
              "mesh / sideband change [dB] | per-stage Spearman of the 15 changes vs twin |")
        print("|---|---|---|---|---|")
        tw = np.array(feats["twin"]["sig"])
        for n, s in summary.items():
            if n == "twin":
                stage_rho = ""
            else:
                rg = np.array(feats[n]["sig"])
                rhos = [spearman(tw[j] - tw[0], rg[j] - rg[0]) for j in range(1, len(damages))]
                s["stage_rho"] = rhos
                stage_rho = " ".join(f"{r:.2f}" for r in rhos)
            print(f"| {n} | {s['rho_rms']:.2f} / {s['rho_mesh']:.2f} / {s['rho_side']:.2f} | {s['rms_ratio']:.2f} | "
                  f"{s['mesh_change_db']:+.1f} / {s['side_change_db']:+.1f} | {stage_rho} |")
        print()
        result[kind] = {"damages": list(damages), "features": feats, "summary": summary, "wall_s": wall}
    return result


# ---- speed -----------------------------------------------------------------------------------
def part_speed(args) -> dict:
    from twin.degradation_run import run_degradation
    from twin.scenario import load_scenario
    rows = []
    for name in ("lubricated", "dry"):
        sc = load_scenario(REPO / "scenarios" / f"{name}.yaml")
        fmu = sc.fmu_path()
        t, cpu = time.perf_counter(), time.process_time()
        run = run_degradation(sc, None, fmu_path=fmu, progress=False)
        rows.append((name, time.perf_counter() - t, time.process_time() - cpu, len(run.stages), run.summary()))
    print(f"Machine: {machine()}\n")
    # on a shared machine the wall time is an upper bound; the process's CPU time is not
    print("| scenario | wall time [s] | CPU time [s] | updates | reached |")
    print("|---|---|---|---|---|")
    for name, wall, cpu, n, summary in rows:
        print(f"| {name} | {wall:.1f} | {cpu:.1f} | {n} | {summary} |")
    return {"rows": rows}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("part", choices=("build", "wear", "nodes", "pitting", "speed", "rigs"))
    ap.add_argument("--depth", type=float, default=1.0e-3, help="wear: mean pinion depth to reach [m]")
    ap.add_argument("--seed", type=int, default=0, help="pitting: the rig's gear seed; the twin pinion's pitch deviations and run-out")
    ap.add_argument("--kind", action="append", choices=tuple(RIG_POINTS),
                    help="rigs: only this damage kind (repeatable; default both)")
    ap.add_argument("--model", help="rigs: the twin's model for its runs (default: the scenario's)")
    args = ap.parse_args()
    if args.part == "nodes" and args.depth == 1.0e-3:
        args.depth = 3.0e-4
    result = globals()[f"part_{args.part}"](args)
    OUT.mkdir(exist_ok=True)
    suffix = f"_{args.model.rsplit('.', 1)[-1]}" if getattr(args, "model", None) else ""
    (OUT / f"degradation_trends_{args.part}{suffix}.json").write_text(json.dumps(result, indent=1, default=float))


if __name__ == "__main__":
    main()
