"""Spectrum and time plots from a synthetic sine result."""
from __future__ import annotations

import numpy as np
import pytest

from twin.errors import OutputPathError
from twin.plotting import plot_spectrum, plot_time, spectrum_figure, welch_psd
from twin.results import SimulationResult

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
FS = 4096.0  # Hz
F_SINE = 123.0  # Hz


@pytest.fixture
def sine() -> SimulationResult:
    rng = np.random.default_rng(7)
    t = np.arange(int(4 * FS)) / FS
    a = 3.0 * np.sin(2 * np.pi * F_SINE * t) + 0.01 * rng.standard_normal(t.size)
    return SimulationResult(time=t, signals={"acc": a, "acc2": 0.5 * a}, units={"acc": "m/s2"},
                            sample_rate=FS, parameters={})


def test_welch_peak_and_default_resolution(sine):
    freq, psd_db = welch_psd(sine, "acc")
    assert freq[1] - freq[0] == pytest.approx(2.0)
    assert abs(freq[np.argmax(psd_db)] - F_SINE) <= 2.0


def test_nperseg_capped_to_signal_length(sine):
    short = SimulationResult(time=sine.time[:100], signals={"acc": sine["acc"][:100]},
                             units={}, sample_rate=FS, parameters={})
    freq, _ = welch_psd(short, "acc")
    assert freq.size == 51


def test_plot_spectrum_writes_png(tmp_path, sine):
    out = plot_spectrum(sine, ["acc", "acc2"], tmp_path / "psd.png", fmax=1000.0,
                        title="sine", markers={"1x": F_SINE, "far": 3000.0}, logx=True)
    assert out == tmp_path / "psd.png"
    assert out.read_bytes()[:8] == PNG_MAGIC
    assert sorted(p.name for p in tmp_path.iterdir()) == ["psd.png"]


def test_marker_lands_on_peak(sine):
    fig = spectrum_figure(sine, ["acc"], fmax=1000.0, markers={"1x": F_SINE, "far": 3000.0})
    ax = fig.axes[0]
    psd_line, *marker_lines = ax.lines
    assert len(marker_lines) == 1  # the 3000 Hz marker lies outside fmax and is skipped
    marker_f = marker_lines[0].get_xdata()[0]
    peak_f = psd_line.get_xdata()[np.argmax(psd_line.get_ydata())]
    assert marker_f == F_SINE and abs(peak_f - marker_f) <= 2.0
    assert "(m/s2)" in ax.get_ylabel()


def test_plot_time_writes_png(tmp_path, sine):
    out = plot_time(sine, ["acc"], tmp_path / "t.png", 0.1, 0.2)
    assert out.read_bytes()[:8] == PNG_MAGIC


def test_plot_time_empty_window(tmp_path, sine):
    with pytest.raises(ValueError, match=r"no samples in \[10, 11\]"):
        plot_time(sine, ["acc"], tmp_path / "t.png", 10, 11)


def test_plot_rejects_non_png_and_missing_dir(tmp_path, sine):
    with pytest.raises(OutputPathError, match="'.svg'"):
        plot_spectrum(sine, ["acc"], tmp_path / "psd.svg")
    with pytest.raises(OutputPathError, match="missing"):
        plot_spectrum(sine, ["acc"], tmp_path / "missing" / "psd.png")


def test_unknown_channel(tmp_path, sine):
    with pytest.raises(KeyError, match="acc2"):
        plot_spectrum(sine, ["nope"], tmp_path / "psd.png")
