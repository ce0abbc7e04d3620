"""The modes fit as a search: every candidate set paired afresh, CMA-ES in log-parameters.

:func:`twin.calibration.modal_fit.fit_modes` (``fit: follow``, the default) pairs the measured modes
with model modes once, at the nominal set, and follows those model modes by their shapes through a
Levenberg-Marquardt descent. Where the model's modes are dense (a gearbox with shafts, pedestals and
a casing has several modes within 15 % of most measured ones) the followed modes veer and cross on
the way, and the descent stops far from what the chosen parameters can reach: on a beam-rig gearbox
(``bench/calibration_rigs.py``, seed 58) it ended with three paired modes 3-4 % off (sum of squared
``z`` 33) where one linear step from that point predicts 0.3, and restarted there it ran to a
different set with other modes paired.

``fit: search`` minimises instead the objective the population search and the score use: at each
candidate set the measured modes are paired afresh, one to one, with the visible model modes
(:func:`twin.calibration.modal_fit.mode_errors`; a measured mode left without a model mode within
15 % costs as much as one 15 % off), plus the bounds' prior ``(u_j / h_j)^2`` of the Levenberg-
Marquardt fit (``u_j = ln(p_j / p_nominal_j)``, ``h_j`` half the log-range of its bounds). Pairing
afresh makes the objective piecewise smooth, so the minimiser is CMA-ES (Hansen's ``cma``, a
dependency of pymoo), which needs no gradient: start at the nominal set, step a fifth of each
parameter's log-range, the bounds as box, each generation's candidates evaluated in parallel on the
executor. The best set found then goes through the Levenberg-Marquardt fit, which starts from a
pairing made there and can only lower its cost.

An opt-in, scored once on the rigs and not adopted (docs/calibration.md, seeds 61-65): on five
gearboxes of each rig it left the first six modes met where the default left them (6 + 7 and 6 + 0
of 30) and fitted about one more paired mode per rig within 3 %, at one to two more minutes.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from twin._progress import progress_bar

#: Evaluations of the search (linearisations; about 0.4 s each on one core).
SEARCH_BUDGET = 160
#: Initial step of the search, as a fraction of each parameter's log-range.
SEARCH_STEP = 0.2
#: Cost of a candidate set whose linearisation failed (far above any real set's).
FAILED_COST = 1e12
#: How the modes fit proceeds: from the nominal pairing, following modes (default), or searching.
FITS = ("follow", "search")


def check_fit(fit: str) -> str:
    """``fit`` if it is a known way to fit the modes (:data:`FITS`), else a ValueError naming it."""
    if fit not in FITS:
        raise ValueError(f"unknown modes fit {fit!r}: use one of {', '.join(FITS)}")
    return fit


def _cost_task(task) -> float:
    """Objective of one candidate set (top level, so that worker processes can run it)."""
    from twin.calibration.modal_fit import mode_errors
    from twin.calibration.model_modes import model_modes

    fmu_path, values, prior, measured, rel_sd, shapes, pairing, kw = task
    z, _ = mode_errors(model_modes(fmu_path, values, **kw), measured, rel_sd, shapes, pairing=pairing)
    return float(z @ z + prior)


def search_modes(fmu_path, names: Sequence[str], lower, upper, nominal, measured, rel_sd, *,
                 fixed: Mapping[str, float], speed_hz: float, load_nm: float,
                 channels: Sequence[str] = ("accel_pinion_casing",), shapes=None, pairing: str = "frequency",
                 visibility: str = "mesh", executor=None, budget: int = SEARCH_BUDGET, seed: int = 0,
                 progress: bool = False) -> tuple[np.ndarray, float]:
    """CMA-ES over ``names`` within ``[lower, upper]`` from ``nominal`` (each ``(d,)``); returns the
    best set found ``(d,)`` and its cost (sum of squared ``z`` plus the prior, see the module
    docstring). ``executor`` (:mod:`twin.executor`) evaluates each generation in parallel; without
    it they run here, one after the other."""
    import cma

    lower, upper, nominal = (np.asarray(v, float) for v in (lower, upper, nominal))
    if not (np.all(lower > 0) and np.all(lower <= nominal) and np.all(nominal <= upper)):
        raise ValueError("search_modes needs 0 < lower <= nominal <= upper for every parameter")
    lo, hi = np.log(lower / nominal), np.log(upper / nominal)
    span = np.where(hi > lo, hi - lo, 1.0)
    half = 0.5 * span
    measured = np.asarray(measured, float)
    rel_sd = np.asarray(rel_sd, float)
    kw = dict(speed_hz=speed_hz, load_nm=load_nm, channels=tuple(channels), visibility=visibility)

    def to_values(y):
        u = lo + np.clip(y, 0.0, 1.0) * span
        return nominal * np.exp(u), float(np.sum((u / half) ** 2))

    def task(y):
        x, prior = to_values(y)
        return (str(fmu_path), {**fixed, **{n: float(v) for n, v in zip(names, x)}}, prior, measured, rel_sd,
                shapes, pairing, kw)

    y0 = (0.0 - lo) / span
    es = cma.CMAEvolutionStrategy(y0, SEARCH_STEP, {"bounds": [0.0, 1.0], "maxfevals": int(budget),
                                                    "seed": int(seed) + 1, "verbose": -9})
    # one bar over the whole budget, not one per generation
    bar = progress_bar(int(budget) + 1, progress, "modes search", "run")
    try:
        best_y, best = y0, _evaluate([task(y0)], executor, bar)[0]
        while not es.stop():
            ys = es.ask()
            costs = _evaluate([task(y) for y in ys], executor, bar)
            es.tell(ys, costs)
            i = int(np.argmin(costs))
            if costs[i] < best:
                best_y, best = np.asarray(ys[i], float), costs[i]
    finally:
        bar.close()
    return to_values(best_y)[0], float(best)


def _evaluate(tasks, executor, bar) -> list[float]:
    # on the executor a failed linearisation comes back as its exception and scores as a very bad
    # set; here, as in the Levenberg-Marquardt fit, it raises
    results = ([_cost_task(t) for t in tasks] if executor is None
               else executor.map(_cost_task, tasks))
    bar.update(len(tasks))
    return [FAILED_COST if isinstance(r, BaseException) or not np.isfinite(r) else float(r) for r in results]
