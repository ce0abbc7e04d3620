"""Model calibration: the multi-objective grasshopper optimiser (MOGOA) of Feng et al. (Eq. 4-9) as a
pymoo algorithm, and the rules that pick one parameter set from its Pareto archive.
See README.md in this directory.

    from pymoo.optimize import minimize
    res = minimize(problem, MOGOA(pop_size=40, archive_size=100), ("n_gen", 200), seed=1)
    best = res.X[least_crowded(res.F)]      # the paper's Eq. 9 pick; knee_point(res.F) is the alternative
"""
from twin.calibration.mogoa import MOGOA, coefficient, iteration_horizon, social_force
from twin.calibration.selection import DEFAULT_RADIUS, knee_point, least_crowded, neighbour_counts

__all__ = [
    "DEFAULT_RADIUS", "MOGOA", "coefficient", "iteration_horizon", "knee_point", "least_crowded",
    "neighbour_counts", "social_force",
]
