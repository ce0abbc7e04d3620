"""Degradation models: the common interface and the damage states.

A model is stateless configuration (coefficients).  The damage lives in an immutable state
object; ``advance`` returns a new state after ``cycles`` more pinion revolutions under a given
:class:`~twin.degradation.load.MeshLoad`.  One pinion revolution is one load cycle for every
point of every pinion flank, so "cycles" counts both.

Damage fields are sampled on a roll-position grid ``xi`` (n,) covering [0, 1]: the pinion flank
point at xi is the one that is the contact centre when the pair is at roll position xi.  Scalar
summaries are means over the active flank weighted by arc length along the involute (the
physical flank area per unit face width), see :func:`flank_mean`.

The models are deterministic; nothing here draws random numbers.
"""
from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad, TransmittedLoad
from twin.errors import ParameterError

_COVER_TOL = 1e-9


def flank_mean(geometry: GearPair, xi: np.ndarray, field: np.ndarray) -> float:
    """Mean of ``field`` (n,) over the active pinion flank, weighted by involute arc length.

    mean = integral field du / (u(1) - u(0)) with u = rho1^2 / (2 rb1) (trapezoidal rule); the
    flank is much longer per unit xi at the tip than at the root (du/dxi is proportional to rho1).
    """
    u = geometry.flank_position(xi)
    return float(np.trapezoid(field, u) / (u[-1] - u[0]))


def _check_grid(name: str, xi, values, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    xi = np.array(xi, dtype=float)
    values = np.array(values, dtype=float)
    if xi.ndim != 1 or values.shape != xi.shape or xi.size < 2:
        raise ParameterError(f"{name}: xi and the damage field must be 1-D of the same length >= 2, "
                             f"got shapes {xi.shape} and {values.shape}")
    if not np.all(np.isfinite(xi)) or np.any(np.diff(xi) <= 0):
        raise ParameterError(f"{name}: xi must be finite and strictly increasing, got {xi!r}")
    if xi[0] > _COVER_TOL or xi[-1] < 1 - _COVER_TOL or xi[0] < -_COVER_TOL or xi[-1] > 1 + _COVER_TOL:
        raise ParameterError(f"{name}: xi must run from 0 to 1 (the path of contact), got [{xi[0]!r}, {xi[-1]!r}]")
    bad = ~np.isfinite(values) | (values < lo) | (values > hi)
    if bad.any():
        raise ParameterError(f"{name}: damage values must lie in [{lo}, {hi}], got {values[bad][0]!r}")
    xi.setflags(write=False)
    values.setflags(write=False)
    return xi, values


def _check_cycles(name: str, cycles, allow_zero: bool) -> float:
    ok = isinstance(cycles, (int, float, np.integer, np.floating)) and not isinstance(cycles, bool)
    if ok:
        value = float(cycles)
        ok = math.isfinite(value) and (value > 0 or (allow_zero and value == 0))
    if not ok:
        bound = ">= 0" if allow_zero else "> 0"
        raise ParameterError(f"{name} must be a finite number {bound}, got {cycles!r}")
    return value


@dataclass(frozen=True, eq=False)
class WearState:
    """Abrasive wear of the pinion flank and of the gear flank it meshes with.

    Attributes
    ----------
    cycles : float
        Pinion revolutions run so far.
    xi : (n,) float array
        Roll positions of the flank points, 0 .. 1: the pinion (gear) flank point at xi is the
        one in contact when the pair is at xi.
    depth : (n,) float array
        Wear depth of the pinion flank [m] normal to the flank (= along the line of action), >= 0.
    geometry : GearPair
        The gear pair the grid refers to.
    gear_depth : (n,) float array, optional
        Wear depth of the gear flank [m] at the same roll positions (zeros when not given).
    pinion_form, gear_form : (n,) float arrays, optional
        The as-manufactured profile form deviation of each flank: material standing proud of the
        involute [m] (>= 0, zeros when not given).  The flank surface lies at ``form - depth``
        from the involute; running-in wears the proud parts first.
    """

    cycles: float
    xi: np.ndarray
    depth: np.ndarray
    geometry: GearPair
    gear_depth: np.ndarray | None = None
    pinion_form: np.ndarray | None = None
    gear_form: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "cycles", _check_cycles("WearState.cycles", self.cycles, allow_zero=True))
        xi, depth = _check_grid("WearState", self.xi, self.depth, 0.0, math.inf)
        object.__setattr__(self, "xi", xi)
        object.__setattr__(self, "depth", depth)
        for name in ("gear_depth", "pinion_form", "gear_form"):
            value = np.zeros(xi.shape) if getattr(self, name) is None else getattr(self, name)
            _, value = _check_grid(f"WearState.{name}", xi, value, 0.0, math.inf)
            object.__setattr__(self, name, value)

    def with_depths(self, cycles: float, depth: np.ndarray, gear_depth: np.ndarray) -> "WearState":
        """The same flanks (grid, form) after ``cycles`` revolutions with new depths."""
        return WearState(cycles, self.xi, depth, self.geometry, gear_depth, self.pinion_form, self.gear_form)

    def deviations(self) -> tuple[np.ndarray, np.ndarray]:
        """Material missing from each flank relative to its most proud point [m], (n,) each:
        ``depth - form + max(form)`` (>= 0; a constant is backlash)."""
        return (self.depth - self.pinion_form + self.pinion_form.max(),
                self.gear_depth - self.gear_form + self.gear_form.max())

    @classmethod
    def pristine(cls, geometry: GearPair, n_grid: int) -> "WearState":
        """Unworn flanks on ``n_grid`` equally spaced roll positions."""
        return cls(0.0, np.linspace(0.0, 1.0, n_grid), np.zeros(n_grid), geometry, np.zeros(n_grid))

    @property
    def gear_mean_depth(self) -> float:
        """Mean wear depth over the active gear flank [m], weighted by its involute arc length."""
        g = self.geometry
        u2 = g.rho2(self.xi) ** 2 / (2.0 * g.base_radius_gear)
        return float(np.trapezoid(self.gear_depth, u2) / (u2[-1] - u2[0]))

    @property
    def damage(self) -> np.ndarray:
        """The damage field, here the depth [m], shape (n,)."""
        return self.depth

    @property
    def mean_depth(self) -> float:
        """Mean wear depth over the active flank [m] (worn volume / flank area), see :func:`flank_mean`."""
        return flank_mean(self.geometry, self.xi, self.depth)

    @property
    def max_depth(self) -> float:
        """Largest wear depth [m]."""
        return float(self.depth.max())


