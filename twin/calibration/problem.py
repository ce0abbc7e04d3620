"""Calibration as a multi-objective problem (paper Eq. 2-3), solved with pymoo.

``CalibrationProblem`` is a pymoo ``Problem`` over bounded FMU parameters. It evaluates a whole
population per call through an executor (local processes or Dask), one simulation and one
linearisation per candidate. An evaluation that fails (an FMU error, a diverging simulation)
is caught, logged and scored infeasible (constraint violation 1). It never stops the run.

``calibrate`` runs NSGA-II or MOGOA through ``pymoo.optimize.minimize``, checkpoints every
generation to JSON and picks the final parameter set from the Pareto front. The pick is the
paper's least-crowded rule (Eq. 9), and the knee point is offered too.
"""
from __future__ import annotations

import json
import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from twin.calibration.mode_search import SEARCH_BUDGET, check_fit, search_modes
from twin.errors import ParameterError

log = logging.getLogger(__name__)


#: Objectives a calibration can minimise (see the module docstring of each):
#: waveform = paper f1, 1 - corr of the synchronous averages; correlation = paper f2, 1 - corr of the
#: dB spectra; frequencies = paper f3, sum of squared mode errors [Hz^2]; modes = mean squared mode
#: error in units of each mode's uncertainty, against the modes a sensor sees (visible modes).
OBJECTIVES = ("waveform", "correlation", "frequencies", "modes")
SIGNAL_OBJECTIVES = ("waveform", "correlation")


@dataclass(frozen=True)
class CalibrationTarget:
    """What the model must reproduce: one measured record and the measured natural frequencies."""

    signal: np.ndarray                  # (n,) measured acceleration [m/s2]
    sample_rate: float                  # Hz
    drive_hz: float                     # commanded input speed of the record (drive setting) [Hz]
    load: float                         # brake torque [N.m]
    natural_frequencies: np.ndarray     # (k,) measured modes [Hz], foundation modes removed
    channel: str = "accel_pinion_casing"
    fmin: float = 10.0
    fmax: float = 5000.0
    shaft_hz: float | None = None       # actual pinion speed [Hz] (tacho); None: from the GMF line
    teeth: int = 19                     # pinion teeth, to find the GMF line
    objectives: tuple[str, ...] = ("waveform", "correlation", "frequencies")
    mode_rel_sd: np.ndarray | None = None   # (k,) relative uncertainty of each measured mode ("modes")
    mode_channels: tuple[str, ...] = ()     # sensors the measured modes were seen by (default: channel)
    mode_shapes: object | None = None       # MeasuredShapes of the measured modes at those sensors, or None
    mode_pairing: object | None = None      # Pairing at the nominal set (shape pairing), or None
    pairing: str = "frequency"              # how measured and model modes are paired (frequency or shape)
    visibility: str = "mesh"                # which excitations make a model mode visible (mesh or run-up)
    fit: str = "follow"                     # how the modes are fitted (twin.calibration.mode_search.FITS)
    search_budget: int = SEARCH_BUDGET      # linearisations of the search (fit: search)

    @property
    def needs_simulation(self) -> bool:
        return any(o in SIGNAL_OBJECTIVES for o in self.objectives)

    @property
    def rel_sd(self) -> np.ndarray:
        from twin.calibration.sensitivity import MODEL_FORM
        base = np.zeros(self.natural_frequencies.size) if self.mode_rel_sd is None else self.mode_rel_sd
        return np.sqrt(np.asarray(base, float) ** 2 + MODEL_FORM ** 2)

    @property
    def measured_shaft_hz(self) -> float:
        if self.shaft_hz is not None:
            return float(self.shaft_hz)
        from twin.calibration.objectives import estimate_shaft_hz
        return estimate_shaft_hz(self.signal, self.sample_rate, self.drive_hz, self.teeth)


