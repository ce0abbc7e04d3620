"""A second, independent simulator of the test gearbox: "measured" data the twin did not make.

The assessor must be judged on target data that did not come from the twin.
The emulated rigs of :mod:`twin.transfer.domain` vary the twin's own 21-DOF FMU, so they share its
mesh-stiffness table, its wear and pitting mappings and its shaft-bearing-pedestal dynamics.  This
module shares none of that code or those parameters: it is a different *model family* of the same
gearbox, written from the gear datasheet alone.  Its results are therefore a test of how far the
assessor's robustness rests on physics rather than on the twin's particular equations.

=============================  =====================================================================
part                           this simulator (defaults in :class:`LumpedRig`)
=============================  =====================================================================
structure                      one degree of freedom: the dynamic transmission error ``x`` [m] along
                               the line of action, ``m_e x'' = F0 - F_mesh``; no shafts, bearings,
                               pedestals or drive line (the twin has 21 DOF)
gear bodies                    solid steel disks of the pitch radius and face width,
                               ``m_e = 1 / (rb1^2/I1 + rb2^2/I2)``
pair stiffness                 ISO 6336-1 single-pair stiffness ``c' b`` (14 N/(mm um)) at mid path,
                               falling to 60 % at the path's ends as ``0.6 + 0.4 sin(pi u)``
contact                        unilateral, per tooth pair: ``f_j = k_j (x - e_j + beta x')`` while
                               ``x > e_j``, 0 otherwise; ``beta`` gives 8 % of critical damping
tooth errors                   per-tooth pitch error (normal, 2 um sd) and pinion run-out (6 um peak to
                               peak), fixed for the gearbox, at a random start angle per record
wear                           Archard profile ``e(u) = h w_i s(u)``, ``s ~ |u - u_pitch|`` times the
                               load share (1 in the single-pair zone, 1/2 in the double-pair zones),
                               mean 1 over the path; ``h`` the mean wear depth, ``w_i`` a per-tooth
                               factor (sd 10 %) fixed for the gearbox
pitting                        lost contact width: ``k_j -> k_j (1 - d_i(u))``, local density
                               ``d_i(u) = D a_i b(u)`` clipped to 0.95, ``b`` a Gaussian band centred
                               in the pinion's dedendum single-pair zone (mean 1 over the path),
                               ``a_i`` per-tooth factors (gamma, sd 50 %) fixed for the gearbox
transfer path                  the dynamic mesh force drives four casing modes (1.35, 2.9, 5.2, 8.4 kHz,
                               2-6 % damping); the channel is their summed acceleration
acquisition                    51.2 kHz (the twin writes 100 kHz), per-record gain (10 % log-normal),
                               white noise 8 % of the record RMS, speed and load scatter 2 % / 10 %
=============================  =====================================================================

The stage variable keeps its meaning: ``D`` is the pitted fraction of the active flank area, ``h``
the mean wear depth of the pinion flank, both drawn within the scenario's stages by the archive's
own rule (:func:`twin.archive.stage_damage`).  The integration is a fixed-step RK4 at four times the
acquisition rate (4.9 us, below the 5 us the 21-DOF model needs), vectorised over records; the
casing response is filtered at that rate and decimated with an anti-alias FIR.

Nothing here was tuned to the assessor: the defaults were set from the datasheet and textbook
values once (2026-11-23), before the first assessment was run on it.

Command line (the records of a scenario's stages, e.g. for ``twin benchmark-transfer --target``)::

    python -m rigs.lumped target SCENARIO --out FILE.h5 [--records-per-stage 15] [--record-duration 0.4]
                                 [--seed 3] [--damage-sampling snapshot] [--damage-scatter 0.1] [--no-progress]
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from twin.errors import ParameterError, ScenarioError

__all__ = ["LumpedRig", "check_records", "field_problems", "make_lumped_target", "mesh_geometry", "mode_problems",
           "simulate_lumped", "write_simulated_target"]

STEEL_DENSITY = 7850.0          # kg/m3
ISO_SINGLE_PAIR_STIFFNESS = 14e9    # N/m per m of face width (ISO 6336-1 c' = 14 N/(mm um))


@dataclass(frozen=True)
class LumpedRig:
    """The independent simulator's gearbox, casing and acquisition (module docstring for the physics).

    Attributes
    ----------
    teeth : tuple of int
        Pinion and gear tooth numbers.
    module, pressure_angle, face_width : float
        Normal module [m], pressure angle [rad], face width [m].
    damping_ratio : float
        Mesh damping as a fraction of critical [-].
    pitch_error, runout : float
        Per-tooth pitch error sd [m]; pinion run-out peak to peak [m].
    wear_tooth_scatter, pitting_tooth_scatter : float
        Relative sd of the per-tooth wear and pitting factors [-].
    pit_band_width : float
        Sd of the pitting band along the path of contact, as a fraction of it [-].
    modes_hz, modes_damping, modes_gain : tuple of float
        Casing modes: frequency [Hz], damping ratio [-], relative participation [-].
    sample_rate : float
        Acquisition rate [Hz].
    substeps : int
        RK4 steps per acquired sample.
    gain_error, noise, speed_scatter, load_scatter : float
        As in :class:`twin.transfer.domain.TargetShift`.
    """

    teeth: tuple = (19, 52)
    module: float = 3e-3
    pressure_angle: float = math.radians(20.0)
    face_width: float = 0.020
    damping_ratio: float = 0.08
    pitch_error: float = 2e-6
    runout: float = 6e-6
    wear_tooth_scatter: float = 0.10
    pitting_tooth_scatter: float = 0.5
    pit_band_width: float = 0.12
    modes_hz: tuple = (1350.0, 2900.0, 5200.0, 8400.0)
    modes_damping: tuple = (0.03, 0.04, 0.05, 0.06)
    modes_gain: tuple = (0.6, 1.0, 0.7, 0.4)
    sample_rate: float = 51200.0
    substeps: int = 4
    gain_error: float = 0.10
    noise: float = 0.08
    speed_scatter: float = 0.02
    load_scatter: float = 0.10

    def __post_init__(self) -> None:
        problems = []
        if (len(self.teeth) != 2 or not all(isinstance(z, int) and z >= 10 for z in self.teeth)):
            problems.append(f"teeth must be two integers >= 10, got {self.teeth!r}")
        problems += field_problems(self, ("module", "pressure_angle", "face_width", "damping_ratio", "sample_rate"),
                                   ("pitch_error", "runout", "wear_tooth_scatter", "pitting_tooth_scatter",
                                    "pit_band_width", "gain_error", "noise", "speed_scatter", "load_scatter"))
        if not (isinstance(self.substeps, int) and self.substeps >= 1):
            problems.append(f"substeps must be a positive integer, got {self.substeps!r}")
        problems += mode_problems(self)
        if problems:
            raise ParameterError("LumpedRig: " + "; ".join(problems))


def field_problems(rig, positive: tuple, nonnegative: tuple) -> list[str]:
    """What is wrong with a rig's fields that must be finite and > 0, or finite and >= 0."""
    problems = []
    for names, ok, rule in ((positive, lambda v: v > 0, "> 0"), (nonnegative, lambda v: v >= 0, ">= 0")):
        for name in names:
            v = getattr(rig, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and ok(v)):
                problems.append(f"{name} must be a finite number {rule}, got {v!r}")
    return problems


