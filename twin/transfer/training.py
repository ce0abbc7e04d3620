"""The assessor's training loop: network, optimiser, learning-rate schedule, batches, losses, history.

:meth:`twin.transfer.assessor.Assessor.fit` prepares and normalises the windows, calls
:func:`train_network` and stores what it returns; the class-prior match comes after training
(:mod:`twin.transfer.matching`).  The schedule and the losses are those of the assessor's docstring
(paper Table 3 and Eq. 15-20).

Determinism: :func:`train_network` seeds torch and numpy from ``params.seed`` and runs under
:func:`deterministic_torch`, so the same seed on the same machine gives bit-identical weights.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager

import numpy as np

from twin.transfer.preprocess import Augmentation, DomainNormaliser, Prepared, Preprocessing, augmented_windows

__all__ = ["deterministic_torch", "train_network"]


@contextmanager
def deterministic_torch(n_threads: int) -> Iterator[None]:
    """Torch on ``n_threads`` CPU threads with deterministic algorithms; the previous settings are
    restored on exit, also after an error or an interruption."""
    import torch
    prev_threads = torch.get_num_threads()
    prev_det = torch.are_deterministic_algorithms_enabled()
    torch.set_num_threads(n_threads)
    torch.use_deterministic_algorithms(True)
    try:
        yield
    finally:
        torch.set_num_threads(prev_threads)
        torch.use_deterministic_algorithms(prev_det)


def train_network(params, src: Sequence[Prepared], xs_fixed: np.ndarray, ys_fixed: np.ndarray, xt: np.ndarray,
                  n_classes: int, pre: Preprocessing, aug: Augmentation | None, source_normaliser: DomainNormaliser,
                  device, monitor: Callable[[object], float | None] | None = None):
    """Train G + C from ``params.seed`` and return ``(network, history, fit_time)``.

    Parameters
    ----------
    params : Assessor
        Its hyperparameters are read (``method``, ``alpha``, ``beta``, ``lr``, ``batch_size``,
        ``epochs``, ``threshold``, ``warmup_epochs``, ``margin``, ``pairs``,
        ``contrastive_reduction``, ``seed``, ``n_threads``, ``progress``), nothing is written.
    src : prepared source records
        Cut anew into augmented windows every epoch when ``aug`` is given.
    xs_fixed, ys_fixed : ndarray (n_s, window), (n_s,)
        The source windows (normalised) and stage labels; every epoch's windows without ``aug``.
    xt : ndarray (n_t, window)
        The target adaptation windows, normalised (unused by ``method="cnn"``).
    n_classes : int
        K, the stage count.
    source_normaliser : DomainNormaliser
        Applied to each epoch's augmented source windows.
    device : torch.device
    monitor : callable, optional
        ``monitor(network)`` after every epoch -> accuracy or None, stored as ``monitor_acc``;
        it must leave the network's mode as it found it and use no training randomness.

    Returns
    -------
    network : torch.nn.Module (in eval mode)
    history : list of dict, one per epoch (``epoch``, ``loss``, ``cls``, ``align``, ``con``,
        ``source_acc``, ``gate``, ``lr``; ``monitor_acc`` with ``monitor``)
    fit_time : float
        Wall time of the epoch loop [s].
    """
    import torch

    from twin._progress import progress_bar
    from twin.transfer.losses import class_contrastive_loss, coral_loss, mmd_loss, pseudo_label_gate
    from twin.transfer.model import Network

    p = params
    k = n_classes
    with deterministic_torch(p.n_threads):
        torch.manual_seed(int(p.seed))
        rng = np.random.default_rng(int(p.seed))
        net = Network(k, pre.window).to(device)
        opt = torch.optim.SGD(net.parameters(), lr=p.lr, momentum=0.9, weight_decay=5e-4)
        n_s = xs_fixed.shape[0]
        steps = math.ceil(n_s / p.batch_size)
        total = steps * p.epochs
        xt_t = torch.from_numpy(xt).unsqueeze(1).to(device)
        adapt = p.method != "cnn"
        history = []
        bar = progress_bar(p.epochs, p.progress, f"train {p.method}", "epoch")
        t_start = time.perf_counter()
        step = 0
        t_perm = rng.permutation(xt.shape[0])
        t_pos = 0
        for epoch in range(p.epochs):
            if aug is not None:
                xs, ys = augmented_windows(src, pre, aug, rng)
                xs = source_normaliser(xs)
            else:
                xs, ys = xs_fixed, ys_fixed
            xs_t = torch.from_numpy(xs).unsqueeze(1).to(device)
            ys_t = torch.from_numpy(ys.astype(np.int64)).to(device)
            perm = rng.permutation(n_s)
            net.train()
            sums = dict(loss=0.0, cls=0.0, align=0.0, con=0.0, correct=0, seen=0, gated=0, tseen=0)
            for b in range(steps):
                idx = torch.from_numpy(perm[b * p.batch_size:(b + 1) * p.batch_size])
                if idx.numel() < 2:         # a batch of one cannot be batch-normalised
                    continue
                lr = p.lr / (1 + 10 * step / total) ** 0.75
                for group in opt.param_groups:
                    group["lr"] = lr
                xb, yb = xs_t[idx], ys_t[idx]
                align = con = torch.zeros((), device=device)
                if adapt:
                    if t_pos + idx.numel() > len(t_perm):
                        t_perm, t_pos = rng.permutation(xt.shape[0]), 0
                    tidx = torch.from_numpy(t_perm[t_pos:t_pos + idx.numel()])
                    t_pos += idx.numel()
                    g, logits = net(torch.cat([xb, xt_t[tidx]]))
                    gs, gt = g[: idx.numel()], g[idx.numel():]
                    ls, lt = logits[: idx.numel()], logits[idx.numel():]
                    align = coral_loss(gs, gt) if p.method == "coral" else mmd_loss(gs, gt)
                    if p.method == "proposed":
                        pt = torch.softmax(lt.detach(), dim=1)
                        yt, mask = pseudo_label_gate(pt, epoch, p.threshold, p.warmup_epochs)
                        con = class_contrastive_loss(gs, yb, gt, yt, mask, p.margin, p.pairs,
                                                     p.contrastive_reduction)
                        sums["gated"] += int(mask.sum())
                        sums["tseen"] += int(mask.numel())
                else:
                    _, ls = net(xb)
                cls = torch.nn.functional.cross_entropy(ls, yb)
                loss = cls + p.alpha * align + (p.beta * con if p.method == "proposed" else 0.0)
                opt.zero_grad(set_to_none=True)
                loss.backward()
                opt.step()
                step += 1
                n_b = idx.numel()
                sums["loss"] += float(loss.detach()) * n_b
                sums["cls"] += float(cls.detach()) * n_b
                sums["align"] += float(align.detach()) * n_b
                sums["con"] += float(con.detach()) * n_b
                sums["correct"] += int((ls.argmax(1) == yb).sum())
                sums["seen"] += n_b
            seen = max(sums["seen"], 1)
            rec = {"epoch": epoch + 1, "loss": sums["loss"] / seen, "cls": sums["cls"] / seen,
                   "align": sums["align"] / seen, "con": sums["con"] / seen,
                   "source_acc": sums["correct"] / seen,
                   "gate": sums["gated"] / sums["tseen"] if sums["tseen"] else 0.0, "lr": lr}
            if monitor is not None:
                rec["monitor_acc"] = monitor(net)
            history.append(rec)
            bar.update(1)
        bar.close()
        fit_time = time.perf_counter() - t_start
    net.eval()
    return net, history, fit_time
