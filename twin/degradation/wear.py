"""Abrasive wear of both flanks of a spur pair, driven by a loaded tooth contact analysis.

Archard's law (Feng et al. Eq. 10), ``dh = K p ds`` with ``ds`` the sliding distance, on each
flank, with the contact pressure from :class:`~twin.degradation.ltca.LoadedContact` of the
current worn flanks at the transmitted force:

* Over one mesh cycle the LTCA is solved at M phases.  At phase m the pair at roll xi carries
  forces q_i on cells x_i (width w) of its contact; the pressure on the intact face width is
  ``p_i = q_i / (w L (1 - D_i))``.
* During the phase step dt = T_mesh / M the contact moves over the pinion flank by v1 dt =
  rho1 2 pi / (z1 M) and over the gear flank by rho2 2 pi / (z2 M).  A flank point at arc u gets
  ``p_i ds = p_i (v_s / v) l_i(u)`` where l_i(u) is the time the cell covers the point as it
  sweeps times v (the cell convolved with the sweep, the pressure taken piecewise linear between
  phases and held up to the end of the path where the pair leaves it), v the rolling speed of
  that flank and v_s = |v1 - v2| the sliding speed (speed-independent per pass: v_s / v).  Each
  grid point gets the mean over the flank stretch it stands for.
* Wear levels what is narrower than the contact: the increment of a flank point is the
  Hertz-weighted mean over the contact half-width b of the pair's force there
  (:func:`twin.degradation._hertz.contact_average`).
* Per pinion revolution every pinion flank point passes through the mesh once and every gear
  flank point z1 / z2 times: each flank has its own cycle count.

So both flanks wear where they slide under load; the worn profiles feed back through the LTCA
(a pair whose flanks are worn more carries less load, and contact moves to where the worn
flanks still touch).  Uniform thinning of a flank changes only the rigid approach (backlash),
not the load sharing.

**Running-in.**  A fresh flank wears faster while its roughness and the asperities of its tip
and root edges are removed.  The local wear coefficient is
``K (1 + (beta - 1) exp(-h / h_r))`` with h the local depth already removed: ``beta`` times the
steady coefficient on a new surface, decaying over ``h_r`` (of the order of the roughness
heights, a few um).  Defaults beta = 5, h_r = 2 um, the order of the running-in wear-rate
ratios reported for steel gears (e.g. Andersson & Eriksson 1990; Flodin & Andersson 1997 use a
steady coefficient after a run-in).  The tip/root relief that running-in produces comes out of
the load distribution itself: the ends of the path of contact slide most.

Not modelled: tip-edge contact (contact is sought on the active flanks only), the thinning of
the tooth body by wear (the tooth-body compliance stays that of the new tooth), wear of the
flank that does not transmit load.
"""
from __future__ import annotations

import math

import numpy as np

from twin.degradation._hertz import contact_average
from twin.degradation._wear_kernels import deposit_matrix, integrate
from twin.degradation.archard import DEFAULT_WEAR_COEFFICIENT
from twin.degradation.base import DegradationModel, WearState
from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad, TransmittedLoad
from twin.degradation.ltca import FlankDamage, LoadedContact, MeshCycle
from twin.errors import ParameterError

DEFAULT_RUNNING_IN_FACTOR = 5.0
DEFAULT_RUNNING_IN_DEPTH = 2.0e-6
DEFAULT_LTCA_INCREMENT = 3.0e-6
_N_SUB = 4                     # sub-points of a grid point's flank stretch in the deposit mean


