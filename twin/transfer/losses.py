"""Losses of the domain adaptation model (paper Eq. 15-20).

* :func:`mmd_loss` -- Eq. 16, the squared maximum mean discrepancy between the source and target
  features in the RKHS of a *multi-kernel* Gaussian ``k(a, b) = mean_m exp(-|a - b|^2 / (2 s_m^2))``
  (biased V-statistic, exactly the three double sums of Eq. 16).  Bandwidths by the median
  heuristic: ``s_0^2 = median(|a - b|^2) / 2`` over the off-diagonal pairs of the pooled
  batch (detached: the bandwidth is a measurement, not something to optimise), and
  ``s_m^2 = s_0^2 * {1/4, 1/2, 1, 2, 4}`` so the kernel family covers distances between a half
  and twice the typical one.
* :func:`class_contrastive_loss` -- Eq. 17-18 with ``c = [y_s == y~_t]`` (Eq. 19): positive pairs
  are pulled together (``d``), negative pairs pushed to at least the margin (``max(0, m - d)``).
  ``d`` is the squared Euclidean distance between the *L2-normalised* features, in [0, 4], so
  the margin ``m`` (default 1, i.e. cosine similarity below 0.5 for different classes) does not
  depend on the feature scale.  By default every (source, confident target) pair of the batch is
  used (``pairs="all"``), the paper's i-th/i-th pairing is ``pairs="diagonal"``.  Eq. 18 *sums*
  the terms over the batch (``reduction="sum"``; with all pairs, each gated target window adds
  the mean of its terms with the source windows), so with batch 20 the paper's ``beta = 0.1``
  weighs the loss 20 times more than the mean over pairs (``reduction="mean"``) does.  The
  assessor keeps the mean by default: with the sum, wrong pseudo-labels lock in on a rig whose
  records do not fall into the twin's stages (``docs/experiments.md``).
* :func:`pseudo_label_gate` -- the target pseudo-labels ``y~_t`` that may enter Eq. 19: the
  classifier's arg-max, kept only where its probability is at least ``threshold`` and only from
  epoch ``warmup_epochs`` on, so that the early, mostly wrong labels cannot lock in.
* :func:`coral_loss` -- CORAL (Sun & Saenko 2016) as a cheap extra baseline.

All functions take torch tensors: features ``(n, d)``, labels ``(n,)`` int64, and return a
0-d tensor.
"""
from __future__ import annotations

import torch

from twin.transfer.errors import AssessorError

__all__ = ["BANDWIDTH_FACTORS", "class_contrastive_loss", "coral_loss", "gaussian_kernel", "median_bandwidth",
           "mmd_loss", "pseudo_label_gate"]

#: Multipliers of the median-heuristic squared bandwidth.
BANDWIDTH_FACTORS = (0.25, 0.5, 1.0, 2.0, 4.0)


def _check_features(a: torch.Tensor, b: torch.Tensor, name: str) -> None:
    if a.ndim != 2 or b.ndim != 2 or a.shape[1] != b.shape[1]:
        raise AssessorError(f"{name}: features must be (n, d) with equal d, got {tuple(a.shape)} and "
                            f"{tuple(b.shape)}")
    if a.shape[0] == 0 or b.shape[0] == 0:
        raise AssessorError(f"{name}: empty feature set ({tuple(a.shape)}, {tuple(b.shape)})")


def median_bandwidth(z: torch.Tensor) -> torch.Tensor:
    """Median heuristic: ``median(|z_i - z_j|^2, i != j) / 2`` (the squared bandwidth s^2), detached.

    Falls back to 1 when every point coincides (the kernel is then constant anyway).
    """
    with torch.no_grad():
        d2 = torch.cdist(z, z).pow(2)
        n = z.shape[0]
        off = d2[~torch.eye(n, dtype=torch.bool, device=z.device)]
        med = off.median() if off.numel() else torch.tensor(0.0, device=z.device)
        return torch.where(med > 0, med / 2, torch.ones_like(med))


def gaussian_kernel(a: torch.Tensor, b: torch.Tensor, s2: torch.Tensor,
                    factors=BANDWIDTH_FACTORS) -> torch.Tensor:
    """Multi-kernel Gaussian Gram matrix (n_a, n_b): mean over ``m`` of exp(-|a-b|^2 / (2 s2 f_m))."""
    d2 = (a.unsqueeze(1) - b.unsqueeze(0)).pow(2).sum(-1)     # exact, also for identical points
    return torch.stack([torch.exp(-d2 / (2 * s2 * f)) for f in factors]).mean(0)


