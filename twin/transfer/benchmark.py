"""The transfer benchmark: CNN, MMD and the proposed assessor side by side, over seeds.

The data of each task (the twin's archive as source, a rig's records as target) are built and
cached by :mod:`twin.transfer.benchmark_data`, whose names are importable from here too.

Protocol (see ``twin/transfer/README.md``): each target record is cut in two halves; the first
halves (unlabelled) are the adaptation set handed to ``fit``, the second halves are the test
set.  Hyperparameters are the paper's and fixed; the model after the last epoch is scored;
target labels are read only by the scoring code.  Each seed seeds the network initialisation,
batch order and augmentation; the data stay the same across seeds.
"""
from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from twin.errors import ParameterError
from twin.transfer.benchmark_data import (ARCHIVE_RULES, CHANNEL, METHODS, REPO, RIG_SEEDS, RIGS,  # noqa: F401
                                          TASK_CLASS_PRIOR, TASK_REMOVE_LEVEL, TASK_SETTINGS, TASKS, WHEEL_MODEL,
                                          DataSettings, _check_rig, _target_halves, _unlabelled, load_task_data,
                                          prepare_task, rig_settings, task_preprocessing, task_scenario)


@dataclass(frozen=True)
class RunResult:
    """One (task, method, seed) training run, scored on the held-out target halves."""

    task: str
    method: str
    seed: int
    window_accuracy: float          # target test windows
    record_accuracy: float          # target test half-records (mean window probability)
    source_accuracy: float          # source windows, no augmentation (training data)
    fit_time: float                 # s, training loop
    confusion: list                 # (K, K) target test windows
    history: list
    embedding: dict = field(default_factory=dict)     # features for t-SNE (first seed only)
    class_prior_drop: float | None = None   # fit's class_prior_confidence_drop_; None without a match (CNN)
    window_stages: tuple = ()       # (n_windows,) assessed stage of each target test window, record by record


def train_one(task: str, method: str, seed: int, source: str, target: str, epochs: int = 80,
              with_features: bool = False, monitor: bool = True) -> RunResult:
    """Fit one assessor with the paper's settings and score it on the target test halves."""
    from twin.transfer.assessor import Assessor
    from twin.transfer.report import confusion_matrix

    a = Assessor(method, epochs=epochs, seed=seed, preprocessing=task_preprocessing(task), progress=False,
                 class_prior=TASK_CLASS_PRIOR[task])
    s, adapt, test = load_task_data(task, source, target, a._pre.sample_rate)
    a.fit(s, adapt, monitor=(test, None) if monitor else None)
    asm = a.assess(test)
    y, p = asm.window_verdicts()
    src_acc = a.score(s) if a._pre.normalise != "domain" else float(np.mean(a.predict(s, domain="source")
                                                                             == [r.label for r in s]))
    emb = {}
    if with_features:
        rng = np.random.default_rng(0)
        fs = a.transform(s, domain="source")
        from twin.transfer.preprocess import prepare, windows_of
        _, _, ys = windows_of(prepare(s, a._pre), a._pre)
        pick = rng.choice(fs.shape[0], size=min(300, fs.shape[0]), replace=False)
        emb = {"source": fs[pick], "source_stage": ys[pick], "target": a.transform(test), "target_stage": y}
    return RunResult(task, method, seed, float(np.mean(y == p)), float(asm.record_accuracy),
                     float(src_acc), float(a.fit_time_), confusion_matrix(y, p, a.n_classes_).tolist(),
                     a.history_, emb,
                     a.class_prior_confidence_drop_ if method != "cnn" and a.class_prior is not None else None,
                     tuple(int(v) for v in p))


def source_ceiling(task: str, source: str, seed: int, epochs: int = 80) -> float:
    """Window accuracy of the source-only CNN on *held-out source records* (every other record
    of each stage is held out; the rest train it).

    No domain shift at all, so this is what the twin's own stages allow across records (damage
    and operating scatter within a stage): a reference for how far any transfer can go.
    """
    from twin.measurements import load_measurements
    from twin.transfer.assessor import Assessor

    a = Assessor("cnn", epochs=epochs, seed=seed, preprocessing=task_preprocessing(task), progress=False)
    recs = list(load_measurements(source, channels=[CHANNEL], resample_to=a._pre.sample_rate).records)
    by_stage: dict = {}
    for r in recs:
        by_stage.setdefault(r.label, []).append(r)
    train = [r for rs in by_stage.values() for r in rs[0::2]]
    held = [r for rs in by_stage.values() for r in rs[1::2]]
    a.fit(train, _unlabelled(held))
    return a.score(held)


