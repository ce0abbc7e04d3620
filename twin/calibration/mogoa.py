"""Multi-objective grasshopper optimisation algorithm (MOGOA) as a pymoo ``Algorithm``.

Implements Eq. 4-9 of Feng et al. (section 2.2.1), i.e. Saremi et al.'s GOA with Mirjalili et al.'s
Pareto archive and roulette target selection.  Usage is the same as any pymoo algorithm::

    res = minimize(problem, MOGOA(pop_size=40, archive_size=100), ("n_gen", 200), seed=1)
    res.F, res.X          # the Pareto archive (non-dominated, feasible)

One iteration (generation ``m`` of ``M``; generation 1 is the random initial swarm):

* ``c = c_max - m (c_max - c_min) / M``                                             (Eq. 8)
* every grasshopper ``i`` draws a target ``T_i`` from the archive by roulette with probability
  proportional to ``1 / N_k`` (``N_k``: archive neighbours of member ``k``)          (Eq. 9)
* in coordinates normalised to the unit box, ``u = (x - lb) / (ub - lb)``::

      u_i <- c * sum_{j != i} c * (1/2) * s(r_ij) * (u_j - u_i) / d_ij  +  u_T_i       (Eq. 7)
      s(r) = f exp(-r / l) - exp(-r)                                                   (Eq. 6)
      d_ij = |u_j - u_i|,   r_ij = 1 + 3 d_ij / sqrt(n_var)   (distance mapped to [1, 4])

  ``(ub - lb) / 2`` of Eq. 7 is ``1/2`` in the unit box; the new position is clipped to it and
  mapped back.  Gravity is omitted and the wind term is the target (as in Saremi's GOA and
  Mirjalili's MOGOA).
* evaluate; add the feasible, finite evaluations to the archive; keep its non-dominated members;
  while it is over ``archive_size`` remove a member drawn by roulette with probability
  proportional to its neighbour count, so crowded regions are thinned first.

See ``README.md`` in this directory for the choices made where the paper is silent.
"""
from __future__ import annotations

import math

import numpy as np
from pymoo.core.algorithm import Algorithm
from pymoo.core.initialization import Initialization
from pymoo.core.population import Population
from pymoo.core.termination import TerminateIfAll, TerminateIfAny
from pymoo.operators.sampling.rnd import FloatRandomSampling
from pymoo.termination.default import DefaultTermination
from pymoo.termination.max_eval import MaximumFunctionCallTermination
from pymoo.termination.max_gen import MaximumGenerationTermination
from pymoo.util.display.multi import MultiObjectiveOutput
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from twin.calibration.selection import DEFAULT_RADIUS, neighbour_counts, normalise_objectives, pairwise_distances

#: Mapped-distance interval of Saremi's GOA: the comfort distance of s(r) with f=0.5, l=1.5 is
#: r ~= 2.08, so grasshoppers closer than ~1/3 of the box diagonal repel and farther ones attract.
R_MIN, R_MAX = 1.0, 4.0


def social_force(r, f: float = 0.5, l: float = 1.5) -> np.ndarray:
    """Social force of Eq. 6, ``s(r) = f exp(-r/l) - exp(-r)``; > 0 attraction, < 0 repulsion.

    Args:
        r: Distance(s), any shape.
        f: Intensity of attraction.
        l: Attractive length scale.

    Returns:
        Array of the same shape as ``r``.
    """
    r = np.asarray(r, dtype=float)
    return f * np.exp(-r / l) - np.exp(-r)


def coefficient(m: float, M: float, c_max: float = 1.0, c_min: float = 1e-5) -> float:
    """Decreasing coefficient of Eq. 8, ``c = c_max - m (c_max - c_min) / M``.

    ``m`` is the generation being produced (2 for the first move of the swarm; pymoo counts the
    initial sampling as generation 1) and ``M`` the total number of generations, so the last
    generation uses exactly ``c_min``.  Outside ``[0, M]`` the value is clipped to
    ``[c_min, c_max]`` (a run that goes on past the planned horizon keeps ``c_min``).
    """
    c = c_max - m * (c_max - c_min) / M
    return float(min(max(c, c_min), c_max))


