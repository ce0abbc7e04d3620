"""Why the wear stages are hard to transfer: level and spectral-shape statistics of the benchmark data.

    python bench/transfer_diagnostics.py --data-dir DIR [--rig rig|blind|lumped|ltca] [--task wear]

Reads the source archive and the target records that ``bench/transfer.py`` built in DIR
(``twin.transfer.benchmark_data.prepare_task``; nothing is simulated or trained here) and prints, per
stage and per domain, the following. Target labels are read here, for diagnosis only.

* the mean and spread of each record's log RMS, after the domain's mean is removed: the
  "level" cue that the assessor keeps for wear;
* a level-only reference: a Gaussian classifier of the record log RMS, fitted on the rig's
  labelled first halves and scored on its second halves (what the level alone allows on that
  rig, whatever a method learns from the twin);
* per pair of neighbouring stages, the change of the level-free log spectrum (64 bands) in
  each domain, and the correlation of the two changes (how well the *shape* cue carries over);
* a linear probe: a shrinkage LDA trained on the twin's windows (shape, level, or both; each
  domain centred on its own mean) and scored on the rig's test windows, with no adaptation;
* per stage and domain, the energy of the shaft-order sidebands (mesh harmonics +- 1-3 shaft
  orders) against the mesh harmonics themselves, in dB: how much tooth-to-tooth variation
  (pitch errors, run-out, uneven damage) each domain has.  Each record's shaft speed is found
  from its mesh comb, since the twin's motor slips under load;
* per stage and domain, the change of the first mesh harmonics' log amplitudes from the first
  stage: the damage's own effect on the mesh excitation.  A linear transfer path multiplies each
  harmonic by a gain of its own, the same at every stage, so the change is free of the path
  (at the near-constant speed of a test); what remains differs between two domains only where
  their damage physics does.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

BANDS = 64


def _levels(records, channel: str) -> np.ndarray:
    return np.array([np.log(np.std(r[channel])) for r in records])


def _window_features(records, pre) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(window level (n,), level-free log spectrum in BANDS bands (n, BANDS), label (n,))."""
    from twin.transfer.preprocess import log_spectrum, prepare, window_signal

    levels, shapes, labels = [], [], []
    for p in prepare(records, pre):
        spec = log_spectrum(window_signal(p.signal, pre.window, pre.hop), pre.time_bandwidth)
        level = spec.mean(axis=1)
        levels.append(level)
        shapes.append((spec - level[:, None]).reshape(len(spec), BANDS, -1).mean(axis=2))
        labels.append(np.full(len(spec), -1 if p.label is None else p.label))
    return np.concatenate(levels), np.concatenate(shapes), np.concatenate(labels)


def _shaft_speed(x: np.ndarray, fs: float, nominal: float, teeth: int) -> float:
    """The shaft speed [Hz] within -5..+2 % of ``nominal`` whose first five mesh harmonics carry
    the most amplitude (a 16x zero-padded Hann spectrum)."""
    n = 16 * x.size
    spec = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(x.size), n))
    freq = np.fft.rfftfreq(n, 1 / fs)
    cands = np.linspace(0.95 * nominal, 1.02 * nominal, 281)
    comb = sum(np.interp(k * teeth * cands, freq, spec) for k in range(1, 6))
    return float(cands[np.argmax(comb)])


HARMONICS = 6


def _mesh_lines(x: np.ndarray, fs: float, nominal: float, teeth: int = 19,
                fmax: float = 5000.0) -> tuple[float, np.ndarray]:
    """One record's mesh lines from one Hann power spectrum, 3 bins per line: the energy at the
    mesh harmonics (below ``fmax``) +- 1-3 shaft orders over that at the harmonics [dB], and the
    natural log of the amplitude at mesh harmonics 1..HARMONICS, shape (HARMONICS,)."""
    f = _shaft_speed(x, fs, nominal, teeth)
    power = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(x.size))) ** 2
    df = fs / x.size

    def at(freq: float) -> float:
        k = int(round(freq / df))
        return float(power[max(k - 1, 0):k + 2].sum())

    harmonics = [k * teeth * f for k in range(1, 100) if k * teeth * f < min(fmax, fs / 2 - 4 * f)]
    mesh = sum(at(h) for h in harmonics)
    side = sum(at(h + m * f) for h in harmonics for m in (-3, -2, -1, 1, 2, 3))
    return 10 * np.log10(side / mesh), np.array([0.5 * np.log(at(h * teeth * f)) for h in range(1, HARMONICS + 1)])


def _lda(x: np.ndarray, y: np.ndarray, shrinkage: float):
    """Shrinkage linear discriminant: returns predict(z) for z (n, d)."""
    k = int(y.max()) + 1
    mu = np.array([x[y == c].mean(axis=0) for c in range(k)])
    cov = np.atleast_2d(np.cov((x - mu[y]).T))
    cov = (1 - shrinkage) * cov + shrinkage * np.trace(cov) / cov.shape[0] * np.eye(cov.shape[0])
    w = np.linalg.solve(cov, mu.T)
    b = -0.5 * np.sum(mu.T * w, axis=0)
    return lambda z: np.argmax(z @ w + b, axis=1)


