"""The typed error and the warning of the transfer-learning assessor."""
from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager

from twin.errors import TwinError


class AssessorError(TwinError):
    """The assessor cannot do what was asked: bad input shape or type, labels that do not match
    the stages, an unfitted model, an unreadable or inconsistent saved model.  The message names
    the offending value."""


class ClassPriorWarning(UserWarning):
    """The class-prior match moved an unusual share of the rig's adaptation windows to another
    stage: either the rig shifts the stage boundaries far, or its data do not cover the stages in
    the twin's proportions (a run-to-failure history), which the match assumes.  The message gives
    the share and the switch (``class_prior=None``, ``twin rematch ... --class-prior none``)."""


@contextmanager
def class_prior_notes() -> Iterator[list]:
    """Collect the :class:`ClassPriorWarning` messages (str) raised inside, instead of showing them,
    for a caller that prints them in its own layout (the CLI, the demo).  Other warnings are shown
    as usual."""
    notes: list = []
    with warnings.catch_warnings():
        warnings.simplefilter("always", ClassPriorWarning)
        shown = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, ClassPriorWarning):
                notes.append(str(message))
            else:
                shown(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        yield notes
