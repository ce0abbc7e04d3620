"""What the RUL modules share: the error type, the damage kinds and how damage values print."""
from __future__ import annotations

from twin.errors import TwinError


RUL_FORMAT = "gear-twin-rul"
DAMAGE_KINDS = {"pitting": "pitting_density", "wear": "wear_depth"}
_PROB_TOL = 5e-3


class RULError(TwinError):
    """An RUL input is unusable: observations, stage boundaries, threshold or trajectory.

    Attributes
    ----------
    source : str or None
        The file (or object) the problem was found in.
    record : str or None
        The record it concerns, if any.
    """

    def __init__(self, message: str, *, source: str | None = None, record: str | None = None):
        self.source = None if source is None else str(source)
        self.record = record
        where = ""
        if self.source is not None:
            where += f"{self.source}: "
        if record is not None:
            where += f"record '{record}': "
        super().__init__(where + message)


def _unit(kind: str) -> tuple[float, str]:
    return (1e6, "um") if kind == "wear_depth" else (100.0, "%")


def format_damage(value: float, kind: str) -> str:
    scale, unit = _unit(kind)
    return f"{scale * value:.3g} {unit}"
