"""Figures and HTML of the transfer-learning assessor: confusion matrices, t-SNE of the high-level
features (source and target, one panel per method), learning curves, and the report of one
assessment (:func:`write_assessment_report`, ``twin assess --report``).

Every file is written atomically (:func:`twin._atomic.atomic_path`); figures are PNG (Agg
backend, no display needed).  The HTML page embeds the PNGs by relative path.
"""
from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["confusion_matrix", "plot_confusion", "plot_learning_curves", "plot_record_stages", "plot_tsne",
           "write_assessment_report", "write_html"]


def confusion_matrix(y_true: np.ndarray, y_pred: np.ndarray, n_classes: int) -> np.ndarray:
    """Counts (K, K): row = true stage, column = predicted stage."""
    y_true, y_pred = np.asarray(y_true), np.asarray(y_pred)
    if y_true.shape != y_pred.shape:
        raise AssessorError(f"confusion_matrix: shapes differ, {y_true.shape} vs {y_pred.shape}")
    bad = sorted({int(v) for v in np.concatenate([y_true, y_pred]) if not 0 <= v < n_classes})
    if bad:
        raise AssessorError(f"confusion_matrix: label(s) {bad} outside 0..{n_classes - 1}")
    cm = np.zeros((n_classes, n_classes), dtype=int)
    np.add.at(cm, (y_true.astype(int), y_pred.astype(int)), 1)
    return cm


def _save(fig, path: Path) -> Path:
    from twin._atomic import atomic_path
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    import matplotlib.pyplot as plt
    plt.close(fig)
    return path


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_confusion(matrices: Mapping[str, np.ndarray], path: str | Path, title: str = "") -> Path:
    """One panel per entry (name -> (K, K) counts), rows normalised to per-stage rates in %."""
    plt = _plt()
    fig, axes = plt.subplots(1, len(matrices), figsize=(4.2 * len(matrices), 3.8), squeeze=False)
    for ax, (name, cm) in zip(axes[0], matrices.items()):
        cm = np.asarray(cm, dtype=float)
        rate = 100 * cm / np.maximum(cm.sum(1, keepdims=True), 1)
        ax.imshow(rate, vmin=0, vmax=100, cmap="Blues")
        k = cm.shape[0]
        for i in range(k):
            for j in range(k):
                ax.text(j, i, f"{rate[i, j]:.0f}", ha="center", va="center", fontsize=8,
                        color="white" if rate[i, j] > 60 else "black")
        acc = 100 * np.trace(cm) / max(cm.sum(), 1)
        ax.set_title(f"{name}: {acc:.1f} %")
        ax.set_xlabel("predicted stage")
        ax.set_ylabel("true stage")
        ax.set_xticks(range(k))
        ax.set_yticks(range(k))
    if title:
        fig.suptitle(title)
    return _save(fig, Path(path))


def plot_tsne(panels: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray]], path: str | Path,
              title: str = "") -> Path:
    """t-SNE panels: name -> (embedding (n, 2), stage (n,), is_target (n,) bool).

    Colour = stage, marker = domain (o source, x target)."""
    plt = _plt()
    fig, axes = plt.subplots(1, len(panels), figsize=(4.5 * len(panels), 4.2), squeeze=False)
    cmap = plt.get_cmap("viridis")
    for ax, (name, (emb, stage, is_target)) in zip(axes[0], panels.items()):
        k = int(stage.max()) + 1
        for dom, marker, alpha in ((False, "o", 0.35), (True, "x", 0.9)):
            m = is_target == dom
            ax.scatter(emb[m, 0], emb[m, 1], c=stage[m], cmap=cmap, vmin=0, vmax=max(k - 1, 1), marker=marker,
                       s=12, alpha=alpha, label="target (rig)" if dom else "source (twin)")
        ax.set_title(name)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.legend(loc="best", fontsize=7)
    if title:
        fig.suptitle(title + "  (colour = stage)")
    return _save(fig, Path(path))


def plot_learning_curves(histories: Mapping[str, Sequence[Mapping]], path: str | Path, title: str = "") -> Path:
    """Per method: training losses (left) and accuracies (right: source batches, monitored target)."""
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.8))
    for i, (name, hist) in enumerate(histories.items()):
        c = f"C{i}"
        ep = [h["epoch"] for h in hist]
        a1.plot(ep, [h["cls"] for h in hist], color=c, label=f"{name} CE")
        if any(h["align"] for h in hist):
            a1.plot(ep, [h["align"] for h in hist], color=c, ls="--", label=f"{name} MMD/CORAL")
        if any(h["con"] for h in hist):
            a1.plot(ep, [h["con"] for h in hist], color=c, ls=":", label=f"{name} contrastive")
        a2.plot(ep, [100 * h["source_acc"] for h in hist], color=c, ls="--", label=f"{name} source (train)")
        if hist and hist[0].get("monitor_acc") is not None:
            a2.plot(ep, [100 * h["monitor_acc"] for h in hist], color=c, label=f"{name} target test (monitor only)")
    a1.set_xlabel("epoch")
    a1.set_ylabel("loss")
    a1.set_yscale("log")
    a1.legend(fontsize=7)
    a2.set_xlabel("epoch")
    a2.set_ylabel("accuracy [%]")
    a2.set_ylim(0, 100)
    a2.legend(fontsize=7)
    if title:
        fig.suptitle(title)
    return _save(fig, Path(path))


