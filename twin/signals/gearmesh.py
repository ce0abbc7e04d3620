"""Gear-mesh harmonics and their sidebands, read from a spectrum.

A gear with ``z`` teeth on a shaft turning at ``shaft_hz`` meshes at ``GMF = z * shaft_hz``.
Tooth-to-tooth variation that repeats once per revolution (eccentricity, a pitted or worn tooth)
modulates the mesh vibration in amplitude and phase, which puts sidebands at
``k*GMF +- m*shaft_hz`` around each mesh harmonic ``k``; the mating gear's shaft adds its own
family at ``+- m*other_shaft_hz``. Wear raises the higher mesh harmonics and the sidebands, which
is why the paper's rig (19/52 teeth, input at 20 Hz) tracks them.

Lines are read as the largest spectrum value within ``tol_hz`` of where they are expected, so the
reading is exact for on-bin lines and suffers the window's scalloping loss otherwise (use a
flat-top amplitude spectrum when absolute amplitudes matter).
"""
from __future__ import annotations

import numpy as np

from twin.signals._checks import SignalError, as_signal, positive, positive_int, same_length
from twin.signals.spectral import spectrum_db


def _read_line(f: np.ndarray, spectrum: np.ndarray, expected: float, tol: float) -> tuple[float, float]:
    """(frequency [Hz], value) of the largest bin within ``tol`` of ``expected``; NaN if off-range."""
    df = f[1] - f[0]
    if expected < f[0] - tol or expected > f[-1] + tol:
        return float("nan"), float("nan")
    window = np.flatnonzero(np.abs(f - expected) <= tol)
    if window.size == 0:
        # Tolerance narrower than a bin: the nearest bin is the only candidate.
        window = np.array([int(np.clip(np.rint((expected - f[0]) / df), 0, f.size - 1))])
    best = window[np.argmax(spectrum[window])]
    return float(f[best]), float(spectrum[best])


def _check_spectrum(f, spectrum):
    f = as_signal(f, "f")
    spectrum = as_signal(spectrum, "spectrum")
    same_length(f, spectrum, "f", "spectrum")
    if np.any(np.diff(f) <= 0):
        raise SignalError("f must be strictly increasing")
    if np.any(spectrum < 0):
        raise SignalError("spectrum must be non-negative (pass magnitudes)")
    return f, spectrum