@dataclass(frozen=True, eq=False)
class PittingState:
    """Fatigue pitting of the pinion flank.

    Attributes
    ----------
    cycles : float
        Pinion revolutions run so far (N in Eq. 11 of Feng et al.).
    xi : (n,) float array
        Roll positions of the flank points, 0 .. 1.
    density : (n,) float array
        Local pitting density D (pitted fraction of the flank area), in [0, 1].
    geometry : GearPair
        The gear pair the grid refers to.
    """

    cycles: float
    xi: np.ndarray
    density: np.ndarray
    geometry: GearPair

    def __post_init__(self):
        object.__setattr__(self, "cycles", _check_cycles("PittingState.cycles", self.cycles, allow_zero=True))
        xi, density = _check_grid("PittingState", self.xi, self.density, 0.0, 1.0)
        object.__setattr__(self, "xi", xi)
        object.__setattr__(self, "density", density)

    @classmethod
    def pristine(cls, geometry: GearPair, n_grid: int) -> "PittingState":
        """Unpitted flank on ``n_grid`` equally spaced roll positions."""
        return cls(0.0, np.linspace(0.0, 1.0, n_grid), np.zeros(n_grid), geometry)

    @property
    def damage(self) -> np.ndarray:
        """The damage field, here the local density, shape (n,)."""
        return self.density

    @property
    def pitting_density(self) -> float:
        """Pitted fraction of the active flank area, the quantity measured on the surface moulds."""
        return flank_mean(self.geometry, self.xi, self.density)

    @property
    def max_density(self) -> float:
        """Largest local pitting density."""
        return float(self.density.max())


