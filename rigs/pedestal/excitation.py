"""Test inputs that are not part of normal operation: the impact hammer."""
from __future__ import annotations

import numpy as np

from .structure import I_YA, I_YB, LinearStructure

LOCATIONS = {"pinion_pedestal": I_YA, "gear_pedestal": I_YB}


def hammer_input(n: int, fs: float, struct: LinearStructure, location: str,
                 rate: float, seed: int) -> dict:
    """Hammer blows at random instants (mean ``rate`` per second), half-sine pulses of 0.2 ms
    and 150-250 N peak (a medium steel tip), on a pedestal in y."""
    if location not in LOCATIONS:
        raise ValueError(f"unknown impact location {location!r}; known: {', '.join(LOCATIONS)}")
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
    direction = np.zeros(struct.mass.size)
    direction[LOCATIONS[location]] = -1.0   # struck from above
    return {"force": force, "direction": direction}