def main() -> None:
    from twin.measurements import load_measurements
    from twin.transfer.benchmark import RIGS, prepare_task, rig_settings, task_preprocessing
    from twin.transfer.preprocess import split_records
    from transfer import INDEPENDENT_RIGS, independent_targets      # bench/transfer.py, beside this script

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data-dir", required=True, help="the data directory of bench/transfer.py (its --data-dir)")
    ap.add_argument("--task", choices=("pitting", "wear"), default="wear")
    ap.add_argument("--rig", choices=tuple(RIGS) + tuple(INDEPENDENT_RIGS), default="rig")
    args = ap.parse_args()

    if args.rig in INDEPENDENT_RIGS:        # the independent simulators' records are written by rigs/
        settings, targets = independent_targets(args.rig, (args.task,), Path(args.data_dir))
        src_path, tgt_path = prepare_task(args.task, args.data_dir, settings[args.task], target=targets[args.task])
    else:
        src_path, tgt_path = prepare_task(args.task, args.data_dir, rig_settings(args.task, args.rig))
    pre = replace(task_preprocessing(args.task), remove_level=False)
    ch = pre.channel
    src = load_measurements(src_path, channels=[ch], resample_to=pre.sample_rate).records
    tgt = load_measurements(tgt_path, channels=[ch], resample_to=pre.sample_rate).records
    adapt, test = split_records(tgt, 0.5)
    k = 1 + max(r.label for r in src)

    print(f"{args.task}, rig '{args.rig}': {len(src)} source records, {len(tgt)} target records\n")
    print("| stage | source log RMS (centred), mean / sd | rig log RMS (centred), mean / sd |")
    print("|---|---|---|")
    ls, lt = _levels(src, ch), _levels(tgt, ch)
    ys, yt = np.array([r.label for r in src]), np.array([r.label for r in tgt])
    ls, lt = ls - ls.mean(), lt - lt.mean()
    for c in range(k):
        print(f"| {c + 1} | {ls[ys == c].mean():+.2f} / {ls[ys == c].std():.2f} | "
              f"{lt[yt == c].mean():+.2f} / {lt[yt == c].std():.2f} |")

    la, lb = _levels(adapt, ch), _levels(test, ch)
    ya, yb = np.array([r.label for r in adapt]), np.array([r.label for r in test])
    mu = np.array([la[ya == c].mean() for c in range(k)])
    sd = np.array([la[ya == c].std() for c in range(k)])
    loglik = -0.5 * ((lb[:, None] - mu) / sd) ** 2 - np.log(sd)
    print(f"\nLevel-only classifier fitted on the rig's labelled first halves: "
          f"{100 * np.mean(loglik.argmax(axis=1) == yb):.1f} % of the second halves (records)\n")

    lev_s, shp_s, y_s = _window_features(src, pre)
    lev_a, shp_a, _ = _window_features(adapt, pre)
    lev_t, shp_t, y_t = _window_features(test, pre)
    # Each domain centred on its own unlabelled mean, as the assessor's domain normaliser does.
    shp_s, shp_t = shp_s - shp_s.mean(axis=0), shp_t - shp_a.mean(axis=0)
    lev_s, lev_t = lev_s - lev_s.mean(), lev_t - lev_a.mean()
    _, shp_full, y_full = _window_features(tgt, pre)
    shp_full = shp_full - shp_full.mean(axis=0)
    print("| stages | shape change, twin [norm] | shape change, rig [norm] | correlation |")
    print("|---|---|---|---|")
    for a in range(k - 1):
        d_s = shp_s[y_s == a + 1].mean(axis=0) - shp_s[y_s == a].mean(axis=0)
        d_t = shp_full[y_full == a + 1].mean(axis=0) - shp_full[y_full == a].mean(axis=0)
        print(f"| {a + 1} -> {a + 2} | {np.linalg.norm(d_s):.2f} | {np.linalg.norm(d_t):.2f} | "
              f"{np.corrcoef(d_s, d_t)[0, 1]:.2f} |")

    print("\n| linear probe trained on the twin, no adaptation | rig test windows [%] |\n|---|---|")
    for name, xs, xt in (("shape", shp_s, shp_t), ("level", lev_s[:, None], lev_t[:, None]),
                         ("shape + level", np.c_[shp_s, lev_s], np.c_[shp_t, lev_t])):
        predict = _lda(xs, y_s, shrinkage=0.1)
        print(f"| {name} | {100 * np.mean(predict(xt) == y_t):.1f} |")

    lines = [[_mesh_lines(r[ch], r.sample_rate, r.nominal_speed) for r in recs] for recs in (src, tgt)]
    labels = [np.array([r.label for r in recs]) for recs in (src, tgt)]
    print("\n| stage | sidebands / mesh harmonics, twin [dB] | the same, rig [dB] |\n|---|---|---|")
    for c in range(k):
        sb = [np.mean([db for (db, _), y in zip(rows, ys) if y == c]) for rows, ys in zip(lines, labels)]
        print(f"| {c + 1} | {sb[0]:.1f} | {sb[1]:.1f} |")

    print(f"\n| stage | mesh harmonics 1-{HARMONICS}, change of log amplitude from stage 1, twin | the same, rig "
          "| correlation |\n|---|---|---|---|")
    response = []
    for rows, y in zip(lines, labels):
        amp = np.array([a for _, a in rows])
        mean = np.array([amp[y == c].mean(axis=0) for c in range(k)])
        response.append(mean - mean[0])
    for c in range(1, k):
        a, b = response[0][c], response[1][c]
        print(f"| {c + 1} | {' '.join(f'{v:+.2f}' for v in a)} | {' '.join(f'{v:+.2f}' for v in b)} | "
              f"{np.corrcoef(a, b)[0, 1]:.2f} |")


if __name__ == "__main__":
    main()