def target_ceiling(task: str, target: str, seed: int, epochs: int = 80) -> float:
    """Window accuracy on the target test halves of a CNN trained *on the rig's own labels*.

    The same network, preprocessing and augmentation as the benchmark's, trained with the stage
    labels of the target adaptation halves (which no transfer method may read) and tested on the
    second halves.  No domain shift and the rig's full information: how well this network can
    tell the stages apart on this rig at all.  A transfer result near it has little left to gain;
    a target above it asks the rig for more than its records hold.
    """
    from twin.transfer.assessor import Assessor

    a = Assessor("cnn", epochs=epochs, seed=seed, preprocessing=task_preprocessing(task), progress=False)
    adapt, test = _target_halves(target, a._pre.sample_rate)
    a.fit(adapt, _unlabelled(adapt))
    return a.score(test)


def _star(job):
    """``fn(*args)`` for ``job = (fn, *args)``: a pool's map takes one argument per job."""
    fn, *args = job
    return fn(*args)


# ---- the whole benchmark --------------------------------------------------------------------------
def summarise(results: list[RunResult]) -> dict:
    """Mean and std (ddof 1) per task and method; paired differences between methods over seeds."""
    from scipy.stats import ttest_rel

    out: dict = {}
    for task in sorted({r.task for r in results}):
        rows = {}
        for m in [m for m in ("cnn", "mmd", "coral", "proposed") if any(r.method == m and r.task == task
                                                                          for r in results)]:
            rs = sorted((r for r in results if r.task == task and r.method == m), key=lambda r: r.seed)
            acc = np.array([r.window_accuracy for r in rs])
            rec = np.array([r.record_accuracy for r in rs])
            t = np.array([r.fit_time for r in rs])
            order = [stage_order_scores(r.confusion) for r in rs]
            rows[m] = {"seeds": [r.seed for r in rs], "window_acc": acc.tolist(), "record_acc": rec.tolist(),
                       "mean": float(acc.mean()), "std": float(acc.std(ddof=1)) if acc.size > 1 else 0.0,
                       "record_mean": float(rec.mean()),
                       "record_std": float(rec.std(ddof=1)) if rec.size > 1 else 0.0,
                       "source_acc_mean": float(np.mean([r.source_accuracy for r in rs])),
                       "within_one_mean": float(np.mean([o[0] for o in order])),
                       "spearman_mean": float(np.nanmean([o[1] for o in order])) if any(
                           np.isfinite(o[1]) for o in order) else float("nan"),
                       "fit_time_mean": float(t.mean()), "fit_time_max": float(t.max()),
                       "class_prior_warnings": _warnings(rs), "seed_agreement": _seed_agreement(rs)}
        pairs = {}
        for a, b in (("cnn", "mmd"), ("mmd", "proposed"), ("cnn", "proposed")):
            if a in rows and b in rows and rows[a]["seeds"] == rows[b]["seeds"]:
                d = np.array(rows[b]["window_acc"]) - np.array(rows[a]["window_acc"])
                p = float(ttest_rel(rows[b]["window_acc"], rows[a]["window_acc"]).pvalue) if d.size > 1 and d.std() > 0 else None
                pairs[f"{b}-{a}"] = {"mean_diff": float(d.mean()), "wins": int((d > 0).sum()), "n": int(d.size),
                                     "paired_t_p": p}
        out[task] = {"methods": rows, "paired": pairs}
    return out


def _seed_agreement(runs: list[RunResult]) -> float | None:
    """Mean pairwise share of target test windows that two seeds assess alike
    (:mod:`twin.transfer.reliability`); None with fewer than two seeds or without the stages."""
    from twin.transfer.reliability import mean_agreement
    stages = [r.window_stages for r in runs]
    if len(stages) < 2 or not stages[0] or any(len(s) != len(stages[0]) for s in stages):
        return None
    return mean_agreement(np.array(stages, dtype=np.int64))


def _warnings(runs: list[RunResult]) -> int | None:
    """How many runs' class-prior match passed fit's warning threshold; None when none had a match."""
    from twin.transfer.assessor import class_prior_warns
    drops = [r.class_prior_drop for r in runs if r.class_prior_drop is not None]
    return sum(class_prior_warns(d) for d in drops) if drops else None