def mode_problems(rig) -> list[str]:
    """What is wrong with a rig's casing modes (``modes_hz``, ``modes_damping``, ``modes_gain``)."""
    modes = (rig.modes_hz, rig.modes_damping, rig.modes_gain)
    if len({len(m) for m in modes}) != 1 or not rig.modes_hz:
        return ["modes_hz, modes_damping and modes_gain must have the same, non-zero length"]
    if any(not 0 < f < rig.sample_rate / 2 for f in rig.modes_hz) or any(d <= 0 for d in rig.modes_damping):
        return [f"casing modes must lie in (0, {rig.sample_rate / 2:g}) Hz with damping > 0, "
                f"got {rig.modes_hz!r} / {rig.modes_damping!r}"]
    return []


def check_records(speeds, loads, damages, kind: str, start_angles) -> tuple[np.ndarray, ...]:
    """Checked (speeds, loads, damages, start angles) of a batch of records, each (R,) float.

    Raises :class:`ParameterError` naming the bad values: an unknown damage ``kind``, arrays of
    different lengths, speeds or loads not finite and > 0, damages not finite and >= 0.
    """
    if kind not in ("pitting_density", "wear_depth"):
        raise ParameterError(f"damage kind must be 'pitting_density' or 'wear_depth', got {kind!r}")
    speeds, loads, damages = (np.asarray(a, dtype=float) for a in (speeds, loads, damages))
    if not (speeds.shape == loads.shape == damages.shape and speeds.ndim == 1):
        raise ParameterError("speeds, loads and damages must be 1-D arrays of one length")
    bad = [f"{name} {a[~ok].tolist()[:5]}" for name, a, ok in (
        ("speeds", speeds, np.isfinite(speeds) & (speeds > 0)), ("loads", loads, np.isfinite(loads) & (loads > 0)),
        ("damages", damages, np.isfinite(damages) & (damages >= 0))) if not ok.all()]
    if bad:
        raise ParameterError("speeds and loads must be finite and > 0, damages finite and >= 0; got " + ", ".join(bad))
    start = np.zeros_like(speeds) if start_angles is None else np.asarray(start_angles, dtype=float)
    if start.shape != speeds.shape:
        raise ParameterError("start_angles must have one angle per record")
    return speeds, loads, damages, start