class DegradationModel(ABC):
    """A surface-degradation law advanced in jumps of many load cycles.

    Subclasses set ``state_type`` and implement the single hook :meth:`_advance`; the public
    :meth:`advance` validates its arguments first, so the hook may assume them valid.
    """

    state_type: ClassVar[type]
    #: True for models that compute the load along the path themselves (from the transmitted force).
    accepts_transmitted_load: ClassVar[bool] = False

    def initial_state(self, geometry: GearPair, n_grid: int = 101):
        """Undamaged state on ``n_grid`` equally spaced roll positions in [0, 1]."""
        if not isinstance(geometry, GearPair):
            raise ParameterError(f"geometry must be a GearPair, got {geometry!r}")
        if not (isinstance(n_grid, (int, np.integer)) and n_grid >= 2):
            raise ParameterError(f"n_grid must be an integer >= 2, got {n_grid!r}")
        return self.state_type.pristine(geometry, int(n_grid))

    def state_from_field(self, geometry: GearPair, cycles: float, xi, field):
        """Rebuild this model's state from a stored damage field (e.g. to resume a run).

        ``field`` (n,) is the depth [m] for wear or the density for pitting, on roll positions
        ``xi`` (n,); validated like any state.
        """
        if not isinstance(geometry, GearPair):
            raise ParameterError(f"geometry must be a GearPair, got {geometry!r}")
        return self.state_type(cycles, xi, field, geometry)

    def advance(self, state, load: MeshLoad, cycles: float, omega1: float):
        """State after ``cycles`` more pinion revolutions under ``load`` at pinion speed ``omega1`` [rad/s].

        The load is held constant over the jump ("cycle jumping"): the caller re-samples it from
        the co-simulation between jumps, so the jump must be short enough for the damage not to
        change the load much.

        Raises
        ------
        ParameterError
            ``cycles`` is not finite and > 0, ``omega1`` is not finite and > 0, the load grid
            does not cover the path of contact [0, 1], or ``state`` is not this model's state.
        """
        if not isinstance(state, self.state_type):
            raise ParameterError(f"{type(self).__name__} advances a {self.state_type.__name__}, "
                                 f"got {type(state).__name__}")
        if isinstance(load, TransmittedLoad):
            if not self.accepts_transmitted_load:
                raise ParameterError(f"{type(self).__name__} needs the load along the path (a MeshLoad), "
                                     "not only the transmitted force")
        elif not isinstance(load, MeshLoad):
            raise ParameterError(f"load must be a MeshLoad or a TransmittedLoad, got {type(load).__name__}")
        elif not load.covers_path:
            raise ParameterError(f"load grid must cover the path of contact [0, 1], got "
                                 f"[{load.xi[0]!r}, {load.xi[-1]!r}]")
        n = _check_cycles("cycles", cycles, allow_zero=False)
        ok = isinstance(omega1, (int, float, np.integer, np.floating)) and not isinstance(omega1, bool)
        if not (ok and math.isfinite(float(omega1)) and float(omega1) > 0):
            raise ParameterError(f"omega1 (pinion speed) must be a finite number > 0 rad/s, got {omega1!r}")
        return self._advance(state, load, n, float(omega1))

    @abstractmethod
    def _advance(self, state, load: MeshLoad, cycles: float, omega1: float):
        """Model-specific update; arguments already validated."""

    def cycles_for_increment(self, state, load: MeshLoad, omega1: float, max_increment: float, *,
                             max_cycles: float = 1e10, rtol: float = 1e-3) -> float:
        """Number of cycles after which the largest local damage increment reaches ``max_increment``.

        Use it to size the cycle jumps between load re-samplings (README.md, "Coupling").
        ``max_increment`` is in the unit of ``state.damage`` (m for wear, 1 for pitting).
        Returns ``max_cycles`` when even that many cycles stay below ``max_increment``, and the
        lower end of the search, ``1e-12 max_cycles``, when that already exceeds it.

        The increment grows monotonically with cycles for every model here; the root is found by
        regula falsi (Illinois variant) on log(increment) against log(cycles), which is exact in
        one step for wear (increment proportional to cycles) and converges superlinearly for
        pitting.
        """
        if not (isinstance(max_increment, (int, float)) and math.isfinite(max_increment) and max_increment > 0):
            raise ParameterError(f"max_increment must be a finite number > 0, got {max_increment!r}")
        max_cycles = _check_cycles("max_cycles", max_cycles, allow_zero=False)
        target = math.log(max_increment)

        def residual(log_n: float) -> float:
            inc = float(np.max(self.advance(state, load, math.exp(log_n), omega1).damage - state.damage))
            return math.log(inc) - target if inc > 0 else -math.inf

        lo, hi = math.log(1e-12 * max_cycles), math.log(max_cycles)
        f_hi = residual(hi)
        if f_hi <= 0:
            return max_cycles
        f_lo = residual(lo)
        if f_lo >= 0:
            return math.exp(lo)
        side = 0
        for _ in range(200):
            # Secant point of the bracket; a bisection while an end is still -inf (no damage).
            x = 0.5 * (lo + hi) if math.isinf(f_lo) else (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
            f_x = residual(x)
            if abs(f_x) <= rtol or hi - lo <= 1e-12:
                return math.exp(x)
            if f_x < 0:
                lo, f_lo = x, f_x
                if side == -1 and not math.isinf(f_hi):
                    f_hi *= 0.5                       # Illinois: unstick the retained end
                side = -1
            else:
                hi, f_hi = x, f_x
                if side == 1 and not math.isinf(f_lo):
                    f_lo *= 0.5
                side = 1
        return math.exp(lo)
