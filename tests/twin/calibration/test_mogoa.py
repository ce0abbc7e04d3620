"""MOGOA (twin/calibration/mogoa.py): Eq. 6 and 8, pymoo integration, archive and constraint rules,
and convergence on ZDT1 / Schaffer N.1 against the true front's hypervolume."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.problem import ElementwiseProblem, Problem
from pymoo.indicators.hv import HV
from pymoo.optimize import minimize
from pymoo.problems import get_problem
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting
from scipy.optimize import brentq

from twin.calibration import MOGOA, coefficient, iteration_horizon, social_force


class Schaffer(Problem):
    """Schaffer N.1: f1 = x^2, f2 = (x - 2)^2 on [-10, 10]; Pareto set x in [0, 2] (interior)."""

    def __init__(self):
        super().__init__(n_var=1, n_obj=2, xl=-10.0, xu=10.0)

    def _evaluate(self, X, out, *args, **kwargs):
        out["F"] = np.column_stack([X[:, 0] ** 2, (X[:, 0] - 2.0) ** 2])


class ElementwiseSchaffer(ElementwiseProblem):
    def __init__(self):
        super().__init__(n_var=1, n_obj=2, xl=-10.0, xu=10.0)

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = [x[0] ** 2, (x[0] - 2.0) ** 2]


class ConstrainedZDT1(Problem):
    """ZDT1 (5 variables) with x0 >= 0.3 required and a "failed simulation" region x1 > 0.8 that
    returns NaN objectives and is scored infeasible, as a calibration objective would."""

    def __init__(self):
        super().__init__(n_var=5, n_obj=2, n_ieq_constr=2, xl=0.0, xu=1.0)

    def _evaluate(self, X, out, *args, **kwargs):
        f1 = X[:, 0]
        g = 1.0 + 9.0 * X[:, 1:].mean(axis=1)
        F = np.column_stack([f1, g * (1.0 - np.sqrt(f1 / g))])
        failed = X[:, 1] > 0.8
        F[failed] = np.nan
        out["F"] = F
        out["G"] = np.column_stack([0.3 - X[:, 0], np.where(failed, 1.0, -1.0)])


def _hv_ratio(problem_name, F):
    if problem_name == "zdt1":
        ref = np.array([1.1, 1.1])
        x = np.linspace(0.0, 1.0, 5001)
        front = np.column_stack([x, 1.0 - np.sqrt(x)])
    else:
        ref = np.array([4.4, 4.4])
        x = np.linspace(0.0, 2.0, 5001)
        front = np.column_stack([x ** 2, (x - 2.0) ** 2])
    hv = HV(ref_point=ref)
    return hv(F) / hv(front)


# ---------------------------------------------------------------------------- Eq. 6 and Eq. 8

def test_social_force_known_values():
    assert social_force(0.0) == pytest.approx(-0.5)
    # 0.5 exp(-r/1.5) = exp(-r)  <=>  r (1 - 1/1.5) = ln 2  <=>  r = 3 ln 2 ~= 2.0794
    root = brentq(social_force, 1.0, 4.0)
    assert root == pytest.approx(3.0 * math.log(2.0), abs=1e-10)
    assert root == pytest.approx(2.079, abs=1e-3)
    r = np.array([0.5, 1.0, 2.0])
    assert np.all(social_force(r) < 0.0)          # repulsion inside the comfort distance
    r = np.array([2.2, 3.0, 4.0, 10.0])
    assert np.all(social_force(r) > 0.0)          # attraction outside it
    assert social_force(50.0) == pytest.approx(0.0, abs=1e-12)
    assert social_force(1.0, f=1.0, l=1.0) == 0.0  # f=1, l=1: no interaction at all


def test_social_term_two_close_grasshoppers_repel():
    algo = MOGOA(pop_size=2, archive_size=5)
    U = np.array([[0.50, 0.5], [0.52, 0.5]])       # mapped distance ~1.04 < 2.08 -> repulsion
    S = algo.social_term(U, c=1.0)
    assert S[0, 0] < 0.0 < S[1, 0]
    assert S[:, 1] == pytest.approx([0.0, 0.0])
    assert S[0] == pytest.approx(-S[1])
    # Coincident grasshoppers have no direction and exert no force on each other.
    assert np.all(algo.social_term(np.array([[0.3, 0.3], [0.3, 0.3]]), c=1.0) == 0.0)


def test_coefficient_schedule_is_linear_and_ends_at_c_min():
    assert coefficient(0, 10) == 1.0
    assert coefficient(10, 10) == pytest.approx(1e-5)
    assert coefficient(15, 10) == pytest.approx(1e-5)    # past the horizon: clipped
    seen = []
    n_gen = 12
    minimize(Schaffer(), MOGOA(pop_size=6, archive_size=10), ("n_gen", n_gen), seed=0,
             callback=lambda algorithm: seen.append(algorithm.c))
    c = np.array(seen[1:])                                # generation 1 is the initial sampling
    assert len(c) == n_gen - 1
    step = (1.0 - 1e-5) / n_gen
    assert np.diff(c) == pytest.approx(np.full(n_gen - 2, -step))
    assert c[0] == pytest.approx(1.0 - 2 * step)
    assert c[-1] == pytest.approx(1e-5)


def test_iteration_horizon_from_terminations():
    from pymoo.termination import get_termination
    from pymoo.termination.default import DefaultMultiObjectiveTermination

    assert iteration_horizon(get_termination("n_gen", 30), 10) == 30
    assert iteration_horizon(get_termination("n_evals", 301), 10) == 31
    assert iteration_horizon(DefaultMultiObjectiveTermination(n_max_gen=50, n_max_evals=10**6), 10) == 50
    assert iteration_horizon(get_termination("time", 5.0), 10) is None
    with pytest.raises(ValueError, match="n_gen"):
        minimize(Schaffer(), MOGOA(pop_size=5), ("time", 1.0), seed=0)
    # A constructor n_gen sets the schedule (and the termination when none is given).
    res = minimize(Schaffer(), MOGOA(pop_size=5, n_gen=7), seed=0)
    assert res.algorithm.n_iter_total == 7 and res.algorithm.n_gen == 8  # counter is past the end
    res = minimize(Schaffer(), MOGOA(pop_size=5, n_gen=20), ("n_gen", 5), seed=0)
    assert res.algorithm.n_iter_total == 20


# ---------------------------------------------------------------------------- pymoo integration

def test_same_seed_same_result_and_seed_matters():
    runs = [minimize(get_problem("zdt1", n_var=5), MOGOA(pop_size=20, archive_size=30), ("n_gen", 15), seed=s)
            for s in (3, 3, 4)]
    np.testing.assert_array_equal(runs[0].F, runs[1].F)
    np.testing.assert_array_equal(runs[0].X, runs[1].X)
    assert runs[0].F.shape != runs[2].F.shape or not np.array_equal(runs[0].F, runs[2].F)


def test_elementwise_problem_matches_vectorised():
    calls = []
    res_e = minimize(ElementwiseSchaffer(), MOGOA(pop_size=10, archive_size=20), ("n_gen", 10), seed=5,
                     callback=lambda algorithm: calls.append(algorithm.n_gen))
    res_v = minimize(Schaffer(), MOGOA(pop_size=10, archive_size=20), ("n_gen", 10), seed=5)
    assert calls == list(range(1, 11))
    assert res_e.algorithm.evaluator.n_eval == 100
    np.testing.assert_array_equal(res_e.F, res_v.F)


def test_result_is_the_nondominated_archive():
    res = minimize(get_problem("zdt1", n_var=5), MOGOA(pop_size=20, archive_size=40), ("n_gen", 20), seed=1)
    assert res.opt is res.algorithm.pareto
    assert res.X.shape == (len(res.F), 5)
    assert len(NonDominatedSorting().do(res.F, only_non_dominated_front=True)) == len(res.F)
    assert len(np.unique(res.F, axis=0)) == len(res.F)
    assert len(res.pop) == 20                              # the swarm, as NSGA-II's res.pop


def test_archive_size_bound_respected():
    sizes = []
    res = minimize(Schaffer(), MOGOA(pop_size=15, archive_size=8), ("n_gen", 25), seed=2,
                   callback=lambda algorithm: sizes.append(len(algorithm.opt)))
    assert max(sizes) <= 8
    assert len(res.F) == 8                                 # the Schaffer front easily fills it


def test_truncation_thins_crowded_regions():
    # Removal is a roulette (P ~ neighbour count), so compare survival rates over many seeded draws.
    algo = MOGOA(pop_size=5, archive_size=8)
    t = np.linspace(0.0, 0.01, 10)
    cluster = np.column_stack([t, 1.0 - t])                # 10 members in one corner
    isolated = np.column_stack([np.linspace(0.2, 1.0, 5), 1.0 - np.linspace(0.2, 1.0, 5)])
    F = np.vstack([cluster, isolated])
    survived = np.zeros(len(F))
    for seed in range(200):
        algo.random_state = np.random.default_rng(seed)
        keep = algo._truncate(F, 8)
        assert len(keep) == 8 and np.all(np.diff(keep) > 0)
        survived[keep] += 1
    rate_cluster, rate_isolated = survived[:10].mean() / 200, survived[10:].mean() / 200
    assert rate_isolated > 0.75 and rate_cluster < 0.5


def test_infeasible_and_failed_evaluations_never_in_archive():
    seen_infeasible = []

    def watch(algorithm):
        seen_infeasible.append(int(np.sum(~algorithm.pop.get("FEAS")[:, 0])))
        F = algorithm.opt.get("F")
        assert np.all(np.isfinite(F)) and np.all(algorithm.opt.get("CV") <= 0.0)

    res = minimize(ConstrainedZDT1(), MOGOA(pop_size=20, archive_size=30), ("n_gen", 20), seed=0, callback=watch)
    assert sum(seen_infeasible) > 0                        # the test did exercise infeasible points
    assert np.all(res.X[:, 0] >= 0.3) and np.all(res.X[:, 1] <= 0.8)
    assert np.all(np.isfinite(res.F)) and np.all(res.CV <= 0.0)


def test_no_feasible_point_reports_like_pymoo():
    class Impossible(Problem):
        def __init__(self):
            super().__init__(n_var=2, n_obj=2, n_ieq_constr=1, xl=0.0, xu=1.0)

        def _evaluate(self, X, out, *args, **kwargs):
            out["F"] = X.copy()
            out["G"] = 1.0 + X.sum(axis=1)                 # always violated, least at x = 0

    res = minimize(Impossible(), MOGOA(pop_size=10), ("n_gen", 5), seed=0)
    assert res.opt is None and res.F is None
    res = minimize(Impossible(), MOGOA(pop_size=10, return_least_infeasible=True), ("n_gen", 5), seed=0)
    assert len(res.opt) == 1 and res.CV[0, 0] > 0.0


# ---------------------------------------------------------------------------- convergence

# Budgets (equal for both algorithms): ZDT1 n_var=5, 30 grasshoppers x 50 generations = 1500
# evaluations; Schaffer N.1, 20 x 30 = 600.  MOGOA archive: 100 members; NSGA-II keeps pop_size.
BUDGETS = {"zdt1": (30, 50), "schaffer": (20, 30)}


@pytest.mark.parametrize("name", ["zdt1", "schaffer"])
def test_hypervolume_close_to_true_front(name, capsys):
    problem = get_problem("zdt1", n_var=5) if name == "zdt1" else Schaffer()
    pop_size, n_gen = BUDGETS[name]
    ratios = {"MOGOA": [], "NSGA-II": []}
    for seed in (0, 1, 2):
        res = minimize(problem, MOGOA(pop_size=pop_size, archive_size=100), ("n_gen", n_gen), seed=seed)
        ratios["MOGOA"].append(_hv_ratio(name, res.F))
        res = minimize(problem, NSGA2(pop_size=pop_size), ("n_gen", n_gen), seed=seed)
        ratios["NSGA-II"].append(_hv_ratio(name, res.F))
    with capsys.disabled():
        print(f"\n{name} ({pop_size}x{n_gen} evals) HV / HV(true front): "
              + ", ".join(f"{k} {np.mean(v):.4f} +- {np.std(v):.4f}" for k, v in ratios.items()))
    assert min(ratios["MOGOA"]) >= 0.85
