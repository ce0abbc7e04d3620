"""Fatigue pitting of the pinion flank: Feng et al., Eqs. (11)-(14).

At each flank point (roll position xi) the accumulated pitting density after N pinion revolutions
follows a Lundberg-Palmgren-type survival law, advanced in jumps of dN cycles:

    D_{i+1} = D_i + exp(-A N^m) - exp(-A (N + dN)^m),   A = K tau0^c V / z0^h        (11)
    tau0 = 0.3 Pmax       [Pa]   maximum orthogonal shear stress below a line contact   (12)
    z0   = 0.786 b        [m]    its depth                                              (13)
    V    = 2 b z0 2 pi R  [m^3]  stressed volume                                        (14)

with Pmax, b (Hertz half-width) and R (equivalent radius) from the current pair force at xi
(:class:`~twin.degradation.geometry.GearPair`).  For a constant load D = 1 - exp(-A N^m) is the
Weibull failure probability of the stressed volume, read as the pitted fraction of the flank
area.  The increment uses the current A with the cycle count N carried by the state, so
cycle jumps telescope exactly under a constant load (one jump of 2 dN equals two jumps of dN).

A ~ w^((c + 2 - h)/2) R^(1 - (c + h - 2)/2) = w^5 R^(-13/3) for the default exponents, so the
density concentrates where the Hertzian stress is highest: the single-pair zone (twice the load
of the double-pair zones), most at its lowest point just below the pitch point.  On the
unmodified 19-tooth involute the start of contact (xi = 0, pinion root, rho1 = 1.9 mm) is as
severe - see README.md.

The density is capped at 1: the sum of increments can only exceed it when A grows between
jumps, and a flank cannot be more than fully pitted.

Variable load.  Eq. (11) evaluates the new A at the total cycle count N, as if the current load
had acted from the start.  After a load increase late in life exp(-A_new N^m) is already ~0, so
the increment vanishes: a heavier load stops pitting.  That is harmless for the small
run-to-run changes of a re-sampled load at one operating condition, but wrong when the
operating condition changes.  ``equivalent_age=True`` uses the equivalent-age rule instead:
the age N_eq at which the current load would have produced the current density,
A N_eq^m = -ln(1 - D_i), then D_{i+1} = 1 - exp(-A (N_eq + dN)^m).  Both rules coincide (up to
rounding) while the load is constant and the state started undamaged.
"""
from __future__ import annotations

import math

import numpy as np

from twin.degradation.base import DegradationModel, PittingState
from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad
from twin.errors import ParameterError

#: Stress exponent c of Lundberg & Palmgren (Acta Polytech. Mech. Eng. Ser. 1(3), 1947): 31/3.
DEFAULT_STRESS_EXPONENT = 31.0 / 3.0
#: Depth exponent h of Lundberg & Palmgren: 7/3.
DEFAULT_DEPTH_EXPONENT = 7.0 / 3.0
#: Weibull slope m; Lundberg & Palmgren's value for line contact, 9/8.
DEFAULT_WEIBULL_SLOPE = 9.0 / 8.0
#: Pitting coefficient K [Pa^-c m^(h-3) cycles^-m] for the default exponents.  Chosen so that the
#: lubricated test of Feng et al. (20 Hz, 20 N.m brake torque -> 7.31 N.m on the pinion) reaches
#: a flank-mean pitting density of 20 % (the paper's last stage) after 1.0e7 pinion revolutions
#: (5.8 days at 20 Hz, an accelerated test of days) under the healthy static load; the first
#: 3 % stage is then reached after 1.3e6 revolutions.  It must be re-derived if c, h or m change.
DEFAULT_PITTING_COEFFICIENT = 7.9e-91

# Eq. (12) and (13) constants (Hertz line contact, maximum orthogonal shear stress).
_TAU_OVER_PMAX = 0.3
_DEPTH_OVER_B = 0.786


