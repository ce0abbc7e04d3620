"""PNG plots of simulation results: Welch power spectra and time traces.

Figures are built on matplotlib's Agg canvas without pyplot, so plotting works
headless, leaks no global figures and never disturbs a caller's interactive
backend. Files are written atomically (see :mod:`twin._atomic`).
"""
from __future__ import annotations

import os
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin._atomic import atomic_path, check_parent
from twin.errors import OutputPathError
from twin.results import SimulationResult

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Frequency resolution [Hz] the default Welch segment length aims for.
DEFAULT_RESOLUTION_HZ = 2.0
# Floor for the dB conversion so an exactly-zero bin plots as very low, not -inf.
_PSD_FLOOR = 1e-300


def welch_psd(
    result: SimulationResult, channel: str, *, nperseg: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density of one channel.

    Hann window, 50 % overlap, mean removed per segment. The default segment
    length gives a resolution of :data:`DEFAULT_RESOLUTION_HZ` (``fs / 2`` samples),
    capped to the signal length.

    Returns
    -------
    freq : numpy.ndarray, shape (m,)
        Frequencies [Hz] from 0 to Nyquist.
    psd_db : numpy.ndarray, shape (m,)
        PSD in dB re 1 unit^2/Hz of the channel (dB re 1 (m/s^2)^2/Hz for
        accelerations).

    Raises
    ------
    ValueError
        If the channel has fewer than 2 samples, the sample rate is not
        positive or ``nperseg`` is below 2.
    """
    from scipy.signal import welch

    x = result[channel]
    fs = result.sample_rate
    if not fs > 0:
        raise ValueError(f"sample_rate must be > 0 Hz for a spectrum, got {fs}")
    if x.size < 2:
        raise ValueError(f"channel '{channel}' has {x.size} samples; a spectrum needs at least 2")
    if nperseg is None:
        nperseg = int(round(fs / DEFAULT_RESOLUTION_HZ))
    if nperseg < 2:
        raise ValueError(f"nperseg must be >= 2, got {nperseg}")
    nperseg = min(nperseg, x.size)
    freq, psd = welch(x, fs=fs, window="hann", nperseg=nperseg, detrend="constant",
                      scaling="density")
    return freq, 10.0 * np.log10(np.maximum(psd, _PSD_FLOOR))


def _png_target(path: str | os.PathLike[str]) -> Path:
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise OutputPathError(f"plot path '{target}' has suffix '{target.suffix}'; only .png is written")
    return check_parent(target)


def _new_figure(n_axes: int) -> Figure:
    import matplotlib

    # Only pick the backend when pyplot is not in use: switching would break a
    # caller's interactive session, and the explicit Agg canvas below suffices.
    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 1.0 + 2.4 * n_axes), layout="constrained")
    FigureCanvasAgg(fig)
    fig.subplots(n_axes, 1, sharex=True, squeeze=False)
    return fig


def _save(fig: Figure, target: Path) -> Path:
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return target


def spectrum_figure(
    result: SimulationResult,
    channels: Sequence[str],
    *,
    fmin: float = 0.0,
    fmax: float | None = None,
    title: str | None = None,
    nperseg: int | None = None,
    markers: Mapping[str, float] | None = None,
    logx: bool = False,
) -> Figure:
    """Build the spectrum figure drawn by :func:`plot_spectrum` (see there) without saving it."""
    if not channels:
        raise ValueError("no channels given to plot")
    nyquist = result.sample_rate / 2.0
    fmax = nyquist if fmax is None else float(fmax)
    if not 0.0 <= fmin < fmax:
        raise ValueError(f"need 0 <= fmin < fmax, got fmin={fmin} Hz, fmax={fmax} Hz")
    fig = _new_figure(len(channels))
    axes = fig.axes
    for i, (ax, name) in enumerate(zip(axes, channels)):
        freq, psd_db = welch_psd(result, name, nperseg=nperseg)
        # A log axis cannot show the DC bin.
        keep = (freq >= fmin) & (freq <= fmax) & ((freq > 0) if logx else True)
        ax.plot(freq[keep], psd_db[keep], lw=0.8, color="C0")
        unit = result.units.get(name, "") or "1"
        ax.set_ylabel(f"PSD [dB re 1 ({unit})²/Hz]", fontsize=8)
        ax.set_title(name, fontsize=9, loc="left")
        ax.grid(True, which="both", lw=0.3, alpha=0.6)
        for label, f_mark in (markers or {}).items():
            if not fmin <= f_mark <= fmax:
                continue
            ax.axvline(f_mark, ls=":", lw=1.0, color="C3", label=label)
            if i == 0:
                # Label each marker once, at the top of the first panel.
                ax.annotate(label, xy=(f_mark, 1.0), xycoords=("data", "axes fraction"),
                            rotation=90, ha="right", va="top", fontsize=7, color="C3")
    last = axes[-1]
    if logx:
        last.set_xscale("log")
    last.set_xlim(max(fmin, freq[1]) if logx else fmin, fmax)
    last.set_xlabel("frequency [Hz]")
    if title:
        fig.suptitle(title)
    return fig


def plot_spectrum(
    result: SimulationResult,
    channels: Sequence[str],
    path: str | os.PathLike[str],
    *,
    fmin: float = 0.0,
    fmax: float | None = None,
    title: str | None = None,
    nperseg: int | None = None,
    markers: Mapping[str, float] | None = None,
    logx: bool = False,
) -> Path:
    """Write a PNG with the Welch PSD of each channel, one panel per channel.

    Parameters
    ----------
    result : SimulationResult
    channels : sequence of str
        Channels to plot, top to bottom.
    path : path-like
        Output ``.png``; its directory must exist.
    fmin, fmax : float
        Frequency range shown [Hz]; ``fmax`` defaults to Nyquist.
    title : str, optional
        Figure title.
    nperseg : int, optional
        Welch segment length [samples]; default ``fs / 2`` (2 Hz resolution),
        capped to the signal length.
    markers : mapping of label -> frequency [Hz], optional
        Vertical dotted lines, e.g. gear-mesh harmonics; those outside
        ``[fmin, fmax]`` are skipped.
    logx : bool
        Logarithmic frequency axis (DC bin omitted).

    Returns
    -------
    Path of the written PNG.

    Raises
    ------
    OutputPathError
        Suffix other than ``.png`` or missing directory (checked before computing).
    KeyError
        Unknown channel.
    """
    target = _png_target(path)
    fig = spectrum_figure(result, channels, fmin=fmin, fmax=fmax, title=title,
                          nperseg=nperseg, markers=markers, logx=logx)
    return _save(fig, target)


def plot_time(
    result: SimulationResult,
    channels: Sequence[str],
    path: str | os.PathLike[str],
    t0: float,
    t1: float,
    *,
    title: str | None = None,
) -> Path:
    """Write a PNG of the channels over the window ``t0 <= t <= t1`` [s], one panel each.

    Raises
    ------
    OutputPathError
        Suffix other than ``.png`` or missing directory.
    ValueError
        Empty channel list, ``t1 <= t0`` or no samples in the window.
    KeyError
        Unknown channel.
    """
    target = _png_target(path)
    if not channels:
        raise ValueError("no channels given to plot")
    if not t1 > t0:
        raise ValueError(f"need t0 < t1, got t0={t0} s, t1={t1} s")
    window = (result.time >= t0) & (result.time <= t1)
    if not window.any():
        raise ValueError(
            f"no samples in [{t0}, {t1}] s; result spans "
            f"[{result.time[0] if len(result) else 'n/a'}, "
            f"{result.time[-1] if len(result) else 'n/a'}] s"
        )
    fig = _new_figure(len(channels))
    for ax, name in zip(fig.axes, channels):
        ax.plot(result.time[window], result[name][window], lw=0.8, color="C0")
        unit = result.units.get(name, "")
        ax.set_ylabel(f"{name} [{unit}]" if unit else name, fontsize=8)
        ax.grid(True, lw=0.3, alpha=0.6)
    fig.axes[-1].set_xlabel("time [s]")
    fig.axes[-1].set_xlim(t0, t1)
    if title:
        fig.suptitle(title)
    return _save(fig, target)


def plot_degradation_stages(stages: Sequence[tuple[str, "SimulationResult"]], path: str | os.PathLike[str], *,
                            stiffness: str = "mesh_stiffness", channel: str = "accel_pinion_casing",
                            mesh_period: float | None = None, fmax: float = 3000.0,
                            title: str | None = None) -> Path:
    """Mesh stiffness over two mesh cycles and the PSD of ``channel``, one curve per stage.

    ``stages`` is a list of (label, result); each result must hold ``stiffness`` [N/m] and
    ``channel``. ``mesh_period`` [s] sets the stiffness window (default: 2/380 s).
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.signal import welch

    target = Path(path)
    if target.suffix.lower() != ".png":
        raise OutputPathError(f"plot path must end in .png, got {target.suffix!r}")
    window = 2 * (mesh_period or 1 / 380.0)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 8))
    cmap = plt.get_cmap("viridis")
    for i, (label, res) in enumerate(stages):
        color = cmap(i / max(len(stages) - 1, 1))
        t = res.time
        sel = t >= t[-1] - window
        ax1.plot(1e3 * (t[sel] - t[sel][0]), res[stiffness][sel] / 1e6, color=color, label=label)
        f, p = welch(res[channel], fs=res.sample_rate, nperseg=min(res.time.size, int(res.sample_rate / 10)))
        keep = f <= fmax
        ax2.semilogy(f[keep], p[keep], color=color, lw=0.8, label=label)
    ax1.set_xlabel("time [ms]")
    ax1.set_ylabel("mesh stiffness [N/um]")
    ax1.set_title("Mesh stiffness over two mesh cycles")
    ax1.legend(fontsize=8, ncol=3)
    ax1.grid(alpha=0.3)
    ax2.set_xlabel("frequency [Hz]")
    ax2.set_ylabel(f"PSD of {channel} [(m/s2)^2/Hz]")
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=8, ncol=3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
    return target


