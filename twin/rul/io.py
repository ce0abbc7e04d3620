"""RUL output (the JSON document, the plot) and ``run_rul``, everything ``twin rul`` does."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from twin.errors import OutputPathError, ScenarioError
from twin.rul.base import RUL_FORMAT, RULError, _unit
from twin.rul.estimator import RULEstimate, RULEstimator
from twin.rul.observations import read_observations
from twin.rul.trajectory import (Trajectory, default_threshold, read_trajectory, scenario_speed_hz,
                                 trajectory_from_scenario)


def rul_document(estimate: RULEstimate, estimator: RULEstimator | None = None) -> dict[str, Any]:
    doc: dict[str, Any] = {"format": RUL_FORMAT, "format_version": 1, "estimate": estimate.to_dict()}
    if estimator is not None:
        doc["stages"] = list(estimator.stages)
        doc["trajectory"] = estimator.trajectory.source
        doc["settings"] = {"rate_range": list(estimator.rate_range), "rate_sigma": estimator.rate_sigma,
                           "offset_range": list(estimator.offset_range), "temperature": estimator.temperature,
                           "floor": estimator.floor, "boundary_width": estimator.boundary_width}
        doc["records"] = [{"record": o.record, "cycles": o.cycles, "probabilities": o.probabilities.tolist()}
                          for o in getattr(estimator, "observations_", ())]
    return doc


def check_json_path(path: str | Path) -> Path:
    from twin._atomic import check_parent
    target = check_parent(path)
    if target.suffix.lower() != ".json":
        raise OutputPathError(f"JSON path '{target}' has suffix '{target.suffix}'; only .json is written")
    return target


def check_png_path(path: str | Path) -> Path:
    from twin._atomic import check_parent
    target = check_parent(path)
    if target.suffix.lower() != ".png":
        raise OutputPathError(f"plot path '{target}' has suffix '{target.suffix}'; only .png is written")
    return target


def write_json(path: str | Path, estimate: RULEstimate, estimator: RULEstimator | None = None) -> Path:
    """Write the estimate (and, with the estimator, its inputs and settings) atomically."""
    from twin._atomic import atomic_path
    target = check_json_path(path)
    text = json.dumps(rul_document(estimate, estimator), indent=2)
    with atomic_path(target) as tmp:
        tmp.write_text(text + "\n", encoding="utf-8")
    return target


def read_json(path: str | Path) -> RULEstimate:
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise RULError(f"cannot read: {exc}", source=str(path)) from None
    if not isinstance(doc, dict) or doc.get("format") != RUL_FORMAT:
        raise RULError(f"not a {RUL_FORMAT} file", source=str(path))
    return RULEstimate.from_dict(doc["estimate"])


def plot_rul(estimator: RULEstimator, estimate: RULEstimate, path: str | Path) -> Path:
    """Damage vs cycles: records (stage spans), posterior median and band, threshold crossing."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from twin._atomic import atomic_path
    target = check_png_path(path)
    scale, unit = _unit(estimate.damage_kind)
    n_end = max(estimate.failure_band[1], estimate.now_cycles) * 1.1
    grid = np.linspace(0.0, n_end, 200)
    lo, med, hi = estimator.damage_quantiles(grid, ((1 - estimate.band) / 2, 0.5, (1 + estimate.band) / 2))
    fig = Figure(figsize=(9.0, 5.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.fill_between(grid, scale * lo, scale * hi, color="C0", alpha=0.25,
                    label=f"posterior {100 * estimate.band:g} % band")
    ax.plot(grid, scale * med, color="C0", label="posterior median")
    ax.plot(grid, scale * estimator.trajectory.damage_at(grid), color="0.5", ls="--", lw=1, label="model (s = 1)")
    b = np.asarray(estimator.stages)
    for o in estimator.observations_:
        k = int(np.argmax(o.probabilities))
        ax.plot([o.cycles, o.cycles], [scale * b[k], scale * b[k + 1]], color="C3",
                alpha=0.3 + 0.7 * float(o.probabilities[k]), lw=2)
    ax.plot([], [], color="C3", lw=2, label="records: most probable stage")
    for v in b:
        ax.axhline(scale * v, color="0.85", lw=0.8, zorder=0)
    ax.axhline(scale * estimate.threshold, color="k", lw=1.2, label="threshold")
    ax.axvspan(estimate.failure_band[0], estimate.failure_band[1], color="C1", alpha=0.15,
               label="predicted crossing band")
    ax.axvline(estimate.failure_cycles, color="C1", lw=1.2)
    ax.axvline(estimate.now_cycles, color="k", ls=":", lw=1, label="now")
    ax.set_xlim(0, n_end)
    ax.set_ylim(0, scale * max(estimate.threshold, b[-1]) * 1.15)
    ax.set_xlabel("pinion cycles")
    ax.set_ylabel(("pitting density" if estimate.damage_kind == "pitting_density" else "mean wear depth")
                  + f" [{unit}]")
    ax.set_title(f"RUL {estimate.rul_cycles:.3g} cycles ({estimate.rul_band[0]:.3g} .. "
                 f"{estimate.rul_band[1]:.3g}) after {estimate.n_observations} records")
    ax.legend(loc="upper left", fontsize=8)
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return target



def run_rul(scenario, observations_path, *, threshold: float | None = None, stages=None, cycles_file=None,
            speed_hz: float | None = None, trajectory=None, method: str = "cosim", now: float | None = None,
            sort: bool = False, json_path=None, plot_path=None, progress: bool = False,
            **estimator_options) -> tuple[RULEstimate, RULEstimator]:
    """Everything ``twin rul`` does, as a function: read, fit, estimate, write.

    Output paths are checked before any work, so a bad path writes nothing.
    """
    if json_path is not None:
        check_json_path(json_path)
    if plot_path is not None:
        check_png_path(plot_path)
    if scenario.degradation is None:
        raise ScenarioError([(str(scenario.source), "degradation", "twin rul needs the scenario's degradation block")])
    speed = speed_hz if speed_hz is not None else scenario_speed_hz(scenario)
    scenario_stages = scenario.archive["stages"] if scenario.archive else None
    obs = read_observations(observations_path, stages=stages, speed_hz=speed, cycles_file=cycles_file, sort=sort,
                            default_stages=scenario_stages)
    bounds = obs.stages
    if bounds is None:
        raise RULError("no stage boundaries: give them in the observation file, with --stages or in the "
                       "scenario's archive block", source=str(observations_path))
    if threshold is None:
        threshold = default_threshold(scenario)
        if threshold is None:
            threshold = float(bounds[-1])
    if trajectory is None:
        top = max(threshold, float(bounds[-1]))
        traj = trajectory_from_scenario(scenario, method=method, progress=progress,
                                        reach=1.5 * top if method == "static" else top)
    elif isinstance(trajectory, Trajectory):
        traj = trajectory
    else:
        traj = read_trajectory(trajectory)
    if obs.damage_kind is not None and obs.damage_kind != traj.kind:
        raise RULError(f"the records are {obs.damage_kind} stages but the trajectory is {traj.kind}",
                       source=str(observations_path))
    est = RULEstimator(traj, bounds, threshold, speed_hz=speed, **estimator_options).fit(obs)
    result = est.estimate(now)
    if json_path is not None:
        write_json(json_path, result, est)
    if plot_path is not None:
        plot_rul(est, result, plot_path)
    return result, est