@dataclass(frozen=True)
class EvalTask:
    fmu_path: str
    parameters: dict
    target: CalibrationTarget
    settle: float
    duration: float
    measured_shaft_hz: float


def evaluate_candidate(task: EvalTask) -> tuple[np.ndarray, dict]:
    """Objectives of one parameter set, in the order of ``target.objectives``. Raises on failure."""
    from twin.calibration.objectives import frequency_mismatch, spectrum_mismatch, waveform_mismatch
    from twin.linearize import modes, state_jacobian
    from twin.operating import operating_point, simulate_operating_point

    tg = task.target
    start, inputs = operating_point(tg.drive_hz, tg.load)
    params = {**task.parameters, **start}
    values: dict[str, float] = {}
    info: dict = {}
    if tg.needs_simulation:
        block = simulate_operating_point(task.fmu_path, tg.drive_hz, tg.load, parameters=task.parameters,
                                         settle=task.settle, duration=task.duration,
                                         channels=[tg.channel, "motor_speed"], output_interval=1.0 / tg.sample_rate)
        sim, speed = block[:, 0], block[:, 1]
        model_shaft_hz = float(np.mean(speed)) / (2 * math.pi)
        n = min(sim.size, tg.signal.size)
        if "waveform" in tg.objectives:
            values["waveform"] = waveform_mismatch(sim[:n], tg.signal[:n], tg.sample_rate, model_shaft_hz,
                                                   measured_shaft_hz=task.measured_shaft_hz)
        if "correlation" in tg.objectives:
            values["correlation"] = spectrum_mismatch(sim[:n], tg.signal[:n], tg.sample_rate, fmin=tg.fmin,
                                                      fmax=tg.fmax)
    if "frequencies" in tg.objectives:
        jac, _ = state_jacobian(task.fmu_path, parameters=params, inputs=inputs, settle=0.02, window=2.5e-3,
                                samples=4)
        freqs, _ = modes(jac)
        values["frequencies"] = frequency_mismatch(freqs[: tg.natural_frequencies.size + 4], tg.natural_frequencies)
        info["natural_frequencies"] = freqs[: tg.natural_frequencies.size + 4].tolist()
    if "modes" in tg.objectives:
        from twin.calibration.modal_fit import modes_objective
        values["modes"], matched = modes_objective(task.fmu_path, task.parameters, tg.natural_frequencies, tg.rel_sd,
                                                   speed_hz=tg.drive_hz, load_nm=tg.load,
                                                   channels=tg.mode_channels or (tg.channel,), shapes=tg.mode_shapes,
                                                   pairing=tg.pairing, visibility=tg.visibility)
        info["matched_frequencies"] = matched.tolist()
    return np.array([values[o] for o in tg.objectives]), info


def _guarded_eval(task: EvalTask, evaluate=None):
    try:
        return (evaluate or evaluate_candidate)(task)
    except Exception as exc:  # an FMU failure scores the candidate infeasible, it does not end the run
        return exc


@dataclass(frozen=True)
class _Evaluation:
    """Picklable ``task -> objectives`` for the executor's workers: ``evaluate`` or the default."""

    evaluate: object = None

    def __call__(self, task: EvalTask):
        return _guarded_eval(task, self.evaluate)


@dataclass(frozen=True)
class ParameterSpace:
    """Bounded FMU parameters to calibrate (names and [lower, upper] in their SI units)."""

    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def from_bounds(cls, bounds: Mapping[str, Sequence[float]]) -> "ParameterSpace":
        problems = [f"{k}: need [lower, upper] with lower < upper, got {v!r}" for k, v in bounds.items()
                    if len(v) != 2 or not (np.isfinite(v[0]) and np.isfinite(v[1]) and v[0] < v[1])]
        if problems or not bounds:
            raise ParameterError("bad calibration bounds: " + ("; ".join(problems) or "no parameters given"))
        names = tuple(bounds)
        return cls(names, np.array([bounds[n][0] for n in names], float), np.array([bounds[n][1] for n in names], float))

    def to_dict(self, x: np.ndarray) -> dict[str, float]:
        return {n: float(v) for n, v in zip(self.names, x)}


