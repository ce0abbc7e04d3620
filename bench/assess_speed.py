"""Benchmark: inference cost per window of an assessor ensemble, the per-member path against the batched one.

    python bench/assess_speed.py [--ensemble DIR] [--records FILE] [--members 1,2,5] [--repeats 5]

Defaults: the pedestal pitting ensemble trained by ``bench/pipeline_rigs.py`` (calibrated twin,
``OUT/pedestal_pitting_calibrated/assessor``) and that rig's 48 test records (1 s at 50 kHz, 912
windows at 20.48 kHz).  Member counts above the trained ones reuse the trained networks in turn: the
cost of a forward pass does not depend on the weights.

For each member count, side by side in one run, repeated ``repeats`` times in turn (the fastest of
each is reported, the machine being shared):

* **before** -- the computation as it ran until 2026-11-26: the file read (with each record's
  tachometer), every record resampled with its anti-aliasing filter designed again, windowed and
  represented, then each member's own ``Assessor._forward`` (batches of 256 under
  ``torch.no_grad``, torch's default threads);
* **after** -- ``Ensemble._raw`` now: the file read record by record without the tachometer,
  each record resampled (polyphase filter as matrix products, designed once per rate) and
  represented on worker threads as soon as it is read, while the members'
  networks, folded once per ensemble, run on the windows already represented, one task per
  member and chunk (:mod:`twin.transfer.inference`);
* **assess** -- the whole ``Ensemble.assess`` of the file (2 members and more) with each path:
  reading, preprocessing, networks, class-prior rule, agreement, order check.

First, the CPU time of each stage of the assessment alone (one thread): the work the two cores
share.  Both paths' stages are compared window by window (they must be identical) and the largest
difference of a probability printed.  Prints the machine, its load and a Markdown table.
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
OUT = REPO / "bench_out" / "pipeline_rigs"


def machine() -> str:
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    return f"{cpu}, {len(os.sched_getaffinity(0))} cores, Python {platform.python_version()}"


def _reference_raw(self, data, what: str = "assess"):
    """``Ensemble._raw`` as it was: all records prepared (scipy's ``resample_poly``), then each
    member's own forward pass."""
    from scipy.signal import resample_poly

    import twin.measurements.resample as rs
    from twin.transfer.preprocess import windows_of
    rs._filter.cache_clear()                     # the filter was designed for every record
    fast, rs.polyphase = rs.polyphase, lambda x, up, down: resample_poly(x, up, down, window=rs._filter(up, down),
                                                                         padtype="line")
    try:
        first = self.members[0]
        prepared = first._prepared(data, None, what, "target")
    finally:
        rs.polyphase = fast
    raw, rec, lab = windows_of(prepared, self.preprocessing, what)
    return np.stack([m._forward(m.target_normaliser_(raw))[1] for m in self.members]), rec, lab, prepared


def ensembles(loaded, members):
    """(before, after) ensembles of these members with the loaded ensemble's rule and trends; for
    one member, objects that only compute the members' probabilities (``_raw``, which needs only
    the members)."""
    from twin.transfer.ensemble import Ensemble

    class Reference(Ensemble):
        _raw = _reference_raw

        def _streamed(self, data, what="assess", features=False, facts=None):
            raw, rec, lab, prepared = self._raw(data, what)
            return raw, rec, lab, prepared, None, self._features(prepared) if features else None

        def assess(self, data, **kw):
            from twin.measurements import load_measurements
            if isinstance(data, (str, Path)):        # read as before: the tachometer too
                data = load_measurements(data, channels=[self.preprocessing.channel_of("target")])
            return super().assess(data, **kw)

    out = []
    for cls in (Reference, Ensemble):
        if len(members) == 1:
            e = object.__new__(cls)
            e.members = members
        else:
            e = cls(members, loaded.facts)
            e.anchors_, e.log_weights_, e.twin_trends_ = loaded.anchors_, loaded.log_weights_, loaded.twin_trends_
            e.train_time_, e.notes_ = 0.0, ()
        out.append(e)
    return out


def stage_profile(loaded, path: Path, repeats: int) -> list[tuple[str, float]]:
    """CPU time per window of each stage of an assessment, each run alone on one thread (torch
    with one thread), the fastest of ``repeats``: what the two cores must share."""
    import torch

    from twin.measurements import iter_measurements
    from twin.transfer.inference import StackedNetworks
    from twin.transfer.preprocess import windows_of

    first, pre = loaded.members[0], loaded.preprocessing
    before = torch.get_num_threads()
    torch.set_num_threads(1)

    def cpu(f):
        best, out = float("inf"), None
        for _ in range(repeats):
            c = time.process_time()
            out = f()
            best = min(best, time.process_time() - c)
        return out, best
    try:
        recs, t_read = cpu(lambda: list(iter_measurements(path, channels=[pre.channel_of("target")], tachometer=False)))
        prep, t_res = cpu(lambda: [first._prepared([r], None, "assess", "target")[0] for r in recs])
        (raw, _, _), t_rep = cpu(lambda: windows_of(prep, pre, "assess"))
        _, normalise = loaded._networks()
        x, t_norm = cpu(lambda: normalise(raw))
        _, t_feat = cpu(lambda: loaded._features(prep))
        one = StackedNetworks([first.network_], threads=1)
        _, t_net = cpu(lambda: one.probabilities(x if x.ndim == 2 else x[0]))
        streamed = loaded._streamed(path, features=True, facts=loaded.facts)
        ens = object.__new__(type(loaded))
        ens.__dict__.update(loaded.__dict__)
        ens._streamed = lambda *a, **k: streamed            # the verdict from the streamed numbers
        _, t_post = cpu(lambda: ens.assess(path, time_ordered=False))
    finally:
        torch.set_num_threads(before)
    n = raw.shape[0]
    return [(k, 1e3 * v / n) for k, v in [("read (HDF5, gzip)", t_read), ("resample", t_res),
                                            ("windows + multitaper spectra", t_rep), ("domain normalisation", t_norm),
                                            ("order-check features", t_feat), ("one member's network", t_net),
                                            ("verdict (rule, agreement, order check)", t_post)]]


def timed(f, *args):
    t, c = time.perf_counter(), time.process_time()
    out = f(*args)
    return out, time.perf_counter() - t, time.process_time() - c


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ensemble", default=str(OUT / "pedestal_pitting_calibrated" / "assessor"))
    ap.add_argument("--records", default=str(OUT / "data" / "pedestal_pitting_test.h5"))
    ap.add_argument("--members", default="1,2,5")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    import torch

    from twin.transfer.ensemble import Ensemble

    ens_dir, path = Path(args.ensemble), Path(args.records)
    if not (ens_dir / "ensemble.json").is_file() or not path.is_file():
        raise SystemExit(f"no trained ensemble in {ens_dir} or no records {path}: run bench/pipeline_rigs.py first")
    loaded = Ensemble.load(ens_dir)
    counts = [int(v) for v in args.members.split(",")]
    print(f"Machine: {machine()}; torch {torch.__version__}, {torch.get_num_threads()} threads by default; "
          f"load average at the start {os.getloadavg()[0]:.1f}", flush=True)
    prof = stage_profile(loaded, path, args.repeats)
    print("CPU per window of each stage alone (1 thread, fastest of the repeats):", flush=True)
    for k, v in prof:
        print(f"  {k}: {v:.3f} ms")
    rows = []
    for m in counts:
        members = [loaded.members[i % len(loaded.members)] for i in range(m)]
        ref, fast = ensembles(loaded, members)
        pb = ref._raw(str(path))[0]                         # warm-up (and the numbers compared)
        pa = fast._raw(str(path))[0]
        n = pa.shape[1]
        same = bool(np.array_equal(pb.argmax(2), pa.argmax(2)))
        diff = float(np.abs(pb - pa).max())
        if m >= 2:
            rb, ra = (e.assess(path, time_ordered=False) for e in (ref, fast))
            same = same and np.array_equal(rb.window_stages, ra.window_stages) and \
                [r.stage for r in rb.records] == [r.stage for r in ra.records]
        runs = [("before", ref._raw, (str(path),)), ("after", fast._raw, (str(path),))]
        if m >= 2:
            runs += [("assess_before", ref.assess, (path,)), ("assess_after", fast.assess, (path,))]
        t = {k: [] for k, _, _ in runs}
        cpu = {k: [] for k in t}
        for _ in range(args.repeats):
            for k, f, a in runs:
                _, w, c = timed(f, *a)
                t[k].append(w)
                cpu[k].append(c)
        best = {k: 1e3 * min(v) / n for k, v in t.items() if v}
        best_cpu = {k: 1e3 * min(v) / n for k, v in cpu.items() if v}
        rows.append((m, n, best, best_cpu, same, diff))
        print(f"members {m}: {n} windows; before {best['before']:.2f}, after {best['after']:.2f} ms/window"
              + (f"; assess before {best['assess_before']:.2f}, after {best['assess_after']:.2f}" if m >= 2 else "")
              + f"; identical stages {same}, largest probability difference {diff:.1e}", flush=True)
    print(f"\nload average at the end {os.getloadavg()[0]:.1f}\n")
    print("| members | before [ms/window] | batched [ms/window] | ratio | CPU before -> batched [ms/window] | "
          "whole assess before -> batched [ms/window] | identical stages |")
    print("|---|---|---|---|---|---|---|")
    for m, n, b, c, same, diff in rows:
        whole = f"{b['assess_before']:.2f} -> {b['assess_after']:.2f} (CPU {c['assess_after']:.2f})" \
            if "assess_before" in b else ""
        print(f"| {m} | {b['before']:.2f} | {b['after']:.2f} | {b['before'] / b['after']:.1f}x | "
              f"{c['before']:.2f} -> {c['after']:.2f} | {whole} | {'yes' if same else 'NO'} ({diff:.0e}) |")


if __name__ == "__main__":
    main()
