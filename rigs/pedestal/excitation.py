"""Test inputs that are not part of normal operation: the impact hammer."""
from __future__ import annotations

import numpy as np

from .structure import I_XA, I_XB, I_YA, I_YB, LinearStructure

#: Struck pedestals by name: their DOF along each blow direction (y is the vertical of this rig).
LOCATIONS = {"pinion_pedestal": {"vertical": I_YA, "horizontal": I_XA},
             "gear_pedestal": {"vertical": I_YB, "horizontal": I_XB}}
DIRECTIONS = tuple(LOCATIONS["pinion_pedestal"])


def hammer_input(n: int, fs: float, struct: LinearStructure, location: str,
                 rate: float, seed: int, direction: str = "vertical") -> dict:
    """Hammer blows at random instants (mean ``rate`` per second), half-sine pulses of 0.2 ms
    and 150-250 N peak (a medium steel tip), on a pedestal: from above (along -y,
    ``direction="vertical"``) or from the side (along -x, ``"horizontal"``)."""
    check_impact(location, direction)
    rate = float(rate)
    if not np.isfinite(rate) or rate <= 0:
        raise ValueError(f"impacts_per_second must be > 0, got {rate!r}")
    rng = np.random.default_rng([seed, 17])
    force = np.zeros(n)
    width = max(3, int(2e-4 * fs))
    pulse = np.sin(np.pi * (np.arange(width) + 0.5) / width)
    t = rng.uniform(0.0, 1.0 / rate)
    while True:
        i = int(t * fs)
        if i + width >= n:
            break
        force[i:i + width] += rng.uniform(150.0, 250.0) * pulse
        t += rng.uniform(0.6, 1.4) / rate
    vector = np.zeros(struct.mass.size)
    vector[LOCATIONS[location][direction]] = -1.0   # struck from above or from the side
    return {"force": force, "direction": vector}


def check_impact(location: str, direction: str) -> None:
    """A ValueError naming an unknown impact location or direction."""
    if location not in LOCATIONS:
        raise ValueError(f"unknown impact location {location!r}; known: {', '.join(LOCATIONS)}")
    if direction not in DIRECTIONS:
        raise ValueError(f"unknown impact direction {direction!r}; known: {', '.join(DIRECTIONS)}")
