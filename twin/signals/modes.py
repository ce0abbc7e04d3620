"""Natural frequencies of the rig: run-up PSD peaks, hammer-test FRF, modal peaks, foundation removal.

Follows Feng et al., section 3.2: the rig's modes are picked as peaks of the PSD of the vibration
measured while the motor ramps up (Fig. 9, Table 1); the foundation's modes come from a hammer
test FRF estimated with Eq. (16) (H2, chosen because the moving hammer's force signal is the
noisier one) and are removed from the run-up list, leaving modes comparable with the dynamic
model, which has no foundation (Table 2).
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy import signal as sps

from twin.signals._checks import SignalError, as_signal, frequency_band, positive, positive_int, same_length
from twin.signals.spectral import spectrum_db, welch_psd


def _parabolic_peak(f: np.ndarray, y: np.ndarray, i: int) -> tuple[float, float]:
    """Vertex (frequency [Hz], value) of the parabola through bins i-1, i, i+1 of y(f)."""
    if i <= 0 or i >= y.size - 1:
        return float(f[i]), float(y[i])
    a, b, c = y[i - 1], y[i], y[i + 1]
    curvature = a - 2.0 * b + c
    if curvature >= 0:
        return float(f[i]), float(b)
    delta = 0.5 * (a - c) / curvature
    return float(f[i] + delta * (f[i + 1] - f[i])), float(b - 0.25 * (a - c) * delta)


def _order_list(exclude_orders) -> np.ndarray | None:
    if exclude_orders is None:
        return None
    orders = np.atleast_1d(np.asarray(exclude_orders, dtype=float))
    if orders.ndim != 1 or orders.size == 0 or not np.all(np.isfinite(orders)) or np.any(orders <= 0):
        raise SignalError(f"exclude_orders must be a non-empty list of positive orders, got {exclude_orders!r}")
    return orders


def _stationary_spectrum(x: np.ndarray, fs: float, speed: np.ndarray, nperseg: int, orders: np.ndarray | None,
                         fmin: float, fmax: float) -> tuple[np.ndarray, np.ndarray]:
    """Median-over-time of a per-slice-normalised log spectrogram, order tracks masked.

    Returns (f (nf,) [Hz], level (nf,) [dB re the slices' median level in the band]).
    """
    step = nperseg // 2
    f, _, psd = sps.spectrogram(x, fs=fs, window="hann", nperseg=nperseg, noverlap=nperseg - step,
                                detrend="constant", scaling="density", mode="psd")
    n_slices = psd.shape[1]
    if n_slices < 5:
        raise SignalError(f"the run-up gives only {n_slices} spectrogram slices at this resolution; "
                          "a median over time needs at least 5 (longer record or coarser resolution)")
    level = 10.0 * np.log10(np.maximum(psd, np.finfo(float).tiny))
    df = f[1] - f[0]
    if orders is not None:
        # Speed seen by each slice: its mean places the order line, its spread widens the track.
        per_slice = np.lib.stride_tricks.sliding_window_view(speed, nperseg)[::step][:n_slices]
        mean_speed = per_slice.mean(axis=1)
        spread = per_slice.max(axis=1) - per_slice.min(axis=1)
        masked = np.zeros(level.shape, dtype=bool)
        for order in orders:
            # Half-width: the order's sweep within the slice plus the Hann main lobe (2 bins).
            half_width = 0.5 * order * spread + 2.0 * df
            masked |= np.abs(f[:, None] - order * mean_speed[None, :]) <= half_width[None, :]
        level[masked] = np.nan
    band = (f >= fmin) & (f <= fmax)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slices/bins are handled below
        # Normalising each slice removes the overall level change of the run-up (excitation grows
        # with speed). Without it, bins masked in different slices would take their median over
        # differently loud slices and show steps that peak picking could mistake for modes.
        level = level - np.nanmedian(level[band], axis=0)[None, :]
        stationary = np.nanmedian(level, axis=1)
    missing = ~np.isfinite(stationary)
    if missing.all():
        raise SignalError("every spectrogram bin is masked by exclude_orders; nothing stationary is left")
    if missing.any():
        stationary[missing] = np.interp(f[missing], f[~missing], stationary[~missing])
    return f, stationary


def runup_natural_frequencies(x, fs: float, *, speed_hz=None, fmin: float, fmax: float, n_peaks: int,
                              resolution: float = 1.0, prominence_db: float = 6.0, exclude_orders=None,
                              shaft_hz: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies as the most prominent PSD peaks of a speed run-up (paper, Fig. 9).

    During a run-up the shaft orders sweep across the band and excite each resonance as they
    pass, while broadband excitation (mesh noise, friction, impacts) keeps the resonances lit
    throughout. Two ways of reading the spectrum:

    * ``speed_hz=None`` -- the paper's method: Welch PSD of the whole record at ``resolution``,
      peaks picked in dB. Order lines from any steady-speed part of the record show up as peaks
      too; with a constant ``shaft_hz`` and ``exclude_orders`` the peaks within two bins of those
      orders are dropped.
    * ``speed_hz`` given -- order tracks are suppressed before picking: a Hann spectrogram
      (segments of ``fs/resolution`` samples, 50 % overlap) is taken in dB, the bins of
      ``exclude_orders`` along the speed profile are masked in every slice, each slice is
      normalised by its median level in [fmin, fmax], and each frequency bin takes its median
      over time. Energy that sweeps with speed occupies a given bin during only a few slices and
      drops out of the median, even for orders not listed; stationary resonances survive. This
      needs the resonances to be excited in more than half of the slices (broadband content).

    Parameters
    ----------
    x : (n,) array
        Vibration [unit, e.g. m/s**2] over the run-up.
    fs : float
        Sampling rate [Hz].
    speed_hz : (n,) array, optional
        Shaft speed [Hz] at each sample (from a tacho or encoder).
    fmin, fmax : float
        Band searched for peaks [Hz], ``fmax <= fs/2``.
    n_peaks : int
        Maximum number of frequencies returned (the most prominent ones).
    resolution : float
        Frequency resolution [Hz] of the PSD/spectrogram.
    prominence_db : float
        Minimum peak prominence [dB] (height above the higher of the two surrounding valleys).
    exclude_orders : sequence of float, optional
        Shaft orders [cycles/rev] to suppress (e.g. 1, 2, z, 2z); needs ``speed_hz`` or ``shaft_hz``.
    shaft_hz : float, optional
        Constant shaft speed [Hz] used with ``exclude_orders`` when ``speed_hz`` is None
        (ignored when ``speed_hz`` is given).

    Returns
    -------
    freqs : (k,) array
        Natural frequencies [Hz], ascending, k <= n_peaks (fewer if fewer peaks pass the
        prominence threshold); refined between bins by a parabola through the dB values.
    prominence : (k,) array
        Prominence [dB] of each peak.
    """
    x = as_signal(x, "x")
    fs = positive(fs, "fs")
    fmin, fmax = frequency_band(fmin, fmax)
    if fmax > fs / 2:
        raise SignalError(f"fmax={fmax:g} Hz is above the Nyquist frequency {fs / 2:g} Hz")
    n_peaks = positive_int(n_peaks, "n_peaks")
    resolution = positive(resolution, "resolution")
    if not np.isfinite(prominence_db) or prominence_db < 0:
        raise SignalError(f"prominence_db must be >= 0, got {prominence_db!r}")
    orders = _order_list(exclude_orders)
    nperseg = int(round(fs / resolution))

    excluded_lines = np.empty(0)
    if speed_hz is None:
        f, psd = welch_psd(x, fs, resolution=resolution)
        level = spectrum_db(psd, quantity="power")
        if orders is not None:
            if shaft_hz is None:
                raise SignalError("exclude_orders needs the speed: pass speed_hz (run-up) or shaft_hz (constant)")
            excluded_lines = orders * positive(shaft_hz, "shaft_hz")
    else:
        speed = as_signal(speed_hz, "speed_hz")
        same_length(x, speed, "x", "speed_hz")
        if np.any(speed < 0):
            raise SignalError(f"speed_hz must be >= 0, its minimum is {speed.min():g}")
        if nperseg > x.size:
            raise SignalError(f"resolution={resolution} Hz needs {nperseg}-sample segments; x has {x.size}")
        f, level = _stationary_spectrum(x, fs, speed, nperseg, orders, fmin, fmax)

    df = f[1] - f[0]
    band = np.flatnonzero((f >= fmin) & (f <= fmax))
    if band.size < 3:
        raise SignalError(f"the band [{fmin:g}, {fmax:g}] Hz holds fewer than 3 bins at {df:g} Hz resolution")
    y, fb = level[band], f[band]
    peaks, props = sps.find_peaks(y, prominence=prominence_db)
    prominences = props["prominences"]
    refined = np.array([_parabolic_peak(fb, y, int(i))[0] for i in peaks])
    if excluded_lines.size and refined.size:
        near_order = np.any(np.abs(refined[:, None] - excluded_lines[None, :]) <= 2.0 * df, axis=1)
        refined, prominences = refined[~near_order], prominences[~near_order]
    strongest = np.argsort(prominences)[::-1][:n_peaks]
    ascending = strongest[np.argsort(refined[strongest])]
    return refined[ascending], prominences[ascending]


def frf_h1_h2(force, response, fs: float, *, nperseg: int, n_averages: int | None = None,
              window: str = "boxcar") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Frequency response function from an impact (hammer) test by the H1 and H2 estimators.

    The record is cut into consecutive, non-overlapping segments of ``nperseg`` samples, one per
    impact (each segment should hold one hit near its start and the response's full decay;
    the rectangular default window then leaks nothing). With ``X``, ``Y`` the segments' DFTs of
    force and response, averaged over the segments:

    * ``Gxx = <|X|^2>``, ``Gyy = <|Y|^2>``, ``Gxy = <conj(X) Y>``, ``Gyx = conj(Gxy)``;
    * ``H1 = Gxy / Gxx`` -- unbiased by response noise, biased low by force noise;
    * ``H2 = Gyy / Gyx`` -- paper Eq. (16): unbiased by force noise, biased high by response
      noise; preferred for hammer tests, where the moving hammer's channel is the noisier;
    * ``coherence = |Gxy|^2 / (Gxx Gyy) = H1 / H2`` in [0, 1]; 1 for a single average.

    Parameters
    ----------
    force : (n,) array
        Hammer force [N].
    response : (n,) array
        Response [unit, e.g. m/s**2], sampled with the force.
    fs : float
        Sampling rate [Hz].
    nperseg : int
        Samples per impact record; the frequency resolution is ``fs / nperseg``.
    n_averages : int, optional
        Number of records averaged, taken from the start; default all whole records in the data.
    window : str
        Window applied to both channels (``"boxcar"``: none; an exponential window suits
        responses that do not decay within the record).

    Returns
    -------
    f : (nperseg // 2 + 1,) array
        Frequencies [Hz].
    H1, H2 : (nperseg // 2 + 1,) complex arrays
        FRF estimates [unit of response / N]. NaN where the denominator is zero.
    coherence : (nperseg // 2 + 1,) array
        Ordinary coherence, dimensionless in [0, 1].
    """
    x = as_signal(force, "force")
    y = as_signal(response, "response")
    same_length(x, y, "force", "response")
    fs = positive(fs, "fs")
    nperseg = positive_int(nperseg, "nperseg")
    available = x.size // nperseg
    if available < 1:
        raise SignalError(f"nperseg={nperseg} is longer than the record ({x.size} samples)")
    if n_averages is None:
        n_averages = available
    n_averages = positive_int(n_averages, "n_averages")
    if n_averages > available:
        raise SignalError(f"n_averages={n_averages} needs {n_averages * nperseg} samples; the record has "
                          f"{x.size} ({available} whole records of nperseg={nperseg})")
    w = sps.get_window(window, nperseg, fftbins=True)
    used = n_averages * nperseg
    X = np.fft.rfft(x[:used].reshape(n_averages, nperseg) * w, axis=1)
    Y = np.fft.rfft(y[:used].reshape(n_averages, nperseg) * w, axis=1)
    # Scale factors common to all spectra cancel in every ratio below, so none is applied.
    gxx = np.mean(np.abs(X) ** 2, axis=0)
    gyy = np.mean(np.abs(Y) ** 2, axis=0)
    gxy = np.mean(np.conj(X) * Y, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        h1 = np.where(gxx > 0, gxy / np.where(gxx > 0, gxx, 1.0), np.nan + 0j)
        h2 = np.where(np.abs(gxy) > 0, gyy / np.where(np.abs(gxy) > 0, np.conj(gxy), 1.0), np.nan + 0j)
        denom = gxx * gyy
        coherence = np.where(denom > 0, np.abs(gxy) ** 2 / np.where(denom > 0, denom, 1.0), np.nan)
    return np.fft.rfftfreq(nperseg, d=1.0 / fs), h1, h2, np.clip(coherence, 0.0, 1.0)


def modal_peaks(f, H, *, n: int, fmin: float, fmax: float, prominence_db: float = 3.0,
                min_phase_shift_deg: float = 90.0) -> tuple[np.ndarray, np.ndarray]:
    """Resonances of an FRF: magnitude peaks confirmed by a phase turn, with half-power damping.

    A mode shows as a magnitude peak across which the phase turns by ~180 deg (paper, Fig. 12).
    Each magnitude peak (prominence >= ``prominence_db``) is checked by the phase change between
    the frequencies three half-power half-widths either side of it -- ~143 deg for an isolated
    lightly damped mode -- and kept if that change is at least ``min_phase_shift_deg``; this
    rejects noise spikes and leakage ripples, whose phase does not turn. Damping is the
    half-power bandwidth estimate ``zeta = (f2 - f1) / (2 fn)``, where ``|H(f1)| = |H(f2)| =
    |H(fn)|/sqrt(2)`` (linear interpolation between bins), valid for light damping
    (zeta < ~0.1) and modes farther apart than their bandwidths.

    Parameters
    ----------
    f : (k,) array
        Frequencies [Hz], increasing.
    H : (k,) complex array
        FRF [any unit]; complex, since the phase check needs the phase.
    n : int
        Maximum number of modes returned (the most prominent that pass the phase check).
    fmin, fmax : float
        Band searched [Hz].
    prominence_db : float
        Minimum magnitude-peak prominence [dB].
    min_phase_shift_deg : float
        Minimum phase turn [deg] across a peak for it to count as a mode.

    Returns
    -------
    freqs : (m,) array
        Natural frequencies [Hz], ascending, m <= n; parabolic interpolation of the dB magnitude.
    damping : (m,) array
        Damping ratios [-] (fraction of critical); NaN where a half-power point lies beyond the data.
    """
    f = as_signal(f, "f", min_length=3)
    H = np.asarray(H)
    if not np.iscomplexobj(H):
        raise SignalError("H must be complex: the phase check needs the FRF's phase, not only its magnitude")
    if H.shape != f.shape:
        raise SignalError(f"f and H must have the same shape, got {f.shape} and {H.shape}")
    if np.any(np.diff(f) <= 0):
        raise SignalError("f must be strictly increasing")
    n = positive_int(n, "n")
    fmin, fmax = frequency_band(fmin, fmax)
    finite = np.isfinite(H)
    if not finite.all():
        raise SignalError(f"H has {int((~finite).sum())} non-finite values; restrict f/H to valid bins")
    mag = np.abs(H)
    level = spectrum_db(mag)
    band = np.flatnonzero((f >= fmin) & (f <= fmax))
    if band.size < 3:
        raise SignalError(f"the band [{fmin:g}, {fmax:g}] Hz holds fewer than 3 bins")
    peaks, props = sps.find_peaks(level[band], prominence=prominence_db)
    peaks = band[peaks]
    order = np.argsort(props["prominences"])[::-1]

    freqs, damping = [], []
    for p in peaks[order]:
        fn, peak_db = _parabolic_peak(f, level, int(p))
        half_power = 10.0 ** ((peak_db - 3.0103) / 20.0)
        f1 = _crossing(f, mag, int(p), half_power, -1)
        f2 = _crossing(f, mag, int(p), half_power, +1)
        if np.isfinite(f1) and np.isfinite(f2):
            zeta = (f2 - f1) / (2.0 * fn)
            reach = 3.0 * 0.5 * (f2 - f1)
        else:
            zeta = float("nan")
            reach = 3.0 * (f[1] - f[0])
        if _phase_turn_deg(f, H, fn - reach, fn + reach) < min_phase_shift_deg:
            continue
        freqs.append(fn)
        damping.append(zeta)
        if len(freqs) == n:
            break
    freqs, damping = np.array(freqs), np.array(damping)
    ascending = np.argsort(freqs)
    return freqs[ascending], damping[ascending]


def _crossing(f: np.ndarray, mag: np.ndarray, start: int, level: float, direction: int) -> float:
    """Frequency [Hz] where |H| first falls below ``level`` walking from bin ``start``; NaN if never."""
    i = start
    while 0 <= i + direction < f.size:
        j = i + direction
        if mag[j] < level:
            t = (mag[i] - level) / (mag[i] - mag[j])
            return float(f[i] + t * (f[j] - f[i]))
        i = j
    return float("nan")


def _phase_turn_deg(f: np.ndarray, H: np.ndarray, f_lo: float, f_hi: float) -> float:
    """|phase(f_hi) - phase(f_lo)| [deg], unwrapped over the bins between them only."""
    lo = int(np.clip(np.searchsorted(f, f_lo) - 1, 0, f.size - 1))
    hi = int(np.clip(np.searchsorted(f, f_hi) + 1, 0, f.size))
    seg_f = f[lo:hi]
    if seg_f.size < 2:
        return 0.0
    # Unwrapping only the local stretch keeps a noisy bin far away from adding spurious turns.
    phase = np.unwrap(np.angle(H[lo:hi]))
    turn = np.interp(min(f_hi, seg_f[-1]), seg_f, phase) - np.interp(max(f_lo, seg_f[0]), seg_f, phase)
    return float(np.degrees(abs(turn)))


def remove_foundation_modes(system_modes, foundation_modes, *, tol_rel: float = 0.03
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Remove the foundation's modes (hammer test) from the rig's modes (run-up).

    A system mode matches a foundation mode when they differ by at most ``tol_rel`` of the
    foundation mode's frequency. Matching is one-to-one, closest pairs first: one foundation mode
    explains at most one run-up peak, so two close rig modes cannot both vanish because of it.
    The 3 % default covers the run-up PSD's bin quantisation (1 Hz is 3 % at 33 Hz) and the small
    shift a foundation mode sees between the hammer test (light load) and the running rig.

    Parameters
    ----------
    system_modes : (p,) array
        Natural frequencies of the whole rig [Hz] (e.g. paper Table 1).
    foundation_modes : (q,) array
        Natural frequencies of the foundation [Hz] from the hammer test.
    tol_rel : float
        Relative tolerance [-], in (0, 1).

    Returns
    -------
    kept : (p - r,) array
        System modes with no foundation counterpart [Hz], in their input order.
    removed : (r,) array
        System modes attributed to the foundation [Hz], in their input order.
    """
    system = np.atleast_1d(np.asarray(system_modes, dtype=float))
    foundation = np.atleast_1d(np.asarray(foundation_modes, dtype=float))
    for name, arr in (("system_modes", system), ("foundation_modes", foundation)):
        if arr.ndim != 1 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
            raise SignalError(f"{name} must be a 1-D list of positive frequencies [Hz], got {arr!r}")
    tol_rel = float(tol_rel)
    if not 0.0 < tol_rel < 1.0:
        raise SignalError(f"tol_rel must be in (0, 1), got {tol_rel!r}")
    if system.size == 0 or foundation.size == 0:
        return system.copy(), np.empty(0)
    distance = np.abs(system[:, None] - foundation[None, :]) / foundation[None, :]
    matched = np.zeros(system.size, dtype=bool)
    used = np.zeros(foundation.size, dtype=bool)
    for flat in np.argsort(distance, axis=None):
        i, j = np.unravel_index(flat, distance.shape)
        if distance[i, j] > tol_rel:
            break
        if not matched[i] and not used[j]:
            matched[i] = used[j] = True
    return system[~matched], system[matched]
