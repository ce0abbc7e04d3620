"""The typed error and the warning of the transfer-learning assessor."""
from __future__ import annotations

from twin.errors import TwinError


class AssessorError(TwinError):
    """The assessor cannot do what was asked: bad input shape or type, labels that do not match
    the stages, an unfitted model, an unreadable or inconsistent saved model.  The message names
    the offending value."""


class ClassPriorWarning(UserWarning):
    """The class-prior match moved an unusual share of the rig's adaptation windows to another
    stage: either the rig shifts the stage boundaries far, or its data do not cover the stages in
    the twin's proportions (a run-to-failure history), which the match assumes.  The message gives
    the share and the switch (``class_prior=None``, ``--no-class-prior``)."""