def plot_modal_survey(survey, path: str | os.PathLike[str], *, title: str | None = None) -> Path:
    """Campbell diagram of a run-up (or the FRF of a hammer test) with what ``twin modes`` found.

    Run-up: left, the spectrogram in dB re its local floor against shaft speed, with the
    speed-locked orders as rays, the modes as solid and the fixed lines as dotted horizontal
    lines; right, the stationary spectrum the modes were read from. Hammer test: the FRF
    magnitude with the modes marked.
    """
    target = _png_target(path)
    fig = _new_figure(1)
    fig.clear()
    fig.set_size_inches(11.0, 6.0)
    modes = [m for m in survey.modes]
    if survey.method == "runup" and survey.slice_speed is not None and survey.spectrogram_db is not None:
        ax, side = fig.subplots(1, 2, sharey=True, gridspec_kw={"width_ratios": [3, 1]})
        speed = survey.slice_speed
        order = np.argsort(speed)
        ax.pcolormesh(speed[order], survey.f, survey.spectrogram_db[:, order], shading="nearest",
                      cmap="viridis", vmin=-10, vmax=30, rasterized=True)
        for o in survey.orders:
            ax.plot(speed[order], o.order * speed[order], color="w", lw=0.6, ls="--", alpha=0.7)
        ax.set_xlabel("shaft speed [Hz]")
        ax.set_ylabel("frequency [Hz]")
        tops = [m.frequency for m in modes] + [ln.frequency for ln in survey.lines]
        ax.set_ylim(survey.band[0], min(survey.band[1], 1.4 * max(tops)) if tops else survey.band[1])
        side.plot(survey.stationary_db, survey.f, color="k", lw=0.7)
        side.set_xlabel("stationary level [dB re floor]")
        axes = (ax, side)
    else:
        side = fig.subplots(1, 1)
        side.plot(survey.f, survey.stationary_db, color="k", lw=0.7)
        side.set_xlabel("frequency [Hz]")
        side.set_ylabel("|H| [dB re median]")
        axes = (side,)
    horizontal = survey.method == "runup" and survey.slice_speed is not None
    for a in axes:
        line = a.axhline if horizontal else a.axvline
        for m in modes:
            line(m.frequency, color="tab:red", lw=0.9, alpha=0.4 + 0.6 * m.confidence)
        for ln in survey.lines:
            line(ln.frequency, color="tab:cyan", lw=0.9, ls=":")
    if horizontal:
        # each mode's shape at the sensors (level and phase of the other channel re the reference;
        # grey when the coherence is below 0.5 and the shape is not to be trusted)
        for m in modes:
            shape = m.evidence.get("shape")
            others = [(c, v) for c, v in (shape or {}).get("channels", {}).items() if c != shape["reference"]]
            if others:
                text = " ".join(f"{v['level_db']:+.0f}dB/{v['phase_deg']:+.0f}\u00b0" for _, v in others)
                side.annotate(text, (1.0, m.frequency), xycoords=("axes fraction", "data"), fontsize=6,
                              ha="right", va="bottom",
                              color="k" if shape.get("min_coherence", 0) >= 0.5 else "0.6")
    axes[0].set_title(title or f"{survey.method}: {len(modes)} modes (red), {len(survey.lines)} fixed lines "
                      f"(dotted), {len(survey.orders)} orders (dashed)")
    return _save(fig, target)
