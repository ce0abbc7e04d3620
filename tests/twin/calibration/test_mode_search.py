"""The modes fit as a search (``calibration.fit: search``): CMA-ES, the modes paired afresh."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration.mode_search import FAILED_COST, _evaluate, check_fit, search_modes
from twin.calibration.model_modes import model_modes

KW = dict(speed_hz=20.0, load_nm=20.0)


def test_the_search_finds_a_set_whose_modes_the_record_shows(gearbox_fmu):
    truth = {"kt12": 2400.0, "kx9": 5.2e7}       # nominal 1500 N.m/rad and 3e7 N/m
    mm = model_modes(gearbox_fmu, truth, **KW)
    measured = mm.frequency[mm.visible][:6]
    names = ("kt12", "kx9")
    lower, upper, nominal = np.array([500.0, 7.5e6]), np.array([4500.0, 1.2e8]), np.array([1500.0, 3e7])
    rel = np.full(measured.size, 0.003)       # well-measured modes: the data outweigh the prior
    start = model_modes(gearbox_fmu, {}, **KW)
    x, cost = search_modes(gearbox_fmu, names, lower, upper, nominal, measured, rel, fixed={}, budget=96, seed=0,
                           **KW)
    assert np.all(x >= lower) and np.all(x <= upper)
    found = model_modes(gearbox_fmu, dict(zip(names, x)), **KW)
    near = [np.min(np.abs(np.log(found.frequency[found.visible] / f))) for f in measured]
    before = [np.min(np.abs(np.log(start.frequency[start.visible] / f))) for f in measured]
    assert max(near) < 0.005 < max(before)
    # the cost holds the prior of the two moved parameters and almost nothing of the modes
    assert cost < 3.0
    assert x == pytest.approx([2400.0, 5.2e7], rel=0.1)


class _Crashing:
    """An executor whose first task comes back as its exception, as a crashed worker's does."""

    def map(self, fn, tasks):
        return [RuntimeError("worker died")] + [3.5] * (len(tasks) - 1)


class _Bar:
    n = 0

    def update(self, k):
        self.n += k


def test_a_failed_linearisation_on_a_worker_scores_as_a_very_bad_set():
    bar = _Bar()
    assert _evaluate([None, None], _Crashing(), bar) == [FAILED_COST, 3.5] and bar.n == 2


def test_an_unknown_fit_is_refused_by_name():
    assert check_fit("search") == "search"
    with pytest.raises(ValueError, match="'serch'"):
        check_fit("serch")
