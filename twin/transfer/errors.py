"""The typed error of the transfer-learning assessor."""
from __future__ import annotations

from twin.errors import TwinError


class AssessorError(TwinError):
    """The assessor cannot do what was asked: bad input shape or type, labels that do not match
    the stages, an unfitted model, an unreadable or inconsistent saved model.  The message names
    the offending value."""
