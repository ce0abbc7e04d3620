"""What an archive carries of a rig's damage trend: archives side by side against the rig's labelled records.

    python bench/archive_diagnostics.py --rig RIG_TEST.h5 NAME=ARCHIVE.h5 [NAME=ARCHIVE.h5 ...]

Reads archives (``twin archive``, ``twin pipeline``'s ``DIR/archive.h5``) and a rig's stage records
whose labels are in ``RIG_TEST.h5.truth.json`` (``bench/pipeline_rigs.py`` writes both; the labels are
read for diagnosis only, nothing is trained).  Per archive and for the rig, over the stages:

* **level**: the log RMS per stage, centred, and its spread within a stage;
* **sidebands**: the shaft-order sidebands (mesh harmonics +- 1-3 orders) against the mesh harmonics [dB];
* **mesh harmonics**: the change of the first six mesh harmonics' log amplitude from stage 1, path-free
  (a linear path multiplies each harmonic by the same gain at every stage), and its correlation with
  the rig's, stages 2-6;
* **where the energy goes**: the energy at the mesh lines (below 5 kHz), at their +-1-3 shaft-order
  sidebands, and everywhere else below 5 kHz (between the lines), each per stage in dB from stage 1,
  from one Hann power spectrum of the whole record at its own shaft speed;
* **spectral shape**: the change from stage 1 of the level-free log spectrum in 64 bands, as the
  assessor's preprocessing makes it for the archive (window, resampling, level removed for pitting),
  its correlation with the rig's, and the stages' separation in it: the mean distance of the stage
  means from their centre over the mean distance of windows from their stage's mean.

The mesh-harmonic and level statistics are those of ``bench/transfer_diagnostics.py``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

from pipeline_rigs import CHANNEL, labelled   # the rig files and their truth labels, as scored there


def energy_split(x: np.ndarray, fs: float, nominal: float, teeth: int = 19, fmax: float = 5000.0) -> np.ndarray:
    """(3,) energy [dB] of one record at the mesh lines, at their +-1-3 shaft-order sidebands and
    between them, below ``fmax``; 3 bins per line."""
    from transfer_diagnostics import _shaft_speed

    f0 = _shaft_speed(x, fs, nominal, teeth)
    x = np.asarray(x, float) - np.mean(x)
    power = np.abs(np.fft.rfft(x * np.hanning(x.size))) ** 2
    f = np.fft.rfftfreq(x.size, 1 / fs)
    near = lambda centre: np.abs(f - centre) <= 1.5 * f[1]      # noqa: E731
    line, side = np.zeros(f.size, bool), np.zeros(f.size, bool)
    for h in range(1, int(fmax / (teeth * f0)) + 1):
        line |= near(h * teeth * f0)
        for order in (1, 2, 3):
            side |= near(h * teeth * f0 + order * f0) | near(h * teeth * f0 - order * f0)
    side &= ~line
    rest = (f < fmax) & ~line & ~side
    return np.array([10 * np.log10(power[m].sum()) for m in (line, side, rest)])


def statistics(records, pre) -> dict:
    """Per-stage statistics of labelled records (see the module docstring)."""
    from transfer_diagnostics import _mesh_lines, _window_features

    y = np.array([r.label for r in records])
    k = int(y.max()) + 1
    level = np.array([np.log(np.std(r[CHANNEL])) for r in records])
    level -= level.mean()
    lines = [_mesh_lines(np.asarray(r[CHANNEL], float), r.sample_rate, r.nominal_speed) for r in records]
    side = np.array([s for s, _ in lines])
    amp = np.array([a for _, a in lines])
    harm = np.array([amp[y == c].mean(axis=0) for c in range(k)])
    split = np.array([energy_split(np.asarray(r[CHANNEL], float), r.sample_rate, r.nominal_speed) for r in records])
    split = np.array([split[y == c].mean(axis=0) for c in range(k)])
    _, shape, yw = _window_features(records, pre)
    mean = np.array([shape[yw == c].mean(axis=0) for c in range(k)])
    within = np.mean([np.linalg.norm(shape[yw == c] - mean[c], axis=1).mean() for c in range(k)])
    between = np.linalg.norm(mean - mean.mean(axis=0), axis=1).mean()
    return {"level": [level[y == c].mean() for c in range(k)], "level_sd": [level[y == c].std() for c in range(k)],
            "sidebands": [side[y == c].mean() for c in range(k)], "harmonics": harm - harm[0],
            "shape": mean - mean[0], "separation": between / within, "energy": split - split[0]}


def main() -> None:
    from twin.measurements import load_measurements
    from twin.transfer.settings import archive_facts, preprocessing_for

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rig", required=True, type=Path, help="the rig's labelled stage records (with .truth.json)")
    ap.add_argument("archives", nargs="+", metavar="NAME=ARCHIVE.h5")
    args = ap.parse_args()
    named = [a.split("=", 1) for a in args.archives]
    if any(len(n) != 2 for n in named):
        raise SystemExit("archives are given as NAME=ARCHIVE.h5")
    pre = preprocessing_for(archive_facts(named[0][1]))
    rig = statistics(labelled(args.rig), pre)
    rows = [(name, statistics(load_measurements(path, channels=[CHANNEL]).records, pre)) for name, path in named]
    fmt = lambda v, f="+.2f": " ".join(format(x, f) for x in v)      # noqa: E731
    print(f"rig {args.rig.name}; window {pre.window} at {pre.sample_rate:g} Hz, level removed: {pre.remove_level}\n")
    print("| source | log RMS per stage, centred | its sd within a stage | sidebands [dB] | mesh-harmonic change, "
          "correlation with the rig's, stages 2-6 | level-free shape change, correlation with the rig's, stages 2-6 "
          "| stage separation in shape |")
    print("|---|---|---|---|---|---|---|")
    for name, s in [*rows, ("rig", rig)]:
        h = [np.corrcoef(s["harmonics"][c], rig["harmonics"][c])[0, 1] for c in range(1, len(s["level"]))]
        c = [np.corrcoef(s["shape"][i], rig["shape"][i])[0, 1] for i in range(1, len(s["level"]))]
        print(f"| {name} | {fmt(s['level'])} | {fmt(s['level_sd'], '.2f')} | {fmt(s['sidebands'], '+.1f')} | "
              f"{fmt(h) if name != 'rig' else ''} | {fmt(c) if name != 'rig' else ''} | {s['separation']:.2f} |")
    print("\n| source | mesh lines, per stage from stage 1 [dB] | their sidebands +-1-3 orders | between them |")
    print("|---|---|---|---|")
    for name, s in [*rows, ("rig", rig)]:
        e = s["energy"]
        print(f"| {name} | {fmt(e[:, 0], '+.1f')} | {fmt(e[:, 1], '+.1f')} | {fmt(e[:, 2], '+.1f')} |")


if __name__ == "__main__":
    main()