class FatiguePitting(DegradationModel):
    """Lundberg-Palmgren-type pitting density law, Feng et al. Eq. (11).

    Parameters
    ----------
    pitting_coefficient : float
        K [Pa^-c m^(h-3) cycles^-m], > 0.
    c : float
        Stress exponent, > 0.
    m : float
        Weibull slope (cycle exponent), > 0.
    h : float
        Depth exponent, >= 0.
    equivalent_age : bool
        False: Eq. (11) as published (age = cycle count of the state).  True: equivalent-age
        rule for loads that change between jumps (module docstring).
    """

    state_type = PittingState

    def __init__(self, pitting_coefficient: float = DEFAULT_PITTING_COEFFICIENT,
                 c: float = DEFAULT_STRESS_EXPONENT, m: float = DEFAULT_WEIBULL_SLOPE,
                 h: float = DEFAULT_DEPTH_EXPONENT, *, equivalent_age: bool = False):
        for name, value, lo in (("pitting_coefficient", pitting_coefficient, 0.0), ("c", c, 0.0), ("m", m, 0.0)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > lo):
                raise ParameterError(f"{name} must be a finite number > 0, got {value!r}")
        if not (isinstance(h, (int, float)) and math.isfinite(h) and h >= 0):
            raise ParameterError(f"h must be a finite number >= 0, got {h!r}")
        if not isinstance(equivalent_age, bool):
            raise ParameterError(f"equivalent_age must be True or False, got {equivalent_age!r}")
        self.equivalent_age = equivalent_age
        self.pitting_coefficient = float(pitting_coefficient)
        self.c = float(c)
        self.m = float(m)
        self.h = float(h)

    def __repr__(self) -> str:
        return (f"FatiguePitting(pitting_coefficient={self.pitting_coefficient!r}, c={self.c!r}, "
                f"m={self.m!r}, h={self.h!r}, equivalent_age={self.equivalent_age!r})")

    def log_rate(self, geometry: GearPair, xi, load: MeshLoad) -> np.ndarray:
        """ln A(xi) with A = K tau0^c V / z0^h [cycles^-m], shape of xi; -inf where unloaded.

        Evaluated in logarithms: tau0^c alone exceeds 1e80 in SI units.
        """
        xi = np.asarray(xi, dtype=float)
        force = load.force_at(xi)
        loaded = force > 0
        out = np.full(xi.shape, -np.inf)
        if not loaded.any():
            return out
        f, x = force[loaded], xi[loaded]
        b = geometry.hertz_half_width(f, x)
        tau0 = _TAU_OVER_PMAX * geometry.hertz_max_pressure(f, x)
        z0 = _DEPTH_OVER_B * b
        volume = 2.0 * b * z0 * 2.0 * math.pi * geometry.equivalent_radius(x)
        out[loaded] = (math.log(self.pitting_coefficient) + self.c * np.log(tau0) + np.log(volume)
                       - self.h * np.log(z0))
        return out

    def _advance(self, state: PittingState, load: MeshLoad, cycles: float, omega1: float) -> PittingState:
        # Damage per cycle depends on the stress only; omega1 acts through the load.
        a = np.exp(self.log_rate(state.geometry, state.xi, load))
        n1 = state.cycles + cycles
        if self.equivalent_age:
            density = self._equivalent_age_update(a, state.density, cycles)
        else:
            n0 = state.cycles
            # exp(-A N0^m) - exp(-A N1^m) = exp(-A N0^m) (1 - exp(-A (N1^m - N0^m))), written with
            # expm1 so that tiny increments (small A or dN) keep their relative precision.
            survival0 = np.exp(-a * n0 ** self.m) if n0 > 0 else np.ones_like(a)
            increment = survival0 * -np.expm1(-a * (n1 ** self.m - n0 ** self.m))
            density = np.minimum(1.0, state.density + increment)
        return PittingState(n1, state.xi, density, state.geometry)

    def _equivalent_age_update(self, a: np.ndarray, density: np.ndarray, cycles: float) -> np.ndarray:
        """D_new = 1 - exp(-A (N_eq + dN)^m) with A N_eq^m = -ln(1 - D); shape (n,)."""
        out = density.copy()
        live = (a > 0) & (density < 1.0)
        hazard = -np.log1p(-density[live])                     # A N_eq^m
        n_eq = (hazard / a[live]) ** (1.0 / self.m)
        out[live] = np.maximum(density[live], -np.expm1(-a[live] * (n_eq + cycles) ** self.m))
        return out