def mmd_loss(source: torch.Tensor, target: torch.Tensor, s2: torch.Tensor | float | None = None,
             factors=BANDWIDTH_FACTORS) -> torch.Tensor:
    """Squared MMD of Eq. 16 (biased estimate, >= 0) between features (n1, d) and (n2, d).

    ``s2`` is the base squared bandwidth; ``None`` uses :func:`median_bandwidth` of the pooled set.
    """
    _check_features(source, target, "mmd_loss")
    if s2 is None:
        s2 = median_bandwidth(torch.cat([source, target]))
    s2 = torch.as_tensor(s2, dtype=source.dtype, device=source.device)
    kss = gaussian_kernel(source, source, s2, factors).mean()
    ktt = gaussian_kernel(target, target, s2, factors).mean()
    kst = gaussian_kernel(source, target, s2, factors).mean()
    return (kss + ktt - 2 * kst).clamp_min(0.0)


def pseudo_label_gate(probs: torch.Tensor, epoch: int, threshold: float, warmup_epochs: int
                      ) -> tuple[torch.Tensor, torch.Tensor]:
    """Pseudo-labels (n,) and the mask (n,) bool of those allowed into the contrastive loss.

    ``probs`` are the classifier's class probabilities (n, K) for target windows.  Nothing passes
    before ``epoch == warmup_epochs`` (epochs count from 0); afterwards a label passes when its
    probability is ``>= threshold``.
    """
    if probs.ndim != 2:
        raise AssessorError(f"pseudo_label_gate: probs must be (n, K), got {tuple(probs.shape)}")
    conf, labels = probs.max(dim=1)
    if epoch < warmup_epochs:
        return labels, torch.zeros_like(labels, dtype=torch.bool)
    return labels, conf >= threshold


def class_contrastive_loss(gs: torch.Tensor, ys: torch.Tensor, gt: torch.Tensor, yt: torch.Tensor,
                           mask: torch.Tensor | None = None, margin: float = 1.0, pairs: str = "all",
                           reduction: str = "mean") -> torch.Tensor:
    """Instance class-contrastive loss, Eq. 17-19 (0 if no pair is used).

    Parameters
    ----------
    gs, gt : (n_s, d), (n_t, d) source and target features (L2-normalised here).
    ys, yt : (n_s,), (n_t,) source labels and target pseudo-labels.
    mask : (n_t,) bool, target windows allowed in (the pseudo-label gate); default all.
    margin : m of Eq. 17, on the squared distance of unit vectors (0 < m <= 4).
    pairs : ``"all"`` every source/target pair, ``"diagonal"`` the i-th with the i-th (paper).
    reduction : ``"mean"`` over the pairs used; ``"sum"`` Eq. 18's sum over the target windows
        let in, where with ``pairs="all"`` each target window contributes the mean of its terms
        with the source windows (the expectation of its one diagonal term over the batch order),
        so both pairings give Eq. 18's magnitude.
    """
    _check_features(gs, gt, "class_contrastive_loss")
    if pairs not in ("all", "diagonal"):
        raise AssessorError(f"class_contrastive_loss: pairs must be 'all' or 'diagonal', got {pairs!r}")
    if reduction not in ("mean", "sum"):
        raise AssessorError(f"class_contrastive_loss: reduction must be 'mean' or 'sum', got {reduction!r}")
    if mask is None:
        mask = torch.ones(gt.shape[0], dtype=torch.bool, device=gt.device)
    a = torch.nn.functional.normalize(gs, dim=1)
    b = torch.nn.functional.normalize(gt, dim=1)
    if pairs == "diagonal":
        n = min(a.shape[0], b.shape[0])
        d = (a[:n] - b[:n]).pow(2).sum(1)
        same = ys[:n] == yt[:n]
        use = mask[:n]
    else:
        d = (a.unsqueeze(1) - b.unsqueeze(0)).pow(2).sum(-1)        # (n_s, n_t)
        same = ys.unsqueeze(1) == yt.unsqueeze(0)
        use = mask.unsqueeze(0).expand_as(d)
    if not bool(use.any()):
        return gs.sum() * 0.0          # keeps the graph, contributes nothing
    loss = torch.where(same, d, (margin - d).clamp_min(0.0))
    if reduction == "mean":
        return loss[use].mean()
    if pairs == "diagonal":
        return loss[use].sum()
    return loss.mean(0)[mask].sum()


def coral_loss(source: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """CORAL: ``|C_s - C_t|_F^2 / (4 d^2)`` between the feature covariances."""
    _check_features(source, target, "coral_loss")
    d = source.shape[1]

    def cov(x):
        xc = x - x.mean(0, keepdim=True)
        return xc.T @ xc / max(x.shape[0] - 1, 1)

    return (cov(source) - cov(target)).pow(2).sum() / (4 * d * d)