@dataclass(frozen=True)
class MeshGeometry:
    """Involute spur-pair quantities derived from the datasheet."""

    contact_ratio: float        # transverse contact ratio [-]
    roll_pitch: float           # roll position of the pitch point on the path (0 start, 1 end) [-]
    base_radii: tuple           # (rb1, rb2) [m]
    equivalent_mass: float      # m_e [kg]
    pair_stiffness: float       # c' b, peak single-pair stiffness [N/m]


def mesh_geometry(rig) -> MeshGeometry:
    """The standard involute relations (addendum = one module, no profile shift) of any rig with the
    datasheet fields ``teeth``, ``module``, ``pressure_angle`` and ``face_width``."""
    z1, z2 = rig.teeth
    r1, r2 = 0.5 * rig.module * z1, 0.5 * rig.module * z2
    rb1, rb2 = r1 * math.cos(rig.pressure_angle), r2 * math.cos(rig.pressure_angle)
    ra1, ra2 = r1 + rig.module, r2 + rig.module
    approach2 = math.sqrt(ra2 ** 2 - rb2 ** 2)
    path = math.sqrt(ra1 ** 2 - rb1 ** 2) + approach2 - (r1 + r2) * math.sin(rig.pressure_angle)
    eps = path / (math.pi * rig.module * math.cos(rig.pressure_angle))
    start = (r1 + r2) * math.sin(rig.pressure_angle) - approach2        # from T1, the pinion root end
    roll_pitch = (r1 * math.sin(rig.pressure_angle) - start) / path
    inertia = [0.5 * STEEL_DENSITY * math.pi * rig.face_width * r ** 4 for r in (r1, r2)]
    m_e = 1.0 / (rb1 ** 2 / inertia[0] + rb2 ** 2 / inertia[1])
    return MeshGeometry(eps, roll_pitch, (rb1, rb2), m_e, ISO_SINGLE_PAIR_STIFFNESS * rig.face_width)


def _profile_shapes(g: MeshGeometry, band_width: float, n: int = 2001):
    """(u grid, Archard wear shape, pitting band), both with mean 1 over the path of contact."""
    u = np.linspace(0.0, 1.0, n)
    eps = g.contact_ratio
    single = (u >= (eps - 1) / eps) & (u <= 1 / eps)
    wear = np.abs(u - g.roll_pitch) * np.where(single, 1.0, 0.5)
    centre = 0.5 * ((eps - 1) / eps + g.roll_pitch)      # the dedendum single-pair zone, below pitch
    band = np.exp(-0.5 * ((u - centre) / max(band_width, 1e-3)) ** 2)
    return u, wear / wear.mean(), band / band.mean()


