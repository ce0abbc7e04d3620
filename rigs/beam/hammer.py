"""The impact hammer of an operational hammer test: blows at random instants, each a
haversine force pulse, on a bearing housing or a free shaft end, struck from above or from
the side.

Vertical is z in this rig (the (y, z) pairs of the structure: y joins the shaft centres,
z is up; the shaft weights act in -z). A vertical blow pushes its point down: the generalised
force is -F(t) times the point's vertical DOF vector; a horizontal blow pushes it along -y
(struck from the +y side, across the shafts' plane): -F(t) times its y DOF vector. Locations
(vertical DOFs shown; the horizontal ones are the y entries of the same pairs):

| location | point | DOF vector (structure.LinearModel) |
|---|---|---|
| `pinion_housing` | housing of bearing A (pinion shaft, front wall, coupling side of the pinion) | `bearing_housing[0, 1]` (casing modal coordinates) |
| `gear_housing` | housing of bearing C (gear shaft, front wall, same axial station as A) | `bearing_housing[2, 1]` |
| `pinion_shaft_end` | free (encoder) end node of the pinion shaft, last node | DOF `encoder - 4 + 1` (= 41 with 9 nodes) |
| `gear_shaft_end` | free (encoder) end node of the gear shaft, its first node | DOF `gear_encoder - 4 + 1` (= 46 with 9 nodes) |

The hammer's own load cell (gain error, noise, range, 16 bits) is in `acquire.load_cell`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LOCATIONS = ("pinion_housing", "gear_housing", "pinion_shaft_end", "gear_shaft_end")
#: Directions of a blow, by the index of its axis in the (y, z) pairs: from above (-z) or from
#: the side (-y).
DIRECTIONS = {"vertical": 1, "horizontal": 0}
#: How the truth file names each direction: (the struck DOF's axis, the blow's sense).
_DIRECTION_NAMES = {"vertical": ("vertical z", "-z (struck from above)"),
                    "horizontal": ("horizontal y", "-y (struck from the side)")}
_HOUSING = {"pinion_housing": 0, "gear_housing": 2}


class HammerError(ValueError):
    """A hammer test the rig cannot do."""


def check_location(location) -> str:
    if location not in LOCATIONS:
        raise HammerError(f"unknown impact location {location!r}; known: {', '.join(LOCATIONS)}")
    return location


def check_direction(direction) -> str:
    if direction not in DIRECTIONS:
        raise HammerError(f"unknown impact direction {direction!r}; known: {', '.join(DIRECTIONS)}")
    return direction


def check_rate(rate) -> float:
    try:
        r = float(rate)
    except (TypeError, ValueError):
        raise HammerError(f"impacts_per_second {rate!r} is not a number") from None
    if not (np.isfinite(r) and 0.0 < r <= 10.0):
        raise HammerError(f"impacts_per_second {rate!r} outside (0, 10]")
    return r


@dataclass(frozen=True)
class Blows:
    """The blows of one record: contact start [s, record time], contact time [s], peak [N]."""
    location: str
    starts: np.ndarray
    widths: np.ndarray
    peaks: np.ndarray
    direction: str = "vertical"

    def force(self, t: np.ndarray) -> np.ndarray:
        """Hammer force [N, > 0 pressing] at times t (ascending): F sin^2(pi (t - t0) / T)."""
        out = np.zeros(t.size)
        for t0, w, f in zip(self.starts, self.widths, self.peaks):
            i0, i1 = np.searchsorted(t, (t0, t0 + w))
            out[i0:i1] += f * np.sin(np.pi * (t[i0:i1] - t0) / w) ** 2
        return out

    def vector(self, model) -> np.ndarray:
        """Generalised force per newton of hammer force (along -z or -y at the struck point)."""
        n = model.M.shape[0]
        axis = DIRECTIONS[self.direction]
        if self.location in _HOUSING:
            v = model.bearing_housing[_HOUSING[self.location], axis].copy()
        else:
            v = np.zeros(n)
            node = (model.encoder if self.location == "pinion_shaft_end" else model.gear_encoder) - 4
            v[node + axis] = 1.0
        return -v

    def truth(self, model) -> dict:
        axis = DIRECTIONS[self.direction]
        name, side = _DIRECTION_NAMES[self.direction]
        if self.location in _HOUSING:
            dof = f"bearing_housing[{_HOUSING[self.location]}, {axis}] (housing {name}, casing modes)"
        else:
            node = (model.encoder if self.location == "pinion_shaft_end" else model.gear_encoder) - 4
            dof = f"shaft DOF {node + axis} (free-end node, {name})"
        return {"location": self.location, "dof": dof, "direction": side,
                "hit_times": [float(x) for x in self.starts],
                "hit_times_are": "start of contact [s from the first sample]",
                "contact_times": [float(x) for x in self.widths],
                "peak_forces": [float(x) for x in self.peaks], "hits": int(self.starts.size)}


def draw_blows(location: str, rate: float, duration: float, hammer, rng,
               direction: str = "vertical") -> Blows:
    """Blows at a mean rate [1/s] within [0, duration): gamma-distributed intervals (a hand's
    rhythm) no shorter than hammer.min_interval, contact time and peak uniform in their ranges;
    the first blow within the first mean interval, none cut by the record's end."""
    location = check_location(location)
    direction = check_direction(direction)
    mean = 1.0 / check_rate(rate)
    k = hammer.interval_shape
    starts, widths, peaks = [], [], []
    t = float(rng.uniform(0.05, 1.0)) * mean
    while True:
        w = float(rng.uniform(*hammer.contact_time))
        f = float(rng.uniform(*hammer.peak))
        if t + w >= duration:
            break
        starts.append(t)
        widths.append(w)
        peaks.append(f)
        t += max(float(rng.gamma(k, mean / k)), hammer.min_interval)
    return Blows(location, np.array(starts), np.array(widths), np.array(peaks), direction)
