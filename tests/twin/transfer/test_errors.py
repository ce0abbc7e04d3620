"""class_prior_notes collects the class-prior warning for the caller's own layout, nothing else."""
from __future__ import annotations

import warnings

import pytest

from twin.transfer.errors import ClassPriorWarning, class_prior_notes


def test_class_prior_notes_collect_only_the_class_prior_warning():
    with pytest.warns(RuntimeWarning, match="other"):
        with class_prior_notes() as notes:
            warnings.warn("moved 12 %", ClassPriorWarning)
            warnings.warn("moved 12 %", ClassPriorWarning)      # "always": a repeat is not lost
            warnings.warn("other", RuntimeWarning)
    assert notes == ["moved 12 %", "moved 12 %"]
    with pytest.warns(ClassPriorWarning):                       # the filter is restored on exit
        warnings.warn("after", ClassPriorWarning)
