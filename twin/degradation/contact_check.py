"""Contact loss of a co-simulated pair checked against the LTCA at the same instantaneous load.

A pair of worn flanks running at speed carries a mesh force that swings about its mean: where
the static transmission error is tens of um and the elastic approach about 1 um (an 18/35 pair
at 10 N.m), the dynamic force drops to a fraction of the mean, and pairs the static load would
share go slack.  A static LTCA at the mean force therefore cannot say whether the FMU's contact
loss is right.  The like-with-like check takes every sample of the co-simulation, the FMU's
elastic mesh force F(t) (the sum of its pair forces) and the roll positions of its pairs, and
solves the LTCA of the same worn flanks at that force and those positions
(:class:`twin.degradation.ltca.LoadedContact`, an influence-coefficient model that shares no
equations with the FMU's pair law ``k (delta - e)``).  It then compares, pair by pair, which
pairs carry load.  The FMU's load sharing at a given force and position depends only on its
mesh model (the profile deviations of both worn flanks and the pairs' compliances), so where
the two disagree the mesh model is wrong; where F(t) is zero the gears have separated, a
dynamic event that the check reports on its own (``no_pair``) and a quasi-static analysis
cannot judge.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.degradation.geometry import GearPair
from twin.degradation.ltca import FlankDamage, contact_for
from twin.errors import ParameterError

__all__ = ["ContactCheck", "contact_check"]

#: Pairs this close to an end of the path are left out: the FMU gates them in and out there
#: (``contact_smoothing`` = 0.01 of the path).
_END = 0.02


@dataclass(frozen=True)
class ContactCheck:
    """Agreement of the co-simulated contact with the LTCA at the same load and position.

    Shares are of pair samples: a pair in the path of contact (roll in [0.02, 0.98]) at a sample
    where the elastic mesh force is above zero.  A pair is unloaded when it carries less than
    ``threshold`` times the instantaneous mesh force.

    Attributes
    ----------
    samples : number of samples checked.
    pair_samples : number of pair samples.
    no_pair : share of the samples at which no pair carries load (the gears have separated).
    fmu_unloaded, ltca_unloaded : share of pair samples unloaded in the FMU / in the LTCA.
    unexplained : share of pair samples the FMU leaves unloaded and the LTCA loads.
    missed : share of pair samples the LTCA leaves unloaded and the FMU loads.
    """

    samples: int
    pair_samples: int
    no_pair: float
    fmu_unloaded: float
    ltca_unloaded: float
    unexplained: float
    missed: float

    @property
    def agreement(self) -> float:
        """Share of pair samples on which the FMU and the LTCA agree (loaded or not)."""
        return 1.0 - self.unexplained - self.missed


def contact_check(geometry: GearPair, damage: FlankDamage, roll, pair_force, *, n_samples: int = 400,
                  threshold: float = 1e-3) -> ContactCheck:
    """Compare the FMU's pair loads with the LTCA at each sample's elastic mesh force.

    Parameters
    ----------
    geometry : GearPair of the FMU.
    damage : FlankDamage of the same worn (or pitted) flanks the FMU's parameters came from.
    roll : (m, p) roll positions of the FMU's pairs (``roll[1..3]``), 0 .. 1 in the path.
    pair_force : (m, p) elastic force of each pair [N] (``pair_force[1..3]``).
    n_samples : samples checked, equally spaced over the m given (all when m is smaller).
    threshold : a pair carrying less than this share of the instantaneous force is unloaded.
    """
    roll = np.asarray(roll, dtype=float)
    pair_force = np.asarray(pair_force, dtype=float)
    if roll.ndim != 2 or roll.shape != pair_force.shape or roll.shape[0] == 0:
        raise ParameterError(f"roll and pair_force must be (m, p) arrays of one shape, got {roll.shape} "
                             f"and {pair_force.shape}")
    if not (np.all(np.isfinite(roll)) and np.all(np.isfinite(pair_force))):
        raise ParameterError("roll and pair_force must be finite")
    if not (isinstance(n_samples, (int, np.integer)) and n_samples >= 1):
        raise ParameterError(f"n_samples must be an integer >= 1, got {n_samples!r}")
    if not (0.0 < threshold < 1.0):
        raise ParameterError(f"threshold must be in (0, 1), got {threshold!r}")
    lc = contact_for(geometry)
    rows = np.unique(np.linspace(0, roll.shape[0] - 1, min(n_samples, roll.shape[0])).astype(int))
    # the largest elastic force of the record: below 1e-6 of it the gears are apart
    scale = max(float(pair_force.sum(axis=1).max()), 1e-12)
    n_pair = no_pair = fmu_un = ltca_un = unexplained = missed = 0
    for i in rows:
        r, f = roll[i], pair_force[i]
        total = float(f.sum())
        if total <= 1e-6 * scale:
            no_pair += 1
            continue
        in_path = [float(v) for v in r if 0.0 <= v <= 1.0]
        pos = lc.solve(in_path, total, damage)
        ltca = np.zeros(r.size)
        for p in pos.pairs:
            ltca[int(np.argmin(np.abs(r - p.xi)))] = p.total
        for j in range(r.size):
            if not (_END <= r[j] <= 1.0 - _END):
                continue
            a = f[j] < threshold * total
            b = ltca[j] < threshold * total
            n_pair += 1
            fmu_un += a
            ltca_un += b
            unexplained += a and not b
            missed += b and not a
    n = max(n_pair, 1)
    return ContactCheck(int(rows.size), int(n_pair), no_pair / rows.size, float(fmu_un / n), float(ltca_un / n),
                        float(unexplained / n), float(missed / n))