def iteration_horizon(termination, pop_size: int) -> int | None:
    """Total number of generations ``M`` implied by a pymoo termination, or ``None`` if unknown.

    * ``("n_gen", N)`` / ``("n_iter", N)``: ``N``;
    * ``("n_evals", E)``: ``ceil(E / pop_size)`` (each generation evaluates the whole swarm);
    * pymoo's default termination: the smaller of its generation and evaluation caps (its
      tolerance criteria may stop the run earlier, with ``c`` not yet at ``c_min``);
    * ``TerminateIfAny``: the smallest known horizon of its criteria; ``TerminateIfAll``: the
      largest, if all are known;
    * anything else (time, ``fmin``, custom): ``None``.
    """
    def finite(v) -> int | None:
        return int(math.ceil(v)) if v is not None and np.isfinite(v) and v > 0 else None

    if isinstance(termination, MaximumGenerationTermination):
        return finite(termination.n_max_gen)
    if isinstance(termination, MaximumFunctionCallTermination):
        v = termination.n_max_evals
        return finite(v / pop_size) if v is not None else None
    if isinstance(termination, DefaultTermination):
        known = [h for h in (iteration_horizon(termination.max_gen, pop_size),
                             iteration_horizon(termination.max_evals, pop_size)) if h is not None]
        return min(known) if known else None
    if isinstance(termination, TerminateIfAny):
        known = [h for h in (iteration_horizon(t, pop_size) for t in termination.criteria) if h is not None]
        return min(known) if known else None
    if isinstance(termination, TerminateIfAll):
        hs = [iteration_horizon(t, pop_size) for t in termination.criteria]
        return max(hs) if hs and all(h is not None for h in hs) else None
    return None


