"""Vibration signal processing for the gearbox twin: spectra, order analysis, gear-mesh lines,
natural frequencies. Pure numpy/scipy; see README.md in this directory.

Typical use on a measured or simulated record (x [m/s**2] at fs [Hz], tacho pulses)::

    angle = shaft_angle_from_tacho(tacho, fs, pulses_per_rev=1)
    theta, tsa, n_revs = synchronous_average(x, fs, angle)
    orders, amp = order_spectrum(x, fs, angle, samples_per_rev=1024, max_order=200)
    lines = mesh_harmonics(orders, amp, shaft_hz=1.0, z=19)        # in orders: shaft = order 1
    freqs, prom = runup_natural_frequencies(x_ramp, fs, speed_hz=speed, fmin=10, fmax=2000, n_peaks=21)
    kept, removed = remove_foundation_modes(freqs, foundation_freqs)
"""
from twin.signals._checks import SignalError
from twin.signals.gearmesh import mesh_harmonics, sideband_energy_ratio
from twin.signals.modes import frf_h1_h2, modal_peaks, remove_foundation_modes, runup_natural_frequencies
from twin.signals.spectral import amplitude_spectrum, padded_spectrum, spectrum_db, welch_psd
from twin.signals.tsa import (angular_resample, order_spectrum, shaft_angle_from_encoder, shaft_angle_from_speed,
                              shaft_angle_from_tacho, synchronous_average)

__all__ = [
    "SignalError", "amplitude_spectrum", "angular_resample", "frf_h1_h2", "mesh_harmonics", "modal_peaks",
    "order_spectrum", "padded_spectrum", "remove_foundation_modes", "runup_natural_frequencies", "shaft_angle_from_encoder",
    "shaft_angle_from_speed", "shaft_angle_from_tacho", "sideband_energy_ratio", "spectrum_db",
    "synchronous_average", "welch_psd",
]