def make_problem(fmu_path: Path, space: ParameterSpace, target: CalibrationTarget, *, executor,
                 settle: float = 0.1, duration: float = 0.3, fixed: Mapping[str, float] | None = None,
                 evaluate=None):
    """A pymoo Problem with the target's objectives and 1 constraint (evaluation failed).

    ``evaluate`` (a picklable top-level function ``EvalTask -> (objectives, info)``) replaces
    :func:`evaluate_candidate`.  An evaluation that raises, or whose worker process dies or hangs
    past the executor's time limit, is logged with its parameters and the signal or error, and
    scored infeasible."""
    from pymoo.core.problem import Problem

    shaft_hz = target.measured_shaft_hz if target.needs_simulation else target.drive_hz   # once, not per candidate
    failed_score = {"waveform": 2.0, "correlation": 2.0, "frequencies": 1e12, "modes": 1e12}

    class CalibrationProblem(Problem):
        def __init__(self):
            super().__init__(n_var=len(space.names), n_obj=len(target.objectives), n_ieq_constr=1, xl=space.lower,
                             xu=space.upper)
            self.history: list[dict] = []

        def _evaluate(self, X, out, *args, **kwargs):
            tasks = [EvalTask(str(fmu_path), {**(fixed or {}), **space.to_dict(x)}, target, settle, duration,
                              shaft_hz) for x in X]
            results = executor.map(_Evaluation(evaluate), tasks, desc="calibration evaluations")
            F = np.empty((len(X), len(target.objectives)))
            G = np.zeros((len(X), 1))
            for i, r in enumerate(results):
                if isinstance(r, Exception):
                    log.warning("evaluation of %s failed and is scored infeasible: %s", tasks[i].parameters, r)
                    F[i] = [failed_score[o] for o in target.objectives]
                    G[i] = 1.0
                    self.history.append({"x": X[i].tolist(), "failed": str(r)})
                else:
                    F[i] = r[0]
                    self.history.append({"x": X[i].tolist(), "f": r[0].tolist()})
            out["F"] = F
            out["G"] = G

    return CalibrationProblem()


@dataclass(frozen=True)
class CalibrationResult:
    names: tuple[str, ...]
    X: np.ndarray                   # (m, d) Pareto-optimal parameter sets
    F: np.ndarray                   # (m, n_obj) their objectives, in the target's order
    chosen: dict[str, float]        # least-crowded pick (paper Eq. 9)
    knee: dict[str, float]
    n_evals: int
    algorithm: str
    failed_evals: int = 0
    history: list = field(default_factory=list)