def mesh_harmonics(f, spectrum, *, shaft_hz: float, z: int, n_harmonics: int = 5, n_sidebands: int = 3,
                   other_shaft_hz: float | None = None, tol_hz: float | None = None, ref: float = 1.0,
                   quantity: str = "amplitude") -> list[dict]:
    """Gear-mesh harmonics and their shaft sidebands, with levels.

    Parameters
    ----------
    f : (k,) array
        Frequencies [Hz] of the spectrum, evenly spaced and increasing.
    spectrum : (k,) array
        Amplitude spectrum [unit] (e.g. from :func:`amplitude_spectrum`), or a power spectrum /
        PSD if ``quantity="power"``.
    shaft_hz : float
        Speed [Hz] of the shaft carrying the gear with ``z`` teeth.
    z : int
        Tooth count of that gear; GMF = z * shaft_hz.
    n_harmonics : int
        Mesh harmonics k = 1 ... n_harmonics.
    n_sidebands : int
        Sideband orders m = 1 ... n_sidebands on each side of each harmonic.
    other_shaft_hz : float, optional
        Speed [Hz] of the mating gear's shaft; adds its sideband family.
    tol_hz : float, optional
        Search half-width [Hz] around each expected line; default a quarter of the smallest
        sideband spacing, so neighbouring sidebands can never be mistaken for each other.
    ref : float
        0 dB reference for the levels, in the unit of ``spectrum``.
    quantity : {"amplitude", "power"}
        How ``spectrum`` is converted to dB (20 or 10 log10).

    Returns
    -------
    list of dict, one per harmonic k (in order), with keys
        ``harmonic`` (k), ``expected_frequency`` [Hz] (k*GMF), ``frequency`` [Hz] (bin read),
        ``amplitude`` [unit of spectrum], ``level_db`` [dB re ref], and ``sidebands``: a list of
        dicts with ``family`` ("shaft" or "other_shaft"), ``order`` (signed m), the same frequency,
        amplitude and level keys, and ``relative_db`` (level relative to the harmonic's) [dB].
        Lines outside the spectrum's frequency range have NaN frequency, amplitude and levels.
    """
    f, spectrum = _check_spectrum(f, spectrum)
    shaft_hz = positive(shaft_hz, "shaft_hz")
    z = positive_int(z, "z")
    n_harmonics = positive_int(n_harmonics, "n_harmonics")
    if isinstance(n_sidebands, bool) or int(n_sidebands) != n_sidebands or n_sidebands < 0:
        raise SignalError(f"n_sidebands must be a non-negative integer, got {n_sidebands!r}")
    families = [("shaft", shaft_hz)]
    if other_shaft_hz is not None:
        families.append(("other_shaft", positive(other_shaft_hz, "other_shaft_hz")))
    if tol_hz is None:
        tol = 0.25 * min(hz for _, hz in families)
    else:
        tol = positive(tol_hz, "tol_hz")

    def level(value: float) -> float:
        return float(spectrum_db(value, ref=ref, quantity=quantity)) if np.isfinite(value) else float("nan")

    gmf = z * shaft_hz
    out = []
    for k in range(1, n_harmonics + 1):
        centre = k * gmf
        freq, amp = _read_line(f, spectrum, centre, tol)
        centre_db = level(amp)
        sidebands = []
        for family, hz in families:
            for m in [-m for m in range(int(n_sidebands), 0, -1)] + list(range(1, int(n_sidebands) + 1)):
                expected = centre + m * hz
                sb_freq, sb_amp = _read_line(f, spectrum, expected, tol)
                sb_db = level(sb_amp)
                sidebands.append({"family": family, "order": m, "expected_frequency": expected,
                                  "frequency": sb_freq, "amplitude": sb_amp, "level_db": sb_db,
                                  "relative_db": sb_db - centre_db})
        out.append({"harmonic": k, "expected_frequency": centre, "frequency": freq, "amplitude": amp,
                    "level_db": centre_db, "sidebands": sidebands})
    return out


def sideband_energy_ratio(f, spectrum, *, shaft_hz: float, z: int, harmonic: int = 1, n_sidebands: int = 6,
                          other_shaft_hz: float | None = None, tol_hz: float | None = None,
                          quantity: str = "amplitude") -> float:
    """Sideband energy ratio (SER) of one mesh harmonic.

    SER = (sum of the sideband amplitudes at ``k*GMF +- m*shaft_hz``, m = 1 ... n_sidebands)
    / (amplitude at ``k*GMF``), the usual definition with 6 sideband pairs. It is ~0 for a
    healthy mesh and grows as tooth damage modulates the mesh. With ``other_shaft_hz`` the mating
    shaft's sidebands are summed too. A power spectrum (``quantity="power"``) is converted to
    amplitudes (square root) first, so the ratio means the same thing for either input.

    Parameters
    ----------
    f, spectrum, shaft_hz, z, other_shaft_hz, tol_hz, quantity
        As for :func:`mesh_harmonics`.
    harmonic : int
        Mesh harmonic k whose SER is wanted.
    n_sidebands : int
        Sideband pairs summed.

    Returns
    -------
    ser : float
        Dimensionless ratio; NaN if the harmonic is outside the spectrum.
    """
    harmonic = positive_int(harmonic, "harmonic")
    lines = mesh_harmonics(f, spectrum, shaft_hz=shaft_hz, z=z, n_harmonics=harmonic, n_sidebands=n_sidebands,
                           other_shaft_hz=other_shaft_hz, tol_hz=tol_hz, quantity=quantity)[-1]
    to_amplitude = np.sqrt if quantity == "power" else (lambda v: v)
    centre = to_amplitude(lines["amplitude"])
    sidebands = np.array([to_amplitude(sb["amplitude"]) for sb in lines["sidebands"]])
    if not np.isfinite(centre):
        return float("nan")
    if centre == 0:
        raise SignalError(f"mesh harmonic {harmonic} has zero amplitude; the SER is undefined")
    return float(np.nansum(sidebands) / centre)