def write_html(path: str | Path, title: str, blocks: Sequence[tuple[str, str]]) -> Path:
    """A self-contained page: blocks of (heading, body); a body ending in ``.png`` is an image,
    anything else is shown as preformatted text (escaped)."""
    from twin._atomic import atomic_path
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
             "<style>body{font-family:sans-serif;max-width:1300px;margin:auto} img{max-width:100%}"
             " pre{background:#f4f4f4;padding:8px}</style></head><body>", f"<h1>{html.escape(title)}</h1>"]
    for head, body in blocks:
        parts.append(f"<h2>{html.escape(head)}</h2>")
        if body.endswith(".png"):
            parts.append(f"<img src='{html.escape(body)}' alt='{html.escape(head)}'>")
        else:
            parts.append(f"<pre>{html.escape(body)}</pre>")
    parts.append("</body></html>")
    with atomic_path(path) as tmp:
        Path(tmp).write_text("\n".join(parts), encoding="utf-8")
    return Path(path)


def plot_record_stages(assessment, path: str | Path, title: str = "") -> Path:
    """Stage probabilities of every record of ``assessment`` (a
    :class:`~twin.transfer.assessor.Assessment`): one row per record, one column per stage, the
    record's mean over its windows in colour; a dot marks the assessed stage and, where the record
    has a label, a cross the true one.  Records stay in their file order, so a time-ordered series
    reads as a history from top to bottom."""
    plt = _plt()
    recs = assessment.records
    if not recs:
        raise AssessorError("plot_record_stages: the assessment holds no record")
    proba = np.array([r.probabilities for r in recs])
    n, k = proba.shape
    fig, ax = plt.subplots(figsize=(1.1 * k + 3.0, min(0.22 * n + 1.6, 40.0)))
    im = ax.imshow(proba, vmin=0, vmax=1, cmap="Blues", aspect="auto", interpolation="nearest")
    rows = np.arange(n)
    ax.scatter([r.stage for r in recs], rows, s=14, c="C1", label="assessed stage", zorder=3)
    known = [(i, r.label) for i, r in enumerate(recs) if r.label is not None]
    if known:
        ax.scatter([lab for _, lab in known], [i for i, _ in known], s=40, marker="x", c="C3", label="true stage",
                   zorder=4)
    ax.set_xticks(range(k))
    ax.set_xlabel("stage")
    ax.set_yticks(rows if n <= 60 else rows[:: int(np.ceil(n / 60))])
    ax.set_yticklabels([recs[i].name for i in ax.get_yticks().astype(int)], fontsize=7)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=2, fontsize=7, frameon=False)
    fig.colorbar(im, ax=ax, label="mean stage probability")
    if title:
        ax.set_title(title, pad=20)
    return _save(fig, Path(path))


def write_assessment_report(assessment, directory: str | Path, title: str = "Wear-stage assessment") -> Path:
    """Write ``stages.png`` (:func:`plot_record_stages`), ``confusion.png`` (windows, only when every
    record has a label) and ``report.html`` (both figures and the table of records) into
    ``directory``, created if its parent exists.  Returns the HTML page's path.

    Raises
    ------
    OutputPathError
        A missing parent directory, or ``directory`` is a file.
    """
    from twin._atomic import check_output_dir
    d = check_output_dir(directory, "report", create=True)
    blocks = [("Stage probabilities per record", plot_record_stages(assessment, d / "stages.png", title).name)]
    if assessment.window_accuracy is not None:
        cm = confusion_matrix(*assessment.window_verdicts(), assessment.n_stages)
        plot_confusion({"windows": cm}, d / "confusion.png", "true against assessed stage, per window")
        blocks.append((f"Confusion matrix (records {100 * assessment.record_accuracy:.1f} %, windows "
                       f"{100 * assessment.window_accuracy:.1f} %)", "confusion.png"))
    lines = [f"{'record':<16} {'stage':>5} {'confidence':>10} {'windows':>7} {'label':>5}"]
    for r in assessment.records:
        lines.append(f"{r.name:<16} {r.stage:>5d} {r.confidence:>10.2f} {len(r.window_stages):>7d} "
                     f"{'' if r.label is None else r.label:>5}")
    blocks.append(("Records", "\n".join(lines)))
    return write_html(d / "report.html", title, blocks)