def calibrate(fmu_path: Path, space: ParameterSpace, target: CalibrationTarget, *, algorithm: str = "mogoa",
              pop_size: int = 20, n_gen: int = 10, seed: int = 0, executor=None, checkpoint: Path | None = None,
              settle: float = 0.1, duration: float = 0.3, fixed: Mapping[str, float] | None = None,
              verbose: bool = False, resume: bool = False, refine: bool = False,
              nominal: Mapping[str, float] | None = None, evaluate=None,
              identity: str | None = None) -> CalibrationResult:
    """Calibrate ``space`` against ``target`` with MOGOA or NSGA-II (see the module docstring).

    ``refine`` polishes the pick on the modes alone: with the "modes" objective by the fit in
    log-parameters about ``nominal`` (default: the middle of the box in log) with the bounds as
    prior (:func:`twin.calibration.modal_fit.fit_modes`), else by :func:`refine_modes`.

    With ``resume=True`` and an existing ``checkpoint``, the run continues: the last checkpointed
    generation seeds the population and only the remaining generations are run. The evaluation
    history carries over. The random stream restarts, so a resumed run is not bit-identical to an
    uninterrupted one.  The checkpoint holds ``identity`` (default: :func:`calibration_identity`
    of the FMU, space, target and settings); a checkpoint of another calibration is refused with
    a :class:`~twin.errors.ResumeError` instead of being continued.

    ``evaluate`` replaces :func:`evaluate_candidate` (see :func:`make_problem`).
    """
    from twin.executor import LocalExecutor

    if algorithm not in ("mogoa", "nsga2"):
        raise ParameterError(f"algorithm must be 'mogoa' or 'nsga2', got {algorithm!r}")
    check_calibration_parameters(fmu_path, space, fixed)
    if identity is None:
        identity = calibration_identity(fmu_path, space, target, algorithm=algorithm, pop_size=pop_size,
                                        seed=seed, settle=settle, duration=duration, fixed=fixed)
    own = executor is None
    ex = executor or LocalExecutor(1)
    try:
        return _calibrate(fmu_path, space, target, ex, algorithm=algorithm, pop_size=pop_size, n_gen=n_gen, seed=seed,
                          checkpoint=checkpoint, settle=settle, duration=duration, fixed=fixed, verbose=verbose,
                          resume=resume, refine=refine, nominal=nominal, evaluate=evaluate, identity=identity)
    finally:
        if own:
            ex.close()