def simulate_lumped(rig: LumpedRig, speeds, loads, damages, kind: str, duration: float, *, gear_seed: int,
                    start_angles=None, settle: float = 0.05) -> np.ndarray:
    """Casing acceleration of records of the lumped model, before gain and noise.

    Parameters
    ----------
    speeds, loads, damages : array_like, shape (R,)
        Pinion speed [Hz], brake (output) torque [N.m], and the stage variable (pitting density
        [-] or mean wear depth [m]) per record.
    kind : {"pitting_density", "wear_depth"}
    duration : float
        Record length after ``settle`` [s].
    gear_seed : int
        Seeds the gearbox's tooth errors and per-tooth factors: one seed, one gearbox.
    start_angles : array_like, shape (R,), optional
        Pinion angle at the start of each record [rad] (default 0).

    Returns
    -------
    ndarray, shape (R, round(duration * rig.sample_rate))
        Acceleration [arbitrary but consistent units, m/s2 per N of mesh force].
    """
    from scipy.signal import bilinear, decimate, lfilter

    speeds, loads, damages, start_angle = check_records(speeds, loads, damages, kind, start_angles)
    g = mesh_geometry(rig)
    z1 = rig.teeth[0]
    rng = np.random.default_rng(gear_seed)
    pitch_err = rig.pitch_error * rng.standard_normal(z1)
    wear_factor = 1.0 + rig.wear_tooth_scatter * rng.standard_normal(z1)
    shape_k = 1.0 / max(rig.pitting_tooth_scatter, 1e-3) ** 2
    pit_factor = rng.gamma(shape_k, 1.0 / shape_k, z1)
    runout_phase = rng.uniform(0, 2 * np.pi)

    u_grid, wear_shape, band = _profile_shapes(g, rig.pit_band_width)
    eps, m_e, k_peak = g.contact_ratio, g.equivalent_mass, g.pair_stiffness
    omega_n = math.sqrt(k_peak * eps / m_e)
    beta = 2 * rig.damping_ratio / omega_n
    f0 = loads / g.base_radii[1]                                  # N, static mesh force
    n_pairs = int(math.ceil(eps))
    j = np.arange(n_pairs)

    # The contact state depends on time only, so RK4's two mid-point stages share one, and only the
    # damage term of the record's kind is evaluated (the other is zero).
    def contact(t):
        """(pair stiffness, flank deviation, pair in contact), each (R, J), at time ``t``."""
        theta = 2 * np.pi * speeds * t + start_angle              # (R,)
        p = theta * z1 / (2 * np.pi)
        n = np.floor(p)
        u = ((p - n)[:, None] + j) / eps                          # (R, J)
        tooth = ((n[:, None] - j) % z1).astype(np.intp)
        uc = np.minimum(u, 1.0)
        k = k_peak * (0.6 + 0.4 * np.sin(np.pi * uc))
        runout = (0.5 * rig.runout * (1 - np.cos(theta + runout_phase)))[:, None]
        if kind == "pitting_density":
            k = k * (1.0 - np.minimum(0.95, damages[:, None] * pit_factor[tooth] * np.interp(uc, u_grid, band)))
            e = pitch_err[tooth] + runout
        else:
            e = damages[:, None] * wear_factor[tooth] * np.interp(uc, u_grid, wear_shape) + pitch_err[tooth] + runout
        return k, e, u < 1.0

    def mesh_force(state, x, v):
        k, e, active = state
        delta = x[:, None] - e
        f = np.where(active & (delta > 0), np.maximum(k * (delta + beta * v[:, None]), 0.0), 0.0)
        return f.sum(axis=1)

    h = 1.0 / (rig.sample_rate * rig.substeps)
    n_settle = int(round(settle / h))
    n_keep = int(round(duration * rig.sample_rate)) * rig.substeps
    # start at the static deflection on the leading pair, so the transient is short
    _, e_start, active_start = contact(0.0)
    x = e_start.min(axis=1, where=active_start, initial=np.inf) + f0 / (k_peak * eps)
    v = np.zeros_like(x)
    force = np.empty((speeds.size, n_keep))
    for step in range(n_settle + n_keep):
        t = step * h
        mid = contact(t + h / 2)
        fa = mesh_force(contact(t), x, v)
        a1 = (f0 - fa) / m_e
        fb = mesh_force(mid, x + h / 2 * v, v + h / 2 * a1)
        a2 = (f0 - fb) / m_e
        fc = mesh_force(mid, x + h / 2 * (v + h / 2 * a1), v + h / 2 * a2)
        a3 = (f0 - fc) / m_e
        fd = mesh_force(contact(t + h), x + h * (v + h / 2 * a2), v + h * a3)
        a4 = (f0 - fd) / m_e
        x, v = x + h * (v + h / 6 * (a1 + a2 + a3)), v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        if step >= n_settle:
            force[:, step - n_settle] = fa
        if not np.all(np.isfinite(x)):
            from twin.errors import SimulationError
            raise SimulationError(f"the lumped model diverged at t = {t:.4g} s")
    force -= force.mean(axis=1, keepdims=True)
    fs = rig.sample_rate * rig.substeps
    acc = np.zeros_like(force)
    for fm, zeta, gain in zip(rig.modes_hz, rig.modes_damping, rig.modes_gain):
        w = 2 * fs * math.tan(math.pi * fm / fs)                  # pre-warped [rad/s]
        b, a = bilinear([1.0, 0.0, 0.0], [1.0, 2 * zeta * w, w ** 2], fs=fs)
        acc += gain * lfilter(b, a, force, axis=1)
    if rig.substeps > 1:
        acc = decimate(acc, rig.substeps, ftype="fir", axis=1, zero_phase=True)
    return acc