class FlankWear(DegradationModel):
    """Archard wear of the pinion and the gear flank under the LTCA contact pressure.

    Parameters
    ----------
    wear_coefficient : float
        Steady dimensional wear coefficient K [m^2/N].
    running_in_factor : float
        beta >= 1, the coefficient of a new surface relative to K.
    running_in_depth : float
        h_r > 0 [m], the local depth over which the excess decays.
    n_positions : int
        Phases of the mesh cycle the LTCA is solved at (>= 8).
    substep_fraction : float
        Largest change of a pair's separation within one sub-step of a jump, as a fraction of
        that pair's elastic approach (0 < f <= 1; see :meth:`_advance`).
    form_deviation : float
        Peak-to-valley of the as-manufactured profile form deviation of each flank [m]
        (ISO 1328-1 f_f_alpha; :func:`iso1328_profile_form`); 0 for perfect involutes.
    form_seed : int
        Seed of the form deviation's shape (:func:`profile_form`).
    ltca_increment : float
        Local wear [m] (90th percentile over a flank) after which a jump takes a new LTCA of
        the worn flanks (see :meth:`_advance`).
    """

    state_type = WearState
    accepts_transmitted_load = True

    def __init__(self, wear_coefficient: float = DEFAULT_WEAR_COEFFICIENT, *,
                 running_in_factor: float = DEFAULT_RUNNING_IN_FACTOR,
                 running_in_depth: float = DEFAULT_RUNNING_IN_DEPTH, n_positions: int = 48,
                 substep_fraction: float = 0.25, form_deviation: float = 0.0, form_seed: int = 0,
                 ltca_increment: float = DEFAULT_LTCA_INCREMENT):
        for name, value, lo in (("wear_coefficient", wear_coefficient, 0.0), ("running_in_depth", running_in_depth, 0.0)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > lo):
                raise ParameterError(f"{name} must be a finite number > 0, got {value!r}")
        if not (isinstance(running_in_factor, (int, float)) and math.isfinite(running_in_factor)
                and running_in_factor >= 1):
            raise ParameterError(f"running_in_factor must be a finite number >= 1, got {running_in_factor!r}")
        if not (isinstance(n_positions, (int, np.integer)) and n_positions >= 8):
            raise ParameterError(f"n_positions must be an integer >= 8, got {n_positions!r}")
        if not (isinstance(substep_fraction, (int, float)) and 0 < substep_fraction <= 1):
            raise ParameterError(f"substep_fraction must be a number in (0, 1], got {substep_fraction!r}")
        self.wear_coefficient = float(wear_coefficient)
        self.running_in_factor = float(running_in_factor)
        self.running_in_depth = float(running_in_depth)
        self.n_positions = int(n_positions)
        self.substep_fraction = float(substep_fraction)
        if not (isinstance(form_deviation, (int, float)) and math.isfinite(form_deviation) and form_deviation >= 0):
            raise ParameterError(f"form_deviation must be a finite number >= 0 m, got {form_deviation!r}")
        self.form_deviation = float(form_deviation)
        self.form_seed = int(form_seed)
        if not (isinstance(ltca_increment, (int, float)) and math.isfinite(ltca_increment) and ltca_increment > 0):
            raise ParameterError(f"ltca_increment must be a finite number > 0 m, got {ltca_increment!r}")
        self.ltca_increment = float(ltca_increment)
        self._contact: dict[GearPair, LoadedContact] = {}
        # (state, force, sweep): sizing a jump and taking it share one LTCA (states are immutable:
        # the cache holds the state object itself)
        self._last: tuple | None = None
        self._calls = 0

    def __repr__(self) -> str:
        return (f"FlankWear(wear_coefficient={self.wear_coefficient!r}, running_in_factor="
                f"{self.running_in_factor!r}, running_in_depth={self.running_in_depth!r}, "
                f"n_positions={self.n_positions!r}, substep_fraction={self.substep_fraction!r}, "
                f"ltca_increment={self.ltca_increment!r})")

    def contact(self, geometry: GearPair) -> LoadedContact:
        """The LTCA of ``geometry`` (built once per geometry)."""
        if geometry not in self._contact:
            self._contact[geometry] = LoadedContact(geometry)
        return self._contact[geometry]

    @staticmethod
    def damage(state: WearState) -> FlankDamage:
        d1, d2 = state.deviations()
        return FlankDamage.of(state.xi, pinion_depth=d1, gear_depth=d2)

    def initial_state(self, geometry: GearPair, n_grid: int = 201):
        """New flanks on ``n_grid`` roll positions, with the model's form deviation."""
        state = super().initial_state(geometry, n_grid)
        if self.form_deviation == 0:
            return state
        f1, f2 = profile_form(state.xi, self.form_deviation, self.form_seed)
        return WearState(0.0, state.xi, state.depth, geometry, state.gear_depth, f1, f2)

    def mesh_cycle(self, state: WearState, force: float) -> MeshCycle:
        """LTCA of the state's worn flanks over one mesh cycle at ``force`` [N].

        The phases sampled shift by the golden ratio of a step from one evaluation to the next
        (deterministic), so that successive jumps do not sample the same mesh positions and
        leave no ripple at the sampling period in the accumulated wear."""
        self._calls += 1
        offset = (0.5 + 0.6180339887498949 * self._calls) % 1.0
        return self.contact(state.geometry).mesh_cycle(force, self.damage(state), n_positions=self.n_positions,
                                                       offset=offset)

    def sweep(self, state: WearState, load) -> "_Sweep":
        """The mesh cycle's contacts of ``state`` at the load, resolved per pair and phase."""
        force = _force(load, state.geometry)
        if self._last is not None and self._last[0] is state and self._last[1] == force:
            return self._last[2]
        result = _Sweep.of(state, self.mesh_cycle(state, force), self.n_positions)
        self._last = (state, force, result)
        return result

    def rates(self, state: WearState, load) -> tuple[np.ndarray, np.ndarray]:
        """integral of p ds per pinion revolution [Pa m] of the pinion and the gear flank points,
        (n,) each (times K: the depth removed per revolution without running-in)."""
        sw = self.sweep(state, load)
        return sw.d1 @ sw.f_scale, sw.d2 @ sw.f_scale

    def depth_per_cycle(self, state: WearState, load) -> tuple[np.ndarray, np.ndarray]:
        """Depth removed per pinion revolution [m] from each flank, (n,) each, at the state's
        load sharing, with the running-in factor of each point's current depth."""
        r1, r2 = self.rates(state, load)
        return (self.wear_coefficient * r1 * self._running_in(state.depth),
                self.wear_coefficient * r2 * self._running_in(state.gear_depth))

    def _running_in(self, depth: np.ndarray) -> np.ndarray:
        return 1.0 + (self.running_in_factor - 1.0) * np.exp(-depth / self.running_in_depth)

    def _advance(self, state: WearState, load, cycles: float, omega1: float) -> WearState:
        """Integrate the wear over ``cycles`` in segments, each with a fresh LTCA of its flanks.

        Within a segment the LTCA fixes where each pair touches and the shape of its pressure;
        the contact moves on a worn flank as soon as the wear at its spot exceeds the
        differences of the separation around it (a fraction of a um), so a spot held for a long
        segment would be dug into a groove a few contact widths wide that the next LTCA then
        avoids: a ripple of the integration, not of the physics.  A segment therefore ends when
        the 90th percentile of the local wear of either flank reaches ``ltca_increment``
        (3 um by default; for the 18/35 flanks worn to 300 um, 3 um gives a smooth profile where
        10 um leaves grooves of 100 um).  Within a segment the load sharing between the pairs
        follows the wear by sub-steps (:meth:`_integrate`).
        """
        done = 0.0
        while done < cycles * (1 - 1e-12):
            d1, d2 = self.depth_per_cycle(state, load)
            peak = max(float(np.percentile(d1, 90)), float(np.percentile(d2, 90)))
            segment = cycles - done
            if peak > 0 and segment * peak > self.ltca_increment:
                # equal segments, so the last is not a sliver
                segment = segment / math.ceil(segment * peak / self.ltca_increment)
            state = self._integrate(state, self.sweep(state, load), segment)
            done += segment
        return state

    def _integrate(self, state: WearState, sw: "_Sweep", cycles: float) -> WearState:
        """Wear over ``cycles`` with the contacts of one LTCA, in sub-steps.

        The load sharing responds to wear through the separations of the pairs: a pair worn by
        more than its elastic approach (a fraction of a um at light load) loses its load.  So
        each pair's force follows its separation by the linear pair law
        ``F_j = k_j max(0, delta - e_j)`` (k_j the LTCA's secant stiffness of that pair, e_j its
        separation plus the pressure-weighted mean wear under its contact since the start),
        re-solved per phase every sub-step; a sub-step changes no separation by more than
        ``substep_fraction`` of the smallest elastic approach.  The local rate is
        ``K (d @ F) (1 + (beta - 1) exp(-h / h_r))`` with d the deposits per newton of each pair
        (compiled: :func:`twin.degradation._wear_kernels.integrate`).
        """
        h1, h2 = state.depth, state.gear_depth
        dh1, dh2, ok = integrate(h1, h2, sw.d1, sw.d2, sw.inv_ref, sw.e0, sw.press1, sw.press2, sw.table,
                                 sw.stiffness, sw.force, sw.approach_scale, self.wear_coefficient,
                                 self.running_in_factor, self.running_in_depth, self.substep_fraction, cycles)
        if not ok:
            raise ParameterError("no tooth pair stiffness to carry the load at a mesh phase of the wear integration")
        return state.with_depths(state.cycles + cycles, h1 + dh1, h2 + dh2)

    def cycles_for_increment(self, state, load, omega1: float, max_increment: float, *,
                             max_cycles: float = 1e10, rtol: float = 1e-3) -> float:
        """Cycles after which the local depth increment of either flank reaches ``max_increment``
        [m] at its 90th percentile over the flank, from the rates at the start.  (The percentile,
        not the maximum: a few points just touched at the ends of the path, still at their
        running-in rate, would otherwise set every jump; the sub-steps keep the load sharing
        stable whatever the jump.)"""
        if not (isinstance(max_increment, (int, float)) and math.isfinite(max_increment) and max_increment > 0):
            raise ParameterError(f"max_increment must be a finite number > 0, got {max_increment!r}")
        d1, d2 = self.depth_per_cycle(state, load)
        peak = max(float(np.percentile(d1, 90)), float(np.percentile(d2, 90)))
        return max_cycles if peak <= 0 else min(max_cycles, max_increment / peak)