def calibration_identity(fmu_path: Path, space: ParameterSpace, target: CalibrationTarget, **settings) -> str:
    """SHA-256 over what decides a calibration's evaluations: the FMU file, the bounds, the
    measured target and the settings (algorithm, population, seed, windows, fixed parameters)."""
    import hashlib
    h = hashlib.sha256()
    with open(fmu_path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    fields = {k: getattr(target, k) for k in ("sample_rate", "drive_hz", "load", "channel", "fmin", "fmax", "shaft_hz",
                                              "teeth", "objectives") if hasattr(target, k)}
    if getattr(target, "pairing", "frequency") != "frequency":     # the default keeps earlier identities
        fields["pairing"] = target.pairing
    if getattr(target, "visibility", "mesh") != "mesh":
        fields["visibility"] = target.visibility
    h.update(json.dumps({"names": list(space.names), "lower": space.lower.tolist(), "upper": space.upper.tolist(),
                         "settings": {k: (dict(v) if isinstance(v, Mapping) else v) for k, v in settings.items()},
                         "target": fields,
                         "modes": np.asarray(target.natural_frequencies, float).tolist()},
                        sort_keys=True, default=str).encode())
    h.update(np.ascontiguousarray(np.asarray(target.signal, dtype=np.float64)).tobytes())
    return h.hexdigest()


def check_calibration_parameters(fmu_path: Path, space: ParameterSpace, fixed: Mapping[str, float] | None) -> None:
    """Refuse, before the first evaluation, names the FMU does not have as Real parameters and
    bounds or values that make no physical sense (a negative stiffness, damping, mass, ...)."""
    from twin.fmu import FMU
    from twin.plausibility import physical_problems
    with FMU(fmu_path) as fmu:
        variables = fmu.variables
        problems = []
        for name in [*space.names, *(fixed or {})]:
            v = variables.get(name)
            if v is None:
                close = [n for n in variables if name.lower() in n.lower()][:5]
                problems.append(f"{fmu.model_name} has no parameter {name!r}" + (f" (similar: {', '.join(close)})"
                                                                                if close else ""))
            elif v.causality != "parameter" or v.type != "Real":
                problems.append(f"{name!r} is a {v.type} {v.causality}, not a Real parameter")
        units = {n: v.unit for n, v in variables.items()}
    for name, lo in zip(space.names, space.lower):
        problems += physical_problems({name: float(lo)}, units, what="lower bound of")
    problems += physical_problems(dict(fixed or {}), units)
    if problems:
        raise ParameterError("calibration refused before the first evaluation: " + "; ".join(problems))


def _read_checkpoint(checkpoint: Path) -> dict:
    from twin.errors import ResumeError
    try:
        ck = json.loads(Path(checkpoint).read_text())
        int(ck["generation"])
        list(ck["history"])
    except OSError as exc:
        raise ResumeError(f"cannot read checkpoint '{checkpoint}': {exc.strerror or exc}") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise ResumeError(f"checkpoint '{checkpoint}' is damaged or not a calibration checkpoint "
                          f"({type(exc).__name__}: {exc}); delete it to start afresh") from None
    return ck


def _calibrate(fmu_path, space, target, ex, *, algorithm, pop_size, n_gen, seed, checkpoint, settle, duration, fixed,
               verbose, resume, refine, nominal, evaluate, identity) -> CalibrationResult:
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    from twin.calibration import MOGOA, knee_point, least_crowded
    from twin.errors import ResumeError
    problem = make_problem(Path(fmu_path), space, target, executor=ex, settle=settle, duration=duration, fixed=fixed,
                           evaluate=evaluate)
    done, sampling = 0, None
    if resume and checkpoint is not None and Path(checkpoint).exists():
        ck = _read_checkpoint(Path(checkpoint))
        if ck.get("names") != list(space.names) or ck.get("algorithm") != algorithm:
            raise ResumeError(f"checkpoint {checkpoint} is for {ck.get('algorithm')} over {ck.get('names')}, "
                              f"not {algorithm} over {list(space.names)}")
        if ck.get("identity") != identity:
            raise ResumeError(f"checkpoint {checkpoint} belongs to another calibration (its FMU, bounds, "
                              "measurement or settings differ); resume refused; remove it or use another --out")
        done = int(ck["generation"])
        problem.history.extend(ck["history"])
        sampling = np.array([h["x"] for h in ck["history"][-pop_size:]])
        if done >= n_gen:
            log.info("checkpoint %s already holds %d generations", checkpoint, done)
    kwargs = {"sampling": sampling} if sampling is not None else {}
    algo = (MOGOA(pop_size=pop_size, archive_size=max(2 * pop_size, 20), **kwargs) if algorithm == "mogoa"
            else NSGA2(pop_size=pop_size, **kwargs))

    def save(alg):
        if checkpoint is None:
            return
        from twin._atomic import atomic_path
        data = {"algorithm": algorithm, "generation": done + int(alg.n_gen), "names": list(space.names),
                "identity": identity, "history": problem.history}
        with atomic_path(checkpoint) as tmp:
            Path(tmp).write_text(json.dumps(data))

    res = minimize(problem, algo, ("n_gen", max(n_gen - done, 1)), seed=seed + done, callback=save, verbose=verbose)
    X = np.atleast_2d(res.X)
    F = np.atleast_2d(res.F)
    pick = least_crowded(F)
    knee = knee_point(F)
    failed = sum(1 for h in problem.history if "failed" in h)
    chosen = space.to_dict(X[pick])
    modal = [o for o in ("modes", "frequencies") if o in target.objectives]
    if refine and modal:
        # polish from the front member with the best mode fit, not from an extreme of the front
        start = X[int(np.argmin(F[:, target.objectives.index(modal[0])]))]
        if modal[0] == "modes":
            from twin.calibration.modal_fit import fit_modes
            mid = np.sqrt(space.lower * space.upper)
            nom = np.array([float((nominal or {}).get(n, m)) for n, m in zip(space.names, mid)])
            # from the nominal set, where the modes were matched, following them step by step: a
            # population member far from it may hold two modes in swapped places
            kw = dict(fixed=dict(fixed or {}), speed_hz=target.drive_hz, load_nm=target.load,
                      channels=target.mode_channels or (target.channel,), shapes=target.mode_shapes,
                      pairing=target.pairing, visibility=target.visibility)
            x0, start_pairing = nom, target.mode_pairing
            if check_fit(target.fit) == "search":
                # paired afresh at every candidate set; the descent then starts from a pairing made there
                x0, _ = search_modes(Path(fmu_path), space.names, space.lower, space.upper, nom,
                                     target.natural_frequencies, target.rel_sd, executor=ex, seed=seed,
                                     budget=target.search_budget, progress=verbose, **kw)
                start_pairing = None
            chosen = space.to_dict(fit_modes(Path(fmu_path), space.names, space.lower, space.upper, nom, x0,
                                             target.natural_frequencies, target.rel_sd,
                                             start_pairing=start_pairing, **kw))
        else:
            chosen = space.to_dict(refine_modes(Path(fmu_path), space, target, start, fixed=fixed))
    return CalibrationResult(space.names, X, F, chosen, space.to_dict(X[knee]),
                             len(problem.history), algorithm, failed, problem.history)


def refine_modes(fmu_path: Path, space: ParameterSpace, target: CalibrationTarget, x0: np.ndarray, *,
                 fixed: Mapping[str, float] | None = None, max_nfev: int = 150) -> np.ndarray:
    """Polish a calibrated point on f3 alone: bounded least squares on the relative mode errors.

    The population search (MOGOA/NSGA-II) finds the right basin; near the optimum, a
    trust-region least-squares step (scipy ``least_squares``, finite differences in normalised
    parameters) converges in tens of linearisations where the swarm would need thousands of
    simulations. Residuals are (f_model - f_measured) / f_measured over the matched modes.
    Returns the refined parameter vector, shape (d,).
    """
    from scipy.optimize import least_squares

    from twin.calibration.objectives import match_modes
    from twin.linearize import modes, state_jacobian
    from twin.operating import operating_point

    tg = target
    start, inputs = operating_point(tg.drive_hz, tg.load)
    span = space.upper - space.lower
    k = tg.natural_frequencies.size

    def residuals(z):
        x = space.lower + z * span
        params = {**(fixed or {}), **space.to_dict(x), **start}
        jac, _ = state_jacobian(fmu_path, parameters=params, inputs=inputs, settle=0.02, window=2.5e-3, samples=4)
        fr, _ = modes(jac)
        fr = fr[: k + 4]
        return (fr[match_modes(fr, tg.natural_frequencies)] - tg.natural_frequencies) / tg.natural_frequencies

    z0 = np.clip((np.asarray(x0, float) - space.lower) / span, 0.0, 1.0)
    sol = least_squares(residuals, z0, bounds=(0.0, 1.0), diff_step=1e-3, max_nfev=max_nfev, x_scale=1.0)
    return space.lower + sol.x * span


def write_parameter_set(parameters: Mapping[str, float], path: str | Path, *, name: str = "calibrated",
                        fmu: str | Path | None = None) -> Path:
    """Write a parameter set as JSON (``.json``) or an SSP parameter-value file (``.ssv``), atomically.

    With ``fmu`` given, the ``.ssv`` gives each Real in the unit of the FMU variable and defines
    that unit (its BaseUnit) in the file, so that another SSP tool reads the values correctly.
    """
    from twin._atomic import atomic_path
    path = Path(path)
    if path.suffix == ".json":
        text = json.dumps({"parameters": {k: float(v) for k, v in parameters.items()}}, indent=2)
    elif path.suffix == ".ssv":
        from twin.ssv import write_ssv
        units, fmu_units = {}, {}
        if fmu is not None:
            from twin.fmu import FMU
            with FMU(fmu) as f:
                units = {k: f.variables[k].unit for k in parameters if k in f.variables and f.variables[k].unit}
                fmu_units = f.unit_definitions
        return write_ssv(parameters, path, name=name, units=units, fmu_units=fmu_units)
    else:
        from twin.errors import OutputPathError
        raise OutputPathError(f"parameter set path must end in .json or .ssv, got {path.suffix!r}")
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text)
    return path
