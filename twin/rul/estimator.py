"""Remaining useful life (RUL) from a time series of assessed wear stages: the estimator.


The assessor (``twin assess``) turns each vibration record into stage probabilities
``p_k``, k = 0 .. K-1, for the stages ``[b_k, b_{k+1})`` of the damage measure (pitting
density, or mean wear depth in m) the archive was built on.  A stage says little by itself;
RUL needs the *trajectory* of the damage.  This module combines the two.

Method
------
**Trajectory.**  The calibrated degradation model of the scenario gives the damage against
pinion cycles, ``D_model(N)`` (:class:`Trajectory`): by default the co-simulated run of
:func:`twin.degradation_run.run_degradation` (``method="cosim"``: the FMU's dynamic load, 20 s
for the lubricated and 35 s for the dry scenario), or an HDF5 already written by ``twin run`` /
``twin archive`` (:func:`read_trajectory`).  ``method="static"`` drives the same cycle-jumping
loop with the quasi-static load sharing :meth:`MeshLoad.static` (damage fed back through
:func:`mesh_parameters`; no FMU, < 1 s for pitting, ~15 s for wear).  For pitting it agrees
with the co-simulated run within 3 % in cycles to 20 % density; for wear it does *not*: the
co-simulated wear rate drops about 4x between 90 and 120 um of mean depth (the worn profile
changes the dynamic load sharing) and the run reaches 240 um after 2.3e6 cycles instead of
1.5e6.  Use the static trajectory for pitting only, or to test.


**Unknowns.**  The real gearbox does not degrade at exactly the model's rate: the wear /
pitting coefficients scatter, the load is not the nominal one, the flank finish differs.  The
real damage is modelled as the model's curve on a stretched and shifted clock,

    D_real(N) = D_model(max(0, s N + tau)),       tau = f N_model(threshold)

with a *rate factor* ``s`` (> 1: faster than the model) and an *offset* ``f`` (a fraction of the
model's life to the threshold; > 0: damage already present when counting started, e.g. a
gearbox run before monitoring began; < 0: an incubation delay).  Under a constant load the
Archard depth is linear in N and the Lundberg-Palmgren density is ``1 - exp(-A N^m)``, so a
change of the wear coefficient, the pitting coefficient or the load is *exactly* a change of
``s`` (``s = (A'/A)^(1/m)`` for pitting); the shape of the curve is the model's.


**Observations.**  Record i at ``N_i`` cycles has stage probabilities ``p_i``.  A classifier's
output is read as soft evidence about the true stage: tempered ``q ∝ p^(1/T)`` (``temperature``
T > 1 softens an over-confident classifier) and mixed with a uniform floor,
``q <- (1 - eps) q + eps / K`` (``floor`` eps bounds the weight of one confident mistake).  The
likelihood of a damage value D is then

    L_i(D) = sum_k q_ik m_k(D),   m_k(D) = Phi((D - b_k)/w) - Phi((D - b_{k+1})/w)

with the outer boundaries at -inf / +inf (damage above the last boundary is in the last stage)
and a boundary width ``w = boundary_width x`` the median stage width (the archive's records are
drawn uniformly in each stage, so a classifier is least sure right at a boundary).


**Posterior.**  On a grid over ``(log s, f)`` with prior ``log s ~ N(0, rate_sigma)`` truncated
to ``rate_range`` (``rate_sigma=None``: log-uniform) and ``f`` uniform in ``offset_range``, the
posterior is ``prior x prod_i L_i(D_real(N_i))``.  The grid is evaluated twice: over the prior
range, then refined over where the posterior mass lies, so its step stays well under the band
width.  Nothing is sampled: the result is deterministic.


**Estimates** at ``now`` (by default the last record's cycles), as posterior quantiles
(default 5 %, 50 %, 95 %):

* current damage ``D_real(now)``;
* failure cycles ``N_fail = (N_model(threshold) - tau) / s``, the first crossing of the
  threshold, and ``RUL = max(0, N_fail - now)``;
* the rate factor and offset, and the probability that the threshold is already passed.

The trajectory is :mod:`twin.rul.trajectory`, the records :mod:`twin.rul.observations`.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from twin.rul.base import RULError, format_damage
from twin.rul.observations import Observation, ObservationSet, check_stages
from twin.rul.trajectory import Trajectory


@dataclass(frozen=True)
class RULEstimate:
    """Posterior summary at ``now_cycles`` (bands are the central ``band`` interval).

    Damage in the unit of ``damage_kind`` (density 0-1, or m); cycles are pinion revolutions.
    """

    now_cycles: float
    current_damage: float
    damage_band: tuple[float, float]
    rul_cycles: float
    rul_band: tuple[float, float]
    failure_cycles: float
    failure_band: tuple[float, float]
    threshold: float
    damage_kind: str
    rate_factor: float
    rate_band: tuple[float, float]
    offset_fraction: float
    probability_failed: float
    n_observations: int
    band: float = 0.90
    speed_hz: float | None = None
    warnings: tuple[str, ...] = ()

    def rul_hours(self) -> tuple[float, float, float] | None:
        """(lo, median, hi) RUL in hours at ``speed_hz``, or None without a speed."""
        if not self.speed_hz:
            return None
        h = 3600.0 * self.speed_hz
        return self.rul_band[0] / h, self.rul_cycles / h, self.rul_band[1] / h

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        for k, v in d.items():
            if isinstance(v, tuple):
                d[k] = list(v)
        return d

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> "RULEstimate":
        try:
            kw = {k: data[k] for k in cls.__dataclass_fields__ if k in data}
            for k in ("damage_band", "rul_band", "failure_band", "rate_band", "warnings"):
                if k in kw:
                    kw[k] = tuple(kw[k])
            return cls(**kw)
        except (TypeError, KeyError) as exc:
            raise RULError(f"not an RUL estimate: {exc}") from None

    def table(self) -> str:
        lo, hi = 100 * (1 - self.band) / 2, 100 * (1 + self.band) / 2
        name = "pitting density" if self.damage_kind == "pitting_density" else "mean wear depth"
        rows = [("quantity", "median", f"{lo:g} %", f"{hi:g} %"),
                (f"current {name}", format_damage(self.current_damage, self.damage_kind),
                 format_damage(self.damage_band[0], self.damage_kind),
                 format_damage(self.damage_band[1], self.damage_kind)),
                ("RUL [cycles]", f"{self.rul_cycles:.4g}", f"{self.rul_band[0]:.4g}", f"{self.rul_band[1]:.4g}")]
        hours = self.rul_hours()
        if hours is not None:
            rows.append((f"RUL [h at {self.speed_hz:g} Hz]", f"{hours[1]:.4g}", f"{hours[0]:.4g}", f"{hours[2]:.4g}"))
        rows += [("failure at [cycles]", f"{self.failure_cycles:.4g}", f"{self.failure_band[0]:.4g}",
                  f"{self.failure_band[1]:.4g}"),
                 ("rate factor vs model", f"{self.rate_factor:.3g}", f"{self.rate_band[0]:.3g}",
                  f"{self.rate_band[1]:.3g}")]
        widths = [max(len(r[i]) for r in rows) for i in range(4)]
        lines = [f"threshold {format_damage(self.threshold, self.damage_kind)} {name}; "
                 f"{self.n_observations} records, now = {self.now_cycles:.4g} cycles; "
                 f"P(threshold already passed) = {self.probability_failed:.3f}"]
        for j, r in enumerate(rows):
            lines.append("  ".join(c.ljust(widths[i]) if i == 0 else c.rjust(widths[i]) for i, c in enumerate(r)))
            if j == 0:
                lines.append("  ".join("-" * w for w in widths))
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)


def weighted_quantile(values: np.ndarray, weights: np.ndarray, q) -> np.ndarray:
    """Quantiles ``q`` of a discrete distribution (values, weights), interpolated on the mid-point CDF."""
    values = np.asarray(values, dtype=float).ravel()
    weights = np.asarray(weights, dtype=float).ravel()
    order = np.argsort(values, kind="stable")
    v, w = values[order], weights[order]
    cdf = (np.cumsum(w) - 0.5 * w) / w.sum()
    return np.interp(q, cdf, v)


class RULEstimator:
    """Bayesian grid posterior over the rate factor and clock offset (module docstring).

    Parameters
    ----------
    trajectory : Trajectory
        The model's D(N).
    stages : sequence of K + 1 floats
        Stage boundaries, in the trajectory's damage unit.
    threshold : float
        Damage at end of life (e.g. 0.2 pitting density); must lie inside the trajectory.
    rate_range : (lo, hi)
        Support of the rate factor s (> 0).
    rate_sigma : float or None
        Prior standard deviation of ln s (centred on 1: the calibrated model); None: log-uniform.
    offset_range : (lo, hi)
        Support of f = tau / N_model(threshold) (uniform prior); (0, 0) fixes the clock origin.
    temperature, floor, boundary_width :
        Softening of the classifier output and of the stage boundaries (module docstring).
    n_rate, n_offset : int
        Grid size per pass.
    band : float
        Central probability of the reported bands (0.90: 5 % .. 95 %).
    """

    def __init__(self, trajectory: Trajectory, stages: Sequence[float], threshold: float, *,
                 rate_range: tuple[float, float] = (0.1, 10.0), rate_sigma: float | None = math.log(2.0),
                 offset_range: tuple[float, float] = (-0.2, 0.2), temperature: float = 1.0, floor: float = 0.05,
                 boundary_width: float = 0.1, n_rate: int = 301, n_offset: int = 41, band: float = 0.90,
                 speed_hz: float | None = None):
        if not isinstance(trajectory, Trajectory):
            raise RULError(f"trajectory must be a Trajectory, got {type(trajectory).__name__}")
        self.trajectory = trajectory
        self.stages = check_stages(stages, "stages")
        if not (isinstance(threshold, (int, float, np.floating)) and math.isfinite(threshold)
                and trajectory.damage[0] < threshold <= trajectory.max_damage):
            raise RULError(f"threshold {threshold!r} is outside the trajectory's damage range "
                           f"({trajectory.damage[0]:.4g}, {trajectory.max_damage:.4g}] ({trajectory.source}); "
                           f"extend the trajectory or lower the threshold")
        self.threshold = float(threshold)
        lo, hi = (float(v) for v in rate_range)
        if not (0 < lo < hi and math.isfinite(hi)):
            raise RULError(f"rate_range must be 0 < lo < hi, got {rate_range!r}")
        self.rate_range = (lo, hi)
        if rate_sigma is not None and not (math.isfinite(rate_sigma) and rate_sigma > 0):
            raise RULError(f"rate_sigma must be > 0 or None, got {rate_sigma!r}")
        self.rate_sigma = rate_sigma
        olo, ohi = (float(v) for v in offset_range)
        if not (olo <= ohi and olo > -1 and ohi < 1):
            raise RULError(f"offset_range must be lo <= hi inside (-1, 1), got {offset_range!r}")
        self.offset_range = (olo, ohi)
        for name, v, ok in (("temperature", temperature, temperature > 0), ("floor", floor, 0 <= floor < 1),
                            ("boundary_width", boundary_width, boundary_width >= 0), ("band", band, 0 < band < 1)):
            if not (math.isfinite(v) and ok):
                raise RULError(f"{name} out of range: {v!r}")
        self.temperature, self.floor, self.boundary_width, self.band = temperature, floor, boundary_width, band
        if not (int(n_rate) >= 11 and int(n_offset) >= 1):
            raise RULError(f"n_rate must be >= 11 and n_offset >= 1, got {n_rate!r}, {n_offset!r}")
        self.n_rate, self.n_offset = int(n_rate), int(n_offset)
        self.speed_hz = speed_hz
        self.life_model = trajectory.cycles_at(self.threshold)   # N_model(threshold)

    # -- likelihood ------------------------------------------------------------------------
    def _evidence(self, probabilities: np.ndarray) -> np.ndarray:
        p = np.clip(probabilities, 0.0, None) ** (1.0 / self.temperature)
        p = p / p.sum(axis=1, keepdims=True)
        k = p.shape[1]
        return (1 - self.floor) * p + self.floor / k

    def _membership(self, damage: np.ndarray) -> np.ndarray:
        """m_k(D) for damage of any shape -> shape + (K,)."""
        from scipy.special import ndtr
        b = np.asarray(self.stages)
        k = b.size - 1
        w = self.boundary_width * float(np.median(np.diff(b)))
        d = damage[..., None]
        inner = b[1:-1]
        if w > 0:
            above = ndtr((d - inner) / w)                         # P(D above boundary j)
        else:
            above = (d >= inner).astype(float)
        ones = np.ones(d.shape[:-1] + (1,))
        zeros = np.zeros(d.shape[:-1] + (1,))
        upper = np.concatenate([ones, above], axis=-1)            # above lower boundary of stage k
        lower = np.concatenate([above, zeros], axis=-1)           # above upper boundary of stage k
        m = upper - lower
        assert m.shape[-1] == k
        return m

    def _log_prior(self, log_s: np.ndarray) -> np.ndarray:
        if self.rate_sigma is None:
            return np.zeros_like(log_s)
        return -0.5 * (log_s / self.rate_sigma) ** 2

    def _log_like(self, log_s: np.ndarray, f: np.ndarray, cycles: np.ndarray, q: np.ndarray) -> np.ndarray:
        s = np.exp(log_s)[:, None, None]
        tau = (f * self.life_model)[None, :, None]
        ll = np.zeros((log_s.size, f.size))
        for start in range(0, cycles.size, 16):                   # bounded memory
            n = cycles[start:start + 16][None, None, :]
            dmg = self.trajectory.damage_at(s * n + tau)          # (R, F, M)
            like = np.einsum("rfmk,mk->rfm", self._membership(dmg), q[start:start + 16])
            ll += np.sum(np.log(np.maximum(like, 1e-300)), axis=-1)
        return ll

    def _grid(self, lo_s, hi_s, lo_f, hi_f):
        log_s = np.linspace(math.log(lo_s), math.log(hi_s), self.n_rate)
        f = np.linspace(lo_f, hi_f, self.n_offset) if hi_f > lo_f else np.array([lo_f])
        return log_s, f

    def fit(self, observations: ObservationSet | Sequence[Observation]) -> "RULEstimator":
        """Posterior over (s, f) given the observations; returns self.

        Learned: ``log_rates_`` (R,), ``offsets_`` (F,), ``posterior_`` (R, F) normalised weights,
        ``observations_``, ``now_`` (cycles of the last record), ``log_evidence_``.
        """
        obs = observations.observations if isinstance(observations, ObservationSet) else tuple(observations)
        if not obs:
            raise RULError("no observations to fit")
        k = len(self.stages) - 1
        for o in obs:
            if o.probabilities.shape != (k,):
                raise RULError(f"{o.probabilities.size} probabilities for {k} stages "
                               f"(boundaries {list(self.stages)})", record=o.record)
        cycles = np.array([o.cycles for o in obs])
        if np.any(np.diff(cycles) < 0):
            i = int(np.argmax(np.diff(cycles) < 0)) + 1
            raise RULError(f"cycles go backwards: {cycles[i]!r} after {cycles[i - 1]!r}", record=obs[i].record)
        q = self._evidence(np.stack([o.probabilities for o in obs]))
        lo_s, hi_s = self.rate_range
        lo_f, hi_f = self.offset_range
        for _ in range(2):
            log_s, f = self._grid(lo_s, hi_s, lo_f, hi_f)
            logp = self._log_like(log_s, f, cycles, q) + self._log_prior(log_s)[:, None]
            top = logp.max()
            w = np.exp(logp - top)
            mass = w.sum()
            w /= mass
            # refine over where the posterior is (1e-6 .. 1 - 1e-6 of each marginal, plus a step)
            ms, mf = w.sum(axis=1), w.sum(axis=0)
            cs, cf = np.cumsum(ms), np.cumsum(mf)
            i0 = max(0, int(np.searchsorted(cs, 1e-6)) - 1)
            i1 = min(log_s.size - 1, int(np.searchsorted(cs, 1 - 1e-6)) + 1)
            j0 = max(0, int(np.searchsorted(cf, 1e-6)) - 1)
            j1 = min(f.size - 1, int(np.searchsorted(cf, 1 - 1e-6)) + 1)
            lo_s, hi_s = math.exp(log_s[i0]), math.exp(log_s[i1])
            lo_f, hi_f = f[j0], f[j1]
        self.log_rates_, self.offsets_, self.posterior_ = log_s, f, w
        d_ls = log_s[1] - log_s[0]
        d_f = (f[1] - f[0]) if f.size > 1 else 1.0
        self.log_evidence_ = float(top + math.log(mass * d_ls * d_f))
        self.observations_ = obs
        self.now_ = float(cycles[-1])
        return self

    def _check_fitted(self):
        if not hasattr(self, "posterior_"):
            raise RULError("call fit(observations) before estimate()")

    def damage_quantiles(self, cycles, q=(0.05, 0.5, 0.95)) -> np.ndarray:
        """Posterior quantiles of D_real at ``cycles`` (n,) -> (len(q), n)."""
        self._check_fitted()
        n = np.atleast_1d(np.asarray(cycles, dtype=float))
        s = np.exp(self.log_rates_)[:, None]
        tau = self.offsets_[None, :] * self.life_model
        w = self.posterior_.ravel()
        out = np.empty((len(q), n.size))
        for j, nj in enumerate(n):
            out[:, j] = weighted_quantile(self.trajectory.damage_at(s * nj + tau), w, q)
        return out

    def failure_samples(self) -> tuple[np.ndarray, np.ndarray]:
        """(failure cycles per grid point (R*F,), weights)."""
        self._check_fitted()
        s = np.exp(self.log_rates_)[:, None]
        tau = self.offsets_[None, :] * self.life_model
        return ((self.life_model - tau) / s).ravel(), self.posterior_.ravel()

    def estimate(self, now: float | None = None) -> RULEstimate:
        """Current damage, RUL and failure cycles at ``now`` (default: the last record's cycles)."""
        self._check_fitted()
        now = self.now_ if now is None else float(now)
        if not (math.isfinite(now) and now >= 0):
            raise RULError(f"now must be finite cycles >= 0, got {now!r}")
        q = ((1 - self.band) / 2, 0.5, (1 + self.band) / 2)
        n_fail, w = self.failure_samples()
        rul = np.maximum(0.0, n_fail - now)
        s = np.exp(self.log_rates_)[:, None] * np.ones_like(self.posterior_)
        f = np.ones_like(self.posterior_) * self.offsets_[None, :]
        d_now = self.trajectory.damage_at(s * now + f * self.life_model).ravel()
        dq = weighted_quantile(d_now, w, q)
        rq = weighted_quantile(rul, w, q)
        fq = weighted_quantile(n_fail, w, q)
        sq = weighted_quantile(s.ravel(), w, q)
        warnings = []
        ms = self.posterior_.sum(axis=1)
        for edge, val, name in ((ms[0], self.rate_range[0], "lower"), (ms[-1], self.rate_range[1], "upper")):
            at_edge = (name == "lower" and math.isclose(self.log_rates_[0], math.log(val))) or \
                      (name == "upper" and math.isclose(self.log_rates_[-1], math.log(val)))
            if at_edge and edge > 1e-3:
                warnings.append(f"the posterior reaches the {name} end of rate_range ({val:g}): "
                                f"the records disagree with the model by more than that factor")
        if self.threshold > 1.1 * self.stages[-1]:
            warnings.append(f"threshold {self.threshold:.4g} lies well above the last stage boundary "
                            f"{self.stages[-1]:.4g}: the records cannot see it, the crossing is the model's "
                            f"shape extrapolated")
        return RULEstimate(
            now_cycles=now, current_damage=float(dq[1]), damage_band=(float(dq[0]), float(dq[2])),
            rul_cycles=float(rq[1]), rul_band=(float(rq[0]), float(rq[2])),
            failure_cycles=float(fq[1]), failure_band=(float(fq[0]), float(fq[2])),
            threshold=self.threshold, damage_kind=self.trajectory.kind,
            rate_factor=float(sq[1]), rate_band=(float(sq[0]), float(sq[2])),
            offset_fraction=float(weighted_quantile(f.ravel(), w, 0.5)),
            probability_failed=float(w[d_now >= self.threshold].sum()),
            n_observations=len(self.observations_), band=self.band, speed_hz=self.speed_hz,
            warnings=tuple(warnings))