def make_lumped_target(source_scenario, output: str | Path, *, records_per_stage: int = 15,
                       record_duration: float = 0.4, seed: int = 3, rig: LumpedRig | None = None,
                       progress: bool = True) -> Path:
    """Simulate the target domain of ``source_scenario``'s stages on the lumped model; write it.

    The counterpart of :func:`twin.transfer.domain.make_target_domain` with the same file layout:
    channel ``accel_pinion_casing`` [m/s2, arbitrary scale] at ``rig.sample_rate``, attributes
    ``label``, ``damage`` (evaluation only), ``nominal_speed``, ``load``; metadata ``stages``,
    ``damage_kind``, ``lumped_rig`` (JSON).  Only the scenario's stages, damage kind (its
    degradation model) and nominal operating point are read; its FMU is not used.
    """
    rig = rig or LumpedRig()
    return write_simulated_target(
        source_scenario, output, rig, lambda *a, nominal_load, **k: simulate_lumped(rig, *a, **k), name="lumped",
        records_per_stage=records_per_stage, record_duration=record_duration, seed=seed, progress=progress,
        note="independent lumped simulator (rigs.lumped); labels and damage are for evaluation only")


def write_simulated_target(source_scenario, output: str | Path, rig, simulate, *, name: str,
                           records_per_stage: int, record_duration: float, seed: int, progress: bool,
                           note: str) -> Path:
    """Draw the records of an independent simulator's target domain, simulate them, write them.

    The part every simulator that is not the twin shares: which damage, operating point, sensor
    gain and start angle each record gets, the noise, and the file layout of
    :func:`make_lumped_target`.  ``rig`` is a frozen dataclass with the fields ``speed_scatter``,
    ``load_scatter``, ``gain_error``, ``noise`` and ``sample_rate``; it is saved as the metadata
    entry ``f"{name}_rig"`` (JSON).  ``simulate(speeds, loads, damages, kind, duration, *,
    gear_seed, start_angles, nominal_load)`` returns the records' acceleration before gain and
    noise, shape (R, round(duration * rig.sample_rate)); ``nominal_load`` is the scenario's brake
    torque [N.m], the load the damage grew under.
    """
    from twin._progress import progress_bar
    from twin.archive import nominal_operating_point, stage_damage
    from twin.measurements import MeasurementSet, Record, write_measurements
    from twin.transfer.domain import check_target_request

    spec, target = check_target_request(source_scenario, output, records_per_stage, record_duration)
    model = (source_scenario.degradation or {}).get("model")
    kinds = {"pitting": "pitting_density", "wear": "wear_depth"}
    if model not in kinds:
        raise ScenarioError([(str(source_scenario.source), "degradation.model",
                              f"the {name} rig simulates 'pitting' or 'wear', got {model!r}")])
    bounds = [float(b) for b in spec["stages"]]
    nominal_speed, nominal_load = nominal_operating_point(source_scenario)
    seq_draw, seq_gear, seq_noise = np.random.SeedSequence(seed).spawn(3)
    draw = np.random.default_rng(seq_draw)
    gear_seed = int(seq_gear.generate_state(1)[0])
    meta = []
    for s, (lo, hi) in enumerate(zip(bounds, bounds[1:])):
        for _ in range(records_per_stage):
            d = stage_damage(draw, lo, hi, spec)
            f = nominal_speed * (1 + rig.speed_scatter * float(draw.standard_normal()))
            t_load = nominal_load * (1 + rig.load_scatter * float(draw.standard_normal()))
            gain = float(np.exp(rig.gain_error * draw.standard_normal()))
            angle = float(draw.uniform(0, 2 * np.pi))     # where the shaft happens to be
            meta.append((s, d, f, t_load, gain, angle))
    s_, d_, f_, l_, g_, a_ = (np.array(c) for c in zip(*meta))
    acc = np.empty((len(meta), int(round(record_duration * rig.sample_rate))))
    chunk = 30      # records simulated together: vectorised, and a bar that moves
    bar = progress_bar(len(meta), progress, f"{name} rig", "record")
    try:
        for i in range(0, len(meta), chunk):
            sl = slice(i, i + chunk)
            acc[sl] = simulate(f_[sl], l_[sl], d_[sl], kinds[model], float(record_duration),
                               gear_seed=gear_seed, start_angles=a_[sl], nominal_load=nominal_load)
            bar.update(acc[sl].shape[0])
    finally:
        bar.close()
    noise_rng = np.random.default_rng(seq_noise)
    records = []
    for k in range(len(meta)):
        x = g_[k] * acc[k]
        x = x + noise_rng.normal(0.0, rig.noise * float(np.sqrt(np.mean(x ** 2))), size=x.shape)
        records.append(Record(f"rec{k:05d}", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"},
                              rig.sample_rate, nominal_speed=float(f_[k]), load=float(l_[k]), label=int(s_[k]),
                              damage=float(d_[k])))
    metadata = {"stages": np.asarray(bounds), "damage_kind": kinds[model], f"{name}_rig": json.dumps(asdict(rig)),
                "seed": int(seed), "source_scenario": source_scenario.name, "note": note}
    return write_measurements(MeasurementSet(tuple(records), None, (), metadata), target)


