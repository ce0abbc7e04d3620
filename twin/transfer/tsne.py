"""A small exact t-SNE (van der Maaten & Hinton 2008) in numpy, for the feature plots.

scikit-learn is not a dependency, so this implements the original algorithm directly:

1. PCA to at most ``pca_dims`` (50) dimensions, which removes noise directions and makes the
   distances cheaper;
2. per-point Gaussian conditional probabilities with the bandwidth found by bisection so that the
   perplexity is ``perplexity`` (30), symmetrised ``P = (P_j|i + P_i|j) / 2n``;
3. Student-t similarities ``Q`` in 2-D; gradient descent on KL(P || Q) with momentum 0.5 then 0.8,
   per-coordinate adaptive gains, and early exaggeration 12 for the first 250 of ``n_iter`` (750)
   iterations.

Exact means O(n^2) memory and time per iteration: fine up to a few thousand points (1 000 points
take a few seconds).  Initialisation is seeded (``seed``), so the embedding is reproducible.
"""
from __future__ import annotations

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["tsne"]


def _conditional_p(d2: np.ndarray, perplexity: float, tol: float = 1e-5, max_iter: int = 64) -> np.ndarray:
    """Row-wise P_j|i (n, n) from squared distances, bandwidth by bisection on the entropy."""
    n = d2.shape[0]
    target = np.log(perplexity)
    p = np.zeros((n, n))
    for i in range(n):
        di = np.delete(d2[i], i)
        lo, hi, beta = 0.0, np.inf, 1.0
        for _ in range(max_iter):
            e = np.exp(-(di - di.min()) * beta)
            s = e.sum()
            h = np.log(s) + beta * np.sum((di - di.min()) * e) / s      # entropy in nats
            if abs(h - target) < tol:
                break
            if h > target:
                lo, beta = beta, beta * 2 if hi == np.inf else (beta + hi) / 2
            else:
                hi, beta = beta, (beta + lo) / 2
        p[i, np.arange(n) != i] = e / s
    return p


def tsne(x: np.ndarray, *, perplexity: float = 30.0, n_iter: int = 750, pca_dims: int = 50,
         learning_rate: float | None = None, seed: int = 0) -> np.ndarray:
    """2-D embedding (n, 2) of points ``x`` (n, d).

    Raises
    ------
    AssessorError
        ``x`` not 2-D, non-finite, or with fewer than 5 points.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[0] < 5:
        raise AssessorError(f"tsne: need an (n >= 5, d) array, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise AssessorError("tsne: non-finite values in the input")
    n = x.shape[0]
    perplexity = min(perplexity, (n - 1) / 3)
    xc = x - x.mean(0)
    if xc.shape[1] > pca_dims:
        _, _, vt = np.linalg.svd(xc, full_matrices=False)
        xc = xc @ vt[:pca_dims].T
    sq = (xc ** 2).sum(1)
    d2 = np.maximum(sq[:, None] + sq[None, :] - 2 * xc @ xc.T, 0.0)
    p = _conditional_p(d2, perplexity)
    p = np.maximum((p + p.T) / (2 * n), 1e-12)
    rng = np.random.default_rng(seed)
    y = rng.normal(0.0, 1e-4, size=(n, 2))
    lr = learning_rate if learning_rate is not None else max(n / 12 / 4, 50.0)   # Belkina et al. 2019
    update = np.zeros_like(y)
    gains = np.ones_like(y)
    for it in range(n_iter):
        exag = 12.0 if it < 250 else 1.0
        sy = (y ** 2).sum(1)
        num = 1.0 / (1.0 + sy[:, None] + sy[None, :] - 2 * y @ y.T)
        np.fill_diagonal(num, 0.0)
        q = np.maximum(num / num.sum(), 1e-12)
        pq = (exag * p - q) * num
        grad = 4.0 * ((np.diag(pq.sum(1)) - pq) @ y)
        momentum = 0.5 if it < 250 else 0.8
        gains = np.where(np.sign(grad) != np.sign(update), gains + 0.2, gains * 0.8).clip(0.01)
        update = momentum * update - lr * gains * grad
        y = y + update
        y = y - y.mean(0)
    return y
