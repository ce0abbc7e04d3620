"""Argument checks shared by the signal-processing modules, and their error type.

Kept in one place so every function rejects bad input with the same wording: the message names
the argument and the offending value, which is what a caller needs to fix a call.
"""
from __future__ import annotations

import numpy as np

from twin.errors import TwinError


class SignalError(TwinError, ValueError):
    """A signal or an analysis parameter is unusable (wrong shape, not finite, out of range).

    Derives from ``ValueError`` too, so code that guards numeric input with ``except ValueError``
    keeps working.
    """


def as_signal(x, name: str, *, min_length: int = 2, allow_nan: bool = False) -> np.ndarray:
    """``x`` as a 1-D float array of at least ``min_length`` samples, finite unless ``allow_nan``."""
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1:
        raise SignalError(f"{name} must be a 1-D array, got shape {arr.shape}")
    if arr.size < min_length:
        raise SignalError(f"{name} needs at least {min_length} samples, got {arr.size}")
    bad = ~np.isfinite(arr) if not allow_nan else np.isinf(arr)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise SignalError(f"{name} must be finite; sample {i} is {arr[i]}")
    return arr


def positive(value, name: str) -> float:
    """``value`` as a float, which must be finite and > 0."""
    v = float(value)
    if not np.isfinite(v) or v <= 0.0:
        raise SignalError(f"{name} must be a finite positive number, got {value!r}")
    return v


def positive_int(value, name: str) -> int:
    """``value`` as an int >= 1 (booleans and non-integral floats are refused)."""
    if isinstance(value, bool) or int(value) != value or int(value) < 1:
        raise SignalError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def frequency_band(fmin, fmax) -> tuple[float, float]:
    """A band ``0 <= fmin < fmax`` [Hz]."""
    lo, hi = float(fmin), float(fmax)
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo < 0.0 or hi <= lo:
        raise SignalError(f"need 0 <= fmin < fmax, got fmin={fmin!r}, fmax={fmax!r}")
    return lo, hi


def same_length(a: np.ndarray, b: np.ndarray, name_a: str, name_b: str) -> None:
    if a.shape != b.shape:
        raise SignalError(f"{name_a} and {name_b} must have the same shape, got {a.shape} and {b.shape}")
