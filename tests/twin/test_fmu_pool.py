"""twin.fmu_pool: an FMU opened once per process and reused, reset between uses."""
from __future__ import annotations

import numpy as np
import pytest

from twin.errors import SimulationError
from twin.fmu import FMU
from twin.fmu_pool import close_idle, reused


def _run(fmu, k1=None):
    fmu.setup(0.0, parameters={} if k1 is None else {"k1": k1})
    return fmu.run(0.2, 1e-3, outputs=["a2"])


def test_a_reused_fmu_is_reset_and_runs_as_a_fresh_one(two_mass_fmu):
    with FMU(two_mass_fmu) as fresh:
        expected = _run(fresh)["a2"]
    with reused(two_mass_fmu) as first:
        stiff = _run(first, k1=400.0)["a2"]
        assert first.get("k1") == 400.0
    with reused(two_mass_fmu) as second:
        assert second is first                         # not unpacked and loaded again
        assert second.get("k1") == 100.0 and second.time == 0.0 and second.initial_parameters == {}
        again = _run(second)
    np.testing.assert_array_equal(again["a2"], expected)
    assert again.parameters == fresh.initial_parameters
    assert not np.array_equal(stiff, expected)
    close_idle()


def test_one_caller_at_a_time_and_a_failed_use_is_not_kept(two_mass_fmu):
    with reused(two_mass_fmu) as a, reused(two_mass_fmu) as b:
        assert a is not b                              # both in use: two instances
    with pytest.raises(SimulationError, match="boom"):
        with reused(two_mass_fmu) as c:
            c.instantiate()
            raise SimulationError("boom")
    assert c._slave is None                            # closed, not kept
    with reused(two_mass_fmu) as d:
        assert d is not c and d in (a, b)
    close_idle()
    assert a._slave is None and b._slave is None