def stage_order_scores(confusion) -> tuple[float, float]:
    """(share of windows within one stage of the truth, Spearman rank correlation of true and assessed
    stage) of a confusion matrix (K, K), rows true, columns assessed.

    Stages are ordered, so a verdict one stage off is a different failure from a random one: a rig
    whose damage shows more strongly than the twin's is read a stage too late, in the right order.
    The correlation is NaN when either stage sequence is constant.
    """
    from scipy.stats import spearmanr

    c = np.asarray(confusion, dtype=np.int64)
    if c.ndim != 2 or c.shape[0] != c.shape[1] or c.sum() <= 0 or (c < 0).any():
        raise ParameterError(f"a confusion matrix must be square with non-negative counts, got shape {c.shape}")
    i, j = np.indices(c.shape)
    within = float(c[np.abs(i - j) <= 1].sum() / c.sum())
    true, assessed = np.repeat(i.ravel(), c.ravel()), np.repeat(j.ravel(), c.ravel())
    if np.ptp(true) == 0 or np.ptp(assessed) == 0:
        return within, float("nan")
    return within, float(spearmanr(true, assessed).statistic)


def markdown_table(summary: dict) -> str:
    """The figures as a Markdown table (accuracy in %, mean +- std over seeds)."""
    lines = ["| task | method | target test windows [%] | target test records [%] | source (train) [%] | "
             "fit time mean / max [s] | within one stage [%] | rank correlation | class-prior warnings | "
             "seed agreement [%] (accuracy bound) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for task, s in summary.items():
        for m, r in s["methods"].items():
            # summaries written before the stage-order columns lack them
            within, rho = r.get("within_one_mean", float("nan")), r.get("spearman_mean", float("nan"))
            warned = r.get("class_prior_warnings")      # absent in older results, None without a match
            warned = "n/a" if warned is None else f"{warned}/{len(r['seeds'])}"
            agree = r.get("seed_agreement")     # absent in older results, None with one seed
            agree = "n/a" if agree is None else f"{100 * agree:.1f} ({100 * (1 + agree) / 2:.1f})"
            lines.append(f"| {task} | {m} | {100 * r['mean']:.1f} +- {100 * r['std']:.1f} | "
                         f"{100 * r['record_mean']:.1f} +- {100 * r['record_std']:.1f} | "
                         f"{100 * r['source_acc_mean']:.1f} | {r['fit_time_mean']:.0f} / {r['fit_time_max']:.0f} | "
                         f"{'n/a' if np.isnan(within) else f'{100 * within:.1f}'} | "
                         f"{'n/a' if np.isnan(rho) else f'{rho:.2f}'} | {warned} | {agree} |")
    lines += ["", "| task | comparison | mean gain [points] | seeds won | paired t-test p |", "|---|---|---|---|---|"]
    for task, s in summary.items():
        for k, d in s["paired"].items():
            p = "n/a" if d["paired_t_p"] is None else f"{d['paired_t_p']:.2g}"
            lines.append(f"| {task} | {k} | {100 * d['mean_diff']:+.1f} | {d['wins']}/{d['n']} | {p} |")
    return "\n".join(lines)


def seed_range(seeds: int, first_seed: int = 0) -> range:
    """The seeds of a run, ``first_seed .. first_seed + seeds - 1``; ParameterError names a bad count or start."""
    if isinstance(seeds, bool) or not isinstance(seeds, int) or seeds < 1:
        raise ParameterError(f"seeds must be a positive integer, got {seeds!r}")
    if isinstance(first_seed, bool) or not isinstance(first_seed, int) or first_seed < 0:
        raise ParameterError(f"first_seed must be an integer >= 0, got {first_seed!r}")
    return range(first_seed, first_seed + seeds)


def training_jobs(tasks: tuple[str, ...], methods: tuple[str, ...], seeds: range,
                  paths: dict[str, tuple[Path, Path]], epochs: int) -> list[tuple]:
    """The ``train_one`` calls of a benchmark over ``seeds`` (a :func:`seed_range`).

    The first seed also returns features for the t-SNE and monitors the target test accuracy per
    epoch for the learning curves (monitoring only: it never feeds back into training).
    """
    return [(train_one, t, m, s, str(paths[t][0]), str(paths[t][1]), epochs, s == seeds[0], s == seeds[0])
            for t in tasks for s in seeds for m in methods]


def run_benchmark(out: str | Path, *, tasks: tuple[str, ...] = ("pitting", "wear"), seeds: int = 5,
                  methods: tuple[str, ...] = METHODS, epochs: int = 80, jobs: int = 2,
                  data_dir: str | Path | None = None, settings: dict[str, DataSettings] | None = None,
                  rig: str = "rig", progress: bool = True, first_seed: int = 0,
                  targets: dict[str, str | Path] | None = None) -> dict:
    """Run every (task, method, seed), write ``results.json``, ``summary.md``, figures and
    ``report.html`` into ``out``; return the summary (see :func:`summarise`).

    The seeds are ``first_seed .. first_seed + seeds - 1``: ``first_seed=5, seeds=5`` adds seeds
    5-9 to an earlier 5-seed run without repeating it (each seed gives the same run on the same
    machine, so the two ``results.json`` can be pooled).

    ``jobs`` training runs go in parallel, each in its own process on one torch thread (so the
    fit times are single-core times).  ``rig`` picks the rig for the tasks whose ``settings`` are
    not given: an emulated rig (:data:`RIGS`), simulated here, or the name of another rig, whose
    records ``targets`` gives per task (a measurement file each, e.g. written by a simulator of
    ``rigs/``).
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    from twin._progress import progress_bar
    from twin.errors import OutputPathError

    out = Path(out)
    _check_rig(rig)
    if not out.parent.is_dir():
        raise OutputPathError(f"output directory '{out.parent}' does not exist (for '{out}')")
    bad = [t for t in tasks if t not in TASKS] + [m for m in methods if m not in METHODS + ("coral",)]
    if bad:
        raise ParameterError(f"unknown task or method {bad[0]!r}; tasks: {', '.join(TASKS)}; "
                             f"methods: cnn, mmd, proposed, coral")
    run_seeds = seed_range(seeds, first_seed)
    settings = {t: (settings or {}).get(t) or rig_settings(t, rig) for t in tasks}
    targets = dict(targets or {})
    for t in tasks:
        if (settings[t].rig in RIGS) == (t in targets):
            raise ParameterError(f"task {t!r} on rig {settings[t].rig!r}: give a target file exactly when the rig "
                                 f"is not emulated here ({', '.join(RIGS)})")
        if t in targets and not Path(targets[t]).is_file():
            raise ParameterError(f"target records '{targets[t]}' of task {t!r} do not exist")
    out.mkdir(exist_ok=True)        # only once every argument is known good: a typo leaves no trace
    data_dir = Path(data_dir) if data_dir is not None else out / "data"
    data_dir.mkdir(exist_ok=True)
    paths = {t: prepare_task(t, data_dir, settings[t], progress=progress, target=targets.get(t)) for t in tasks}
    jobs_list = training_jobs(tasks, methods, run_seeds, paths, epochs)
    bar = progress_bar(len(jobs_list), progress, "transfer benchmark", "run")
    results: list[RunResult] = []
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn")) as pool:
        for r in pool.map(_star, jobs_list):
            results.append(r)
            bar.update(1)
    bar.close()
    wall = time.perf_counter() - t0
    summary = summarise(results)
    _write_outputs(out, results, summary, epochs, wall, settings, run_seeds[0])
    return summary


def _write_outputs(out: Path, results: list[RunResult], summary: dict, epochs: int, wall: float,
                   settings: dict[str, DataSettings], first_seed: int) -> None:
    # The figures show the run's first seed: only its jobs returned features and learning curves
    # (training_jobs).
    from twin._atomic import atomic_path
    from twin.transfer import report
    from twin.transfer.tsne import tsne

    table = markdown_table(summary)
    blocks = [("Summary (target test = second halves of the rig records; last epoch; "
               f"{epochs} epochs; wall time {wall:.0f} s)", table)]
    for task in summary:
        first = {r.method: r for r in results if r.task == task and r.seed == first_seed}
        cm = report.plot_confusion({m: np.array(r.confusion) for m, r in first.items()},
                                   out / f"confusion_{task}.png", f"{task}: target test windows, seed {first_seed}")
        lc = report.plot_learning_curves({m: r.history for m, r in first.items()}, out / f"curves_{task}.png",
                                         f"{task}: learning curves, seed {first_seed}")
        panels = {}
        for m, r in first.items():
            e = r.embedding
            if not e:
                continue
            x = np.concatenate([e["source"], e["target"]])
            emb = tsne(x, seed=0)
            panels[m] = (emb, np.concatenate([e["source_stage"], e["target_stage"]]),
                         np.r_[np.zeros(len(e["source"]), bool), np.ones(len(e["target"]), bool)])
        blocks += [(f"{task}: confusion matrices", cm.name), (f"{task}: learning curves", lc.name)]
        if panels:
            ts = report.plot_tsne(panels, out / f"tsne_{task}.png", f"{task}: t-SNE of G features, seed {first_seed}")
            blocks.append((f"{task}: t-SNE", ts.name))
    report.write_html(out / "report.html", "Transfer benchmark: CNN vs MMD vs proposed", blocks)
    payload = {"summary": summary, "epochs": epochs, "wall_time": wall, "data": {t: asdict(v) for t, v in settings.items()},
               "runs": [{k: v for k, v in asdict(r).items() if k != "embedding"} for r in results]}
    with atomic_path(out / "results.json") as tmp:
        Path(tmp).write_text(json.dumps(payload, indent=1))
    with atomic_path(out / "summary.md") as tmp:
        Path(tmp).write_text(table + "\n")