def main(argv=None, *, make=None, prog: str = "python -m rigs.lumped") -> int:
    """``target SCENARIO --out FILE.h5 ...``: write the records of the scenario's stages simulated by
    ``make`` (default :func:`make_lumped_target`); return the exit code (0 ok, 2 bad input)."""
    import argparse
    import sys

    from twin.errors import TwinError
    from twin.scenario import load_scenario

    make = make or make_lumped_target
    ap = argparse.ArgumentParser(prog=prog, description="Records of an independent simulator of the gearbox.")
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("target", help="labelled records of the stages of a scenario's archive block")
    p.add_argument("scenario", metavar="SCENARIO", help="scenario YAML with degradation (pitting or wear) and "
                                                        "archive blocks: its stages and nominal operating point")
    p.add_argument("--out", required=True, help="measurement HDF5 to write (atomically)")
    p.add_argument("--records-per-stage", type=int, default=15)
    p.add_argument("--record-duration", type=float, default=0.4, help="[s]")
    p.add_argument("--seed", type=int, help="seed of the gearbox and of every draw (default: the simulator's)")
    p.add_argument("--damage-sampling", choices=("uniform", "snapshot"),
                   help="overrides the archive block's: records spread over each stage or at its centre")
    p.add_argument("--damage-scatter", type=float, help="overrides the archive block's (snapshot sampling)")
    p.add_argument("--no-progress", action="store_true")
    args = ap.parse_args(argv)
    try:
        sc = load_scenario(args.scenario)
        overrides = {k: v for k, v in (("damage_sampling", args.damage_sampling),
                                       ("damage_scatter", args.damage_scatter)) if v is not None}
        if overrides:
            if sc.archive is None:
                raise ScenarioError([(str(sc.source), "archive", "the scenario has no archive block")])
            sc = sc.with_overrides(archive={**sc.archive, **overrides})
        seed = {} if args.seed is None else {"seed": args.seed}
        out = make(sc, args.out, records_per_stage=args.records_per_stage, record_duration=args.record_duration,
                   progress=not args.no_progress, **seed)
    except TwinError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
    print(out)
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(main())