def iso1328_profile_form(module: float, diameter: float, quality: int) -> float:
    """Profile form tolerance f_f_alpha [m] of ISO 1328-1:1995 for a quality class (3..12):
    (2.5 sqrt(m) + 0.17 sqrt(d) + 0.5) um for class 5 (m, d in mm), times sqrt(2) per class."""
    if not (isinstance(quality, (int, np.integer)) and 1 <= quality <= 12):
        raise ParameterError(f"quality must be an ISO 1328 class 1..12, got {quality!r}")
    m, d = module * 1e3, diameter * 1e3
    return (2.5 * math.sqrt(m) + 0.17 * math.sqrt(d) + 0.5) * 2.0 ** ((quality - 5) / 2) * 1e-6


def profile_form(xi: np.ndarray, peak_to_valley: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Seeded form deviations of the pinion and the gear flank (material proud of the involute,
    >= 0, peak-to-valley ``peak_to_valley`` each): a waviness of 1 to 4 cycles over the active
    profile with amplitudes falling as 1/k, as a hobbed or ground flank's form chart shows."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(2):
        f = np.zeros(xi.shape)
        for k in range(1, 5):
            f += rng.standard_normal() / k * np.cos(math.pi * k * xi + rng.uniform(0, 2 * math.pi))
        f -= f.min()
        out.append(f * (peak_to_valley / f.max()) if f.max() > 0 else f)
    return out[0], out[1]


def _force(load, geometry: GearPair) -> float:
    if isinstance(load, TransmittedLoad):
        return load.force
    if isinstance(load, MeshLoad):
        # the single-pair zone carries the whole force: the largest pair force is the transmitted one
        return float(load.force.max())
    raise ParameterError(f"load must be a TransmittedLoad or a MeshLoad, got {type(load).__name__}")


class _Sweep:
    """The contacts of one mesh cycle, one column per (phase, pair): pressure deposits on both
    flanks (at the pair's LTCA force, or per newton for a pair out of load), the pair's
    separation, the flank points under its pressure and its secant stiffness: what the pair law
    of :meth:`FlankWear._integrate` needs to redistribute the force as the flanks wear."""

    def __init__(self, d1, d2, f0, inv_ref, e0, press1, press2, stiffness, phase_of, n_phases, force, approach_scale):
        self.d1, self.d2 = d1, d2                       # (n, J) deposits [Pa m per revolution / N of ref]
        self.f_scale = f0 * inv_ref                     # (J,) 1 for loaded items, 0 for the others
        self.inv_ref = inv_ref                          # (J,) 1 / reference force of the deposit
        self.e0 = e0                                    # (J,) separation [m]
        self.press1, self.press2 = press1, press2       # (J, n) pressure weights under each contact
        self.stiffness = stiffness                      # (J,) N/m
        self.phase_of = phase_of                        # (J,) phase index
        self.n_phases = n_phases
        self.force = force
        self.approach_scale = approach_scale            # smallest elastic approach of a loaded pair [m]

    @property
    def table(self) -> np.ndarray:
        """(phases, slots) item index of each pair at each phase, -1 where none."""
        if self.__dict__.get("_table_cache") is None:
            width = int(np.max(np.bincount(self.phase_of, minlength=self.n_phases)))
            table = -np.ones((self.n_phases, width), dtype=int)
            fill = np.zeros(self.n_phases, dtype=int)
            for j, m in enumerate(self.phase_of):
                table[m, fill[m]] = j
                fill[m] += 1
            self.__dict__["_table_cache"] = table
        return self.__dict__["_table_cache"]

    @classmethod
    def of(cls, state: WearState, cycle: MeshCycle, n_positions: int) -> "_Sweep":
        g = state.geometry
        xi = state.xi
        rb1, rb2 = g.base_radius_pinion, g.base_radius_gear
        s = g.contact_start + xi * g.path_of_contact_length
        u1 = s ** 2 / (2 * rb1)
        u2 = (g.line_of_action_length - s) ** 2 / (2 * rb2)
        # the geometry's scalars, read once (its properties recompute them on each call)
        s_a, length, loa = g.contact_start, g.path_of_contact_length, g.line_of_action_length
        z1, z2, face = g.z1, g.z2, g.face_width
        contact = None
        flanks = None
        cells = {"c1": [], "c2": [], "w1": [], "w2": []}
        per_item = {"a": [], "s1": [], "s2": [], "ahead": [], "behind": [], "count": []}
        step = 1.0 / (n_positions * g.contact_ratio)          # roll advance per phase
        under = {"xi1": [], "xi2": [], "w": []}                 # the flank points under each pair's pressure
        f0, ref, e0, kk, phase, loaded_flag = [], [], [], [], [], []
        approach = []
        j = 0
        for m, pos in enumerate(cycle.positions):
            for pair in pos.pairs:
                xc = pair.xi
                rho1 = s_a + xc * length
                rho2 = loa - rho1
                slide = abs(rho1 - rho2 * z1 / z2)                   # v_s / omega1
                loaded = pair.force > 0
                total = pair.total
                if total > 0:
                    x, q = pair.x[loaded], pair.force[loaded]
                    width = pair.width
                    centroid = float(np.sum(x * q) / total)
                    reference = total
                    # the secant stiffness is only well defined for a pair that carries a fair share
                    lever = pos.approach - pair.separation
                    stiffness = total / lever if total > 0.05 * cycle.force and lever > 0 else np.nan
                    if total > 0.05 * cycle.force and lever > 0:
                        approach.append(lever * cycle.force / total)
                else:
                    # out of load: a contact strip of the healthy width at the least separation,
                    # per newton
                    if contact is None:
                        from twin.degradation.ltca import contact_for
                        contact = contact_for(g)
                    if flanks is None:
                        flanks = FlankWear.damage(state)
                    sep, _ = contact.gap(xc, pair.x, flanks)
                    centroid = float(pair.x[int(np.argmin(sep))])
                    width = pair.width
                    x, q = np.array([centroid]), np.array([1.0])
                    reference = 1.0
                    stiffness = np.nan
                line_pressure = q / (width * face)
                cells["c1"].append(rho1 ** 2 / (2 * rb1) + x)
                cells["c2"].append(rho2 ** 2 / (2 * rb2) - x)
                per_item["a"].append(width / 2)
                per_item["s1"].append(math.pi * rho1 / (z1 * n_positions))
                per_item["s2"].append(math.pi * rho2 / (z2 * n_positions))
                per_item["ahead"].append((1.0 - xc) / step)
                per_item["behind"].append(xc / step)
                per_item["count"].append(x.size)
                cells["w1"].append(line_pressure * slide / rho1)                     # v_s / v1
                cells["w2"].append(line_pressure * slide / (rho2 * z1 / z2))     # v_s / v2
                p_xi1, p_xi2, _ = (contact or _contact_of(g))._flank_points(xc, x)
                under["xi1"].append(p_xi1)
                under["xi2"].append(p_xi2)
                under["w"].append(q / q.sum())
                f0.append(total)
                ref.append(reference)
                e0.append(pair.separation)
                kk.append(stiffness)
                phase.append(m)
                loaded_flag.append(total > 0)
                j += 1
        n_items = j
        cat = {k: np.concatenate(v) if v else np.empty(0) for k, v in cells.items()}
        count = np.array(per_item.pop("count"), dtype=int)
        cat.update({k: np.repeat(np.array(v, dtype=float), count) for k, v in per_item.items()})
        item = np.repeat(np.arange(n_items), count)
        d1 = np.zeros((xi.size, n_items))
        d2 = np.zeros((xi.size, n_items))
        if n_items:
            # each cell's pressure swept past the flank points, as the mean over the flank
            # stretch each grid point stands for (the grid is coarser than the contact at the
            # tips; :func:`twin.degradation._wear_kernels.deposit_matrix`)
            d1 = deposit_matrix(u1, cat["c1"], cat["a"], cat["s1"], cat["ahead"], cat["behind"], 1.0, cat["w1"], item,
                                n_items, _N_SUB)
            d2 = deposit_matrix(u2, cat["c2"], cat["a"], cat["s2"], cat["ahead"], cat["behind"], -1.0,
                                cat["w2"] * (g.z1 / g.z2), item, n_items, _N_SUB)
        kk = np.array(kk, dtype=float)
        xi_items = np.array([p.xi for pos in cycle.positions for p in pos.pairs])
        known = np.isfinite(kk)
        if not known.any():
            raise ParameterError("no tooth pair carries a fair share of the load in the contact analysis")
        if not known.all():
            kk[~known] = np.interp(xi_items[~known], xi_items[known][np.argsort(xi_items[known])],
                                   kk[known][np.argsort(xi_items[known])])
        f0 = np.array(f0)
        ref = np.array(ref)
        if n_items:
            # wear levels what is narrower than the contact: the increment is the Hertz-weighted
            # mean over the contact width of the pair's force at that roll position
            order = np.argsort(xi_items)
            pair_force = np.interp(xi, xi_items[order], f0[order])
            b = g.hertz_half_width(pair_force, xi)
            d1 = contact_average(u1, b) @ d1
            d2 = contact_average(u2, b) @ d2
        # the elastic approach of a pair carrying the whole force (the stiffest one sets the scale)
        scale = float(np.min(approach))
        # a pair's separation grows by the pressure-weighted mean of the wear under its contact
        # (to first order, Betti's theorem), not by the wear at one point of it
        un = {k: np.concatenate(v) if v else np.empty(0) for k, v in under.items()}
        rows = item
        press1 = _interp_rows(xi, un["xi1"], un["w"], rows, n_items)
        press2 = _interp_rows(xi, un["xi2"], un["w"], rows, n_items)
        return cls(d1, d2, f0, 1.0 / ref, np.array(e0), press1, press2, kk, np.array(phase),
                   len(cycle.positions), cycle.force, scale)


def _interp_rows(grid: np.ndarray, points: np.ndarray, weight: np.ndarray, rows: np.ndarray, n_rows: int) -> np.ndarray:
    """(n_rows, n) matrix M with ``M @ f`` = sum over a row's points of weight x f(point), f
    interpolated linearly on ``grid`` (increasing, (n,))."""
    out = np.zeros((n_rows, grid.size))
    j = np.clip(np.searchsorted(grid, points, side="right") - 1, 0, grid.size - 2)
    t = np.clip((points - grid[j]) / (grid[j + 1] - grid[j]), 0.0, 1.0)
    np.add.at(out, (rows, j), weight * (1.0 - t))
    np.add.at(out, (rows, j + 1), weight * t)
    return out


def _contact_of(geometry: GearPair):
    from twin.degradation.ltca import contact_for
    return contact_for(geometry)