class MOGOA(Algorithm):
    """Multi-objective grasshopper optimisation (Feng et al. Eq. 4-9) for box-bounded real problems.

    Args:
        pop_size: Number of grasshoppers ``K`` (evaluations per generation).
        archive_size: Maximum number of Pareto-archive members.
        f, l: Social-force intensity and length scale of Eq. 6 (paper: 0.5, 1.5).
        c_max, c_min: Range of the decreasing coefficient of Eq. 8 (paper/GOA: 1, 1e-5).
        n_gen: Total number of generations ``M`` for Eq. 8.  When given it takes precedence over
            the termination; when given and no termination is passed to ``minimize`` the run also
            stops after ``n_gen`` generations.  When omitted, ``M`` is derived from the
            termination (see :func:`iteration_horizon`); a termination without a generation or
            evaluation budget (time, ``fmin``, custom) then raises ``ValueError`` at setup.
            Generations beyond ``M`` keep ``c = c_min``.
        neighbour_radius: Radius, in archive-normalised objective space, of the neighbourhoods
            used for target selection and archive truncation (see ``selection.DEFAULT_RADIUS``).
        sampling: Initial swarm: a pymoo ``Sampling`` (default uniform random in the bounds), an
            ``(n, n_var)`` array or a ``Population``.
        **kwargs: Passed to :class:`pymoo.core.algorithm.Algorithm` (``output``, ``callback``...).

    Attributes after setup / during a run:
        pareto: ``Population`` of the archive members (also ``opt`` and ``result().opt``).
        pop: ``Population`` of the current swarm (its last evaluated positions).
        c: Coefficient used for the most recent move (``c_max`` before the first move).
        n_iter_total: The horizon ``M`` in use.
    """

    def __init__(
        self,
        pop_size: int = 50,
        archive_size: int = 100,
        *,
        f: float = 0.5,
        l: float = 1.5,
        c_max: float = 1.0,
        c_min: float = 1e-5,
        n_gen: int | None = None,
        neighbour_radius: float = DEFAULT_RADIUS,
        sampling=None,
        output=None,
        **kwargs,
    ):
        if int(pop_size) < 2:
            raise ValueError("pop_size must be >= 2 (the social term needs other grasshoppers)")
        if int(archive_size) < 1:
            raise ValueError("archive_size must be >= 1")
        if not 0.0 < c_min <= c_max:
            raise ValueError(f"need 0 < c_min <= c_max, got c_min={c_min}, c_max={c_max}")
        if n_gen is not None and int(n_gen) < 1:
            raise ValueError("n_gen must be >= 1")
        if not neighbour_radius > 0.0:
            raise ValueError("neighbour_radius must be > 0")
        if n_gen is not None and kwargs.get("termination") is None:
            kwargs["termination"] = ("n_gen", int(n_gen))
        super().__init__(output=MultiObjectiveOutput() if output is None else output, **kwargs)
        self.pop_size = int(pop_size)
        self.archive_size = int(archive_size)
        self.f = float(f)
        self.l = float(l)
        self.c_max = float(c_max)
        self.c_min = float(c_min)
        # Not ``self.n_gen``: pymoo's Algorithm aliases that name to the generation counter.
        self.n_gen_schedule = None if n_gen is None else int(n_gen)
        self.neighbour_radius = float(neighbour_radius)
        self.initialization = Initialization(FloatRandomSampling() if sampling is None else sampling)
        self.pareto = Population.empty()
        self.c = self.c_max
        self.n_iter_total: int | None = None
        # Least-violating evaluation so far, the swarm's target while the archive is empty.
        self._fallback = None
        self._fallback_violation = np.inf

    # ------------------------------------------------------------------ pymoo hooks

    def _setup(self, problem, **kwargs):
        xl, xu = problem.bounds()
        if xl is None or xu is None:
            raise ValueError("MOGOA needs a box-bounded problem (xl and xu)")
        xl = np.broadcast_to(np.asarray(xl, dtype=float), (problem.n_var,)).copy()
        xu = np.broadcast_to(np.asarray(xu, dtype=float), (problem.n_var,)).copy()
        if not (np.all(np.isfinite(xl)) and np.all(np.isfinite(xu)) and np.all(xu >= xl)):
            raise ValueError("MOGOA needs finite bounds with xu >= xl")
        self._xl, self._xu = xl, xu
        # Degenerate (fixed) variables get span 1 so normalisation stays defined; clipping to the
        # unit box maps them back onto their single allowed value.
        self._span = np.where(xu > xl, xu - xl, 1.0)
        horizon = self.n_gen_schedule or iteration_horizon(self.termination, self.pop_size)
        if horizon is None:
            raise ValueError(
                f"cannot derive the number of iterations for Eq. 8 from {type(self.termination).__name__}; "
                "pass MOGOA(n_gen=...) or use an ('n_gen', N) / ('n_evals', E) termination")
        self.n_iter_total = int(horizon)
        self.pareto = Population.empty()
        self.c = self.c_max
        self._fallback = None
        self._fallback_violation = np.inf

    def _initialize_infill(self):
        return self.initialization.do(self.problem, self.pop_size, algorithm=self, random_state=self.random_state)

    def _initialize_advance(self, infills=None, **kwargs):
        self._update_archive(infills)

    def _infill(self):
        # n_iter was already advanced by _post_advance: it is the generation being produced.
        self.c = coefficient(self.n_iter, self.n_iter_total, self.c_max, self.c_min)
        U = self._normalise(self.pop.get("X"))
        targets = self._normalise(self._select_targets(len(U)).get("X"))
        U_new = np.clip(self.c * self.social_term(U, self.c) + targets, 0.0, 1.0)
        return Population.new(X=self._xl + U_new * self._span)

    def _advance(self, infills=None, **kwargs):
        # GOA has no survival selection: the swarm simply moves to its new positions; memory of
        # good solutions is the archive alone.
        self.pop = infills
        self._update_archive(infills)

    def _set_optimum(self):
        if len(self.pareto) > 0:
            self.opt = self.pareto
        elif self._fallback is not None and not self._fallback.feas:
            # Nothing feasible yet: expose the least infeasible point so that pymoo's
            # return_least_infeasible option behaves as with its own algorithms.
            self.opt = Population.create(self._fallback)
        else:
            self.opt = Population.empty()

    # ------------------------------------------------------------------ GOA mechanics

    def social_term(self, U: np.ndarray, c: float) -> np.ndarray:
        """Inner sum of Eq. 7 in the unit box: ``sum_j c (1/2) s(r_ij) (u_j - u_i) / d_ij``.

        Args:
            U: ``(K, n_var)`` normalised positions.
            c: Coefficient of Eq. 8 (the inner ``c``).

        Returns:
            ``(K, n_var)`` social displacement of every grasshopper.
        """
        K, D = U.shape
        diff = U[None, :, :] - U[:, None, :]                     # [i, j] = u_j - u_i
        d = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))
        r = R_MIN + (R_MAX - R_MIN) * d / math.sqrt(D)           # box diagonal -> R_MAX
        s = social_force(r, self.f, self.l)
        # Coincident grasshoppers (including j == i) have no direction: their term is zero,
        # which is what GOA's "+eps" in the denominator achieves.
        unit = diff / np.where(d > 0.0, d, 1.0)[:, :, None]
        return 0.5 * c * np.einsum("ij,ijk->ik", s, unit)

    def _normalise(self, X: np.ndarray) -> np.ndarray:
        return (np.asarray(X, dtype=float) - self._xl) / self._span

    def _select_targets(self, k: int) -> Population:
        """``k`` targets drawn independently from the archive, P(member i) ~ 1 / N_i (Eq. 9)."""
        if len(self.pareto) == 0:
            return Population.create(*([self._fallback] * k))
        counts = neighbour_counts(self.pareto.get("F"), self.neighbour_radius)
        p = 1.0 / counts
        idx = self.random_state.choice(len(self.pareto), size=k, p=p / p.sum())
        return self.pareto[idx]

    def _update_archive(self, pop: Population) -> None:
        """Merge feasible, finite evaluations of ``pop`` into the archive and keep it non-dominated.

        Infeasible (CV above pymoo's feasibility threshold) and failed (non-finite F or CV)
        evaluations never enter: a feasible point dominates every infeasible one, so the archive of
        a problem with at least one feasible evaluation holds feasible points only.  Until then the
        least violating evaluation is remembered as the target of the swarm.
        """
        F = np.asarray(pop.get("F"), dtype=float).reshape(len(pop), -1)
        CV = np.asarray(pop.get("CV"), dtype=float).reshape(len(pop), -1)[:, 0]
        finite = np.all(np.isfinite(F), axis=1) & np.isfinite(CV)
        ok = finite & np.asarray(pop.get("FEAS"), dtype=bool).reshape(len(pop), -1)[:, 0]

        violation = np.where(finite, CV, np.inf)
        best = int(np.argmin(violation))
        if self._fallback is None or violation[best] < self._fallback_violation:
            self._fallback, self._fallback_violation = pop[best], violation[best]

        if not np.any(ok):
            return
        merged = Population.merge(self.pareto, pop[ok]) if len(self.pareto) else pop[ok]
        Fm = np.asarray(merged.get("F"), dtype=float).reshape(len(merged), -1)
        # Identical objective vectors add nothing to the front; keep the first (the older member).
        _, first = np.unique(Fm, axis=0, return_index=True)
        first = np.sort(first)
        front = np.sort(NonDominatedSorting().do(Fm[first], only_non_dominated_front=True))
        keep = first[front]
        if keep.size > self.archive_size:
            keep = keep[self._truncate(Fm[keep], self.archive_size)]
        self.pareto = merged[keep]

    def _truncate(self, F: np.ndarray, size: int) -> np.ndarray:
        """Indices (sorted) of ``size`` rows kept after roulette removal in crowded regions.

        Each removal draws a member with probability proportional to its neighbour count and then
        decrements the counts of its neighbours, so a dense cluster is thinned one member at a
        time rather than wiped out in one go.  Normalisation is fixed before the removals.
        """
        near = pairwise_distances(normalise_objectives(F)) < self.neighbour_radius
        counts = near.sum(axis=1).astype(float)
        alive = np.ones(len(F), dtype=bool)
        for _ in range(len(F) - size):
            w = np.where(alive, counts, 0.0)
            k = self.random_state.choice(len(F), p=w / w.sum())
            alive[k] = False
            counts -= near[k]
        return np.flatnonzero(alive)
