"""The transfer-learning wear assessor (paper section 2.3), with its baselines in one code path.

::

    from twin.transfer import Assessor
    a = Assessor(method="proposed", seed=0).fit("archive.h5", "rig.h5")   # rig labels never read
    a.predict("rig_new.h5")            # stage per record; a.assess(...) adds confidences per window
    a.save("assessor/"); Assessor.load("assessor/").predict(...)        # identical numbers
    a.rematch("rig.h5", class_prior=None)   # the same network staged without the class-prior match

Methods (``method=``):

* ``"cnn"`` -- source only: G + C trained with the cross-entropy of Eq. 15 on the twin's data;
  target data are not used at all (also not in the batch-norm statistics).
* ``"mmd"`` -- Eq. 15 + ``alpha`` * multi-kernel MMD (Eq. 16) between source and target features.
* ``"proposed"`` -- Eq. 20: Eq. 15 + ``alpha`` * MMD + ``beta`` * class-contrastive loss (Eq. 17-19)
  on gated target pseudo-labels (see :func:`twin.transfer.losses.pseudo_label_gate`).
* ``"coral"`` -- Eq. 15 + ``alpha`` * CORAL, a cheap extra baseline.

Every method that adapts (all but ``"cnn"``) ends with a **class-prior match**
(``class_prior="source"``, :mod:`twin.transfer.prior`): per-stage logit offsets, fitted on the
unlabelled adaptation windows so that the rig's mean stage probabilities equal the twin's stage
proportions, move the decision boundaries the rig has shifted.  ``class_prior="ordinal"`` places the
boundaries along the windows' expected stage instead, at the quantiles of the twin's stage
proportions, and keeps only the order of the windows (the benchmark's pitting default).
``class_prior=None`` switches it off.

Training (paper Table 3 defaults): SGD with momentum 0.9 and weight decay 5e-4, initial learning
rate ``lr`` = 0.01 annealed as ``lr / (1 + 10 p)^0.75`` over the training progress ``p`` in [0, 1]
(the usual domain-adaptation schedule), batches of ``batch_size`` = 20 source windows paired with
20 target windows, ``epochs`` = 80 passes over the source windows.  Source and target batches go
through G together, so batch normalisation sees both domains.  Fixed hyperparameters, no early
stopping: the model after the last epoch is the result.

Determinism: ``fit`` seeds torch and numpy from ``seed``, switches torch to deterministic
algorithms and to ``n_threads`` threads (1 by default) for its duration, so the same seed on the
same machine gives bit-identical weights and predictions.
"""
from __future__ import annotations

import math
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from twin.transfer.assessment import Assessment, RecordAssessment
from twin.transfer.errors import AssessorError, ClassPriorWarning
from twin.transfer.preprocess import (Augmentation, Preprocessing, Prepared, augmented_windows, domain_normaliser,
                                      prepare, windows_of)

__all__ = ["Assessment", "Assessor", "METHODS", "RecordAssessment"]

METHODS = ("cnn", "mmd", "proposed", "coral")
CLASS_PRIORS = ("source", "ordinal", None)
# How far the class-prior match may lower the adaptation windows' mean confidence before fit warns
# (twin.transfer.prior.confidence_drop).  The middle of the gap in the runs that chose it
# (2026-11-23, docs/experiments.md): on the balanced benchmark and blind rigs the match cost at most 0.019, on
# run-to-failure-like subsets of the benchmark rig, where it costs 7-16 points of accuracy, at least
# 0.066.  Unseen imbalanced sets afterwards: at least 0.053.  The share of windows moved (the earlier
# statistic, 8 %) overlapped: up to 14 % on balanced data, from 7.8 % on imbalanced.
CLASS_PRIOR_WARN_DROP = 0.04
_EVAL_BATCH = 256


def class_prior_warns(confidence_drop: float) -> bool:
    """``fit``'s rule: does a class-prior match that cost this much mean confidence warn?"""
    return confidence_drop > CLASS_PRIOR_WARN_DROP


class Assessor:
    """Wear-stage assessor trained on labelled twin data and unlabelled rig data.

    Parameters
    ----------
    method : {"proposed", "mmd", "cnn", "coral"}
    alpha, beta : float
        Weights of the alignment loss (MMD or CORAL) and of the class-contrastive loss (Eq. 20).
    lr : float
        Initial learning rate.
    batch_size : int
        Source windows (and as many target windows) per step.
    epochs : int
        Passes over the source windows.
    threshold : float
        Pseudo-label confidence threshold in (0, 1].
    warmup_epochs : int
        Epochs before any pseudo-label enters the contrastive loss.
    margin : float
        Contrastive margin m on squared distances of unit feature vectors, in (0, 4].
    pairs : {"all", "diagonal"}
        Source/target pairs of the contrastive loss (see :mod:`twin.transfer.losses`).
    contrastive_reduction : {"mean", "sum"}
        How the contrastive terms of a batch add up: their mean, or Eq. 18's sum over the batch's
        gated target windows, which gives ``beta`` the paper's weight, ``batch_size`` times the
        mean's (:func:`~twin.transfer.losses.class_contrastive_loss`).  The sum locks in wrong
        pseudo-labels on a rig whose records do not fall into the twin's stages (docs/experiments.md),
        so the mean is the default.
    preprocessing : Preprocessing, optional
        Channel, resampling rate, window, hop, normalisation (default :class:`Preprocessing()`).
    augmentation : Augmentation or None, optional
        Source-side augmentation; default :class:`Augmentation()`, ``None`` for none.
    n_stages : int, optional
        Expected number of stages; the source labels must cover exactly ``0 .. n_stages - 1``.
    seed : int
    device : str, optional
        ``"cpu"``, ``"cuda"``; default the GPU when there is one.
    n_threads : int
        Torch CPU threads during ``fit`` (determinism does not depend on it, speed does).
    progress : bool
        Progress bars.
    class_prior : {"source", "ordinal", None}
        ``"source"``: after training, offset the stage logits on rig data so that the mean stage
        probabilities of the adaptation windows equal the twin's stage proportions
        (:mod:`twin.transfer.prior`; methods that adapt only).  It assumes the rig's adaptation
        data cover the stages in about the twin's proportions, as the domain normalisation does.
        ``"ordinal"``: the same assumption, used along the stage order: a rig window's stage is
        where its expected stage falls among the quantiles of the adaptation windows' expected
        stages at the twin's cumulative proportions (:func:`~twin.transfer.prior.ordinal_probabilities`;
        its confidence, in [0.5, 1], is the distance from the nearest boundary).  Robust to a rig
        whose damage moves the features by another amount than the twin's; wrong where the rig
        reverses the order of stages.  ``None``: no match.

    Attributes (after ``fit``)
    --------------------------
    network_ : torch.nn.Module
    n_classes_ : int
    classes_ : ndarray (K,)
    history_ : list of dict, one per epoch: ``loss``, ``cls``, ``align``, ``con``, ``source_acc``,
        ``gate`` (fraction of target windows whose pseudo-label passed), ``lr`` and, with
        ``monitor=``, ``monitor_acc``.
    n_source_windows_, n_target_windows_ : int
    source_normaliser_, target_normaliser_ : DomainNormaliser
        The per-domain part of the normalisation (identity unless ``normalise="domain"``): the
        waveform scale [channel unit], or the mean log spectrum (window,) and the shared scale.
    fit_time_ : float
        Wall time of the training loop [s].
    source_prior_ : ndarray (K,)
        The twin's stage proportions in the source windows, which every class-prior match aims at
        (kept so that :meth:`rematch` can fit another rule without retraining).
    target_log_weights_ : ndarray (K,)
        Logit offsets applied to rig (target-domain) data; zeros without a class-prior match.
    adaptation_stage_counts_ : ndarray (2, K) of int
        Adaptation windows assessed as each stage, without (row 0) and with (row 1) the offsets.
    ordinal_anchors_ : ndarray (2K - 1,) or None
        With ``class_prior="ordinal"``: the middles and boundaries of the rig's stages along the
        expected stage (:func:`~twin.transfer.prior.ordinal_anchors`); ``None`` otherwise.
    class_prior_moved_ : float
        Share of the adaptation windows whose stage the match (offsets or ordinal) changed, in [0, 1].
    class_prior_confidence_drop_ : float
        How much the offsets lowered the adaptation windows' mean confidence (largest stage
        probability), in (-1, 1) (:func:`~twin.transfer.prior.confidence_drop`).  Above
        :data:`CLASS_PRIOR_WARN_DROP`, ``fit`` issues a :class:`~twin.transfer.errors.ClassPriorWarning`.
    """

    def __init__(self, method: str = "proposed", *, alpha: float = 0.1, beta: float = 0.1, lr: float = 0.01,
                 batch_size: int = 20, epochs: int = 80, threshold: float = 0.9, warmup_epochs: int = 10,
                 margin: float = 1.0, pairs: str = "all", contrastive_reduction: str = "mean",
                 preprocessing: Preprocessing | None = None,
                 augmentation: Augmentation | None | str = "default", n_stages: int | None = None,
                 seed: int = 0, device: str | None = None, n_threads: int = 1, progress: bool = True,
                 class_prior: str | None = "source"):
        self.method = method
        self.alpha = alpha
        self.beta = beta
        self.lr = lr
        self.batch_size = batch_size
        self.epochs = epochs
        self.threshold = threshold
        self.warmup_epochs = warmup_epochs
        self.margin = margin
        self.pairs = pairs
        self.contrastive_reduction = contrastive_reduction
        self.preprocessing = preprocessing
        self.augmentation = augmentation
        self.n_stages = n_stages
        self.seed = seed
        self.device = device
        self.n_threads = n_threads
        self.progress = progress
        self.class_prior = class_prior

    # ---- scikit-learn plumbing ---------------------------------------------------------------
    _PARAMS = ("method", "alpha", "beta", "lr", "batch_size", "epochs", "threshold", "warmup_epochs", "margin",
               "pairs", "contrastive_reduction", "preprocessing", "augmentation", "n_stages", "seed", "device",
               "n_threads", "progress", "class_prior")

    def get_params(self, deep: bool = True) -> dict:
        return {k: getattr(self, k) for k in self._PARAMS}

    def set_params(self, **params) -> "Assessor":
        for k, v in params.items():
            if k not in self._PARAMS:
                raise AssessorError(f"unknown parameter {k!r}; parameters: {', '.join(self._PARAMS)}")
            setattr(self, k, v)
        return self

    def __repr__(self) -> str:
        return f"Assessor(method={self.method!r}, seed={self.seed}, epochs={self.epochs})"

    @property
    def _pre(self) -> Preprocessing:
        return self.preprocessing or Preprocessing()

    def _aug(self) -> Augmentation | None:
        if isinstance(self.augmentation, str):
            if self.augmentation != "default":
                raise AssessorError(f"augmentation must be an Augmentation, None or 'default', "
                                    f"got {self.augmentation!r}")
            return Augmentation()
        if self.augmentation is not None and not isinstance(self.augmentation, Augmentation):
            raise AssessorError(f"augmentation must be an Augmentation, None or 'default', got {self.augmentation!r}")
        return self.augmentation

    def _check_params(self) -> None:
        def bad(name, rule):
            raise AssessorError(f"{name}={getattr(self, name)!r} is invalid: {rule}")

        if self.method not in METHODS:
            bad("method", f"use one of {', '.join(METHODS)}")
        for name in ("alpha", "beta", "lr"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0) or (name == "lr" and v == 0):
                bad(name, "must be a finite number >= 0 (lr > 0)")
        for name in ("batch_size", "epochs", "n_threads"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < (2 if name == "batch_size" else 1):
                bad(name, "must be a positive integer (batch_size >= 2 for batch normalisation)")
        if isinstance(self.warmup_epochs, bool) or not isinstance(self.warmup_epochs, int) or self.warmup_epochs < 0:
            bad("warmup_epochs", "must be an integer >= 0")
        if not (isinstance(self.threshold, (int, float)) and 0 < self.threshold <= 1):
            bad("threshold", "must be in (0, 1]")
        if not (isinstance(self.margin, (int, float)) and 0 < self.margin <= 4):
            bad("margin", "must be in (0, 4]")
        if self.pairs not in ("all", "diagonal"):
            bad("pairs", "use 'all' or 'diagonal'")
        if self.contrastive_reduction not in ("mean", "sum"):
            bad("contrastive_reduction", "use 'mean' or 'sum'")
        if self.class_prior not in CLASS_PRIORS:
            bad("class_prior", "use 'source', 'ordinal' or None")
        if self.n_stages is not None and (isinstance(self.n_stages, bool) or not isinstance(self.n_stages, int)
                                          or self.n_stages < 2):
            bad("n_stages", "must be an integer >= 2")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            bad("seed", "must be an integer >= 0")
        if self.preprocessing is not None and not isinstance(self.preprocessing, Preprocessing):
            bad("preprocessing", "must be a twin.transfer.Preprocessing")
        self._aug()

    def _device(self):
        import torch
        if self.device is None:
            return torch.device("cuda" if torch.cuda.is_available() else "cpu")
        try:
            return torch.device(self.device)
        except RuntimeError:
            raise AssessorError(f"device={self.device!r} is not a torch device") from None

    # ---- data -----------------------------------------------------------------------------------
    def _prepared(self, data, labels, what: str, domain: str = "source") -> list[Prepared]:
        """Records (or raw windows ``(n, window)`` + labels) -> prepared signals; ``domain`` picks
        the channel of records (:meth:`Preprocessing.channel_of`)."""
        pre = self._pre
        if isinstance(data, np.ndarray) or (isinstance(data, (list, tuple)) and data
                                            and isinstance(data[0], np.ndarray)):
            x = np.asarray(data, dtype=np.float64)
            if x.ndim != 2 or x.shape[1] != pre.window:
                raise AssessorError(f"{what}: windows must have shape (n, {pre.window}), got {x.shape}")
            if x.shape[0] == 0:
                raise AssessorError(f"{what}: no windows (shape {x.shape})")
            if not np.all(np.isfinite(x)):
                raise AssessorError(f"{what}: windows contain non-finite samples")
            if labels is None:
                lab = [None] * x.shape[0]
            else:
                lab = np.asarray(labels)
                if lab.shape != (x.shape[0],):
                    raise AssessorError(f"{what}: labels must have shape ({x.shape[0]},), got {lab.shape}")
                lab = [int(v) for v in lab]
            return [Prepared(f"window{i}", x[i], lab[i]) for i in range(x.shape[0])]
        if labels is not None:
            raise AssessorError(f"{what}: labels are read from the records; pass labels only with window arrays")
        return prepare(data, pre, what, domain)

    def _check_source_labels(self, prepared: Sequence[Prepared]) -> int:
        missing = [p.name for p in prepared if p.label is None]
        if missing:
            raise AssessorError(f"source: {len(missing)} record(s) have no stage label, first '{missing[0]}'")
        labels = sorted({p.label for p in prepared})
        if labels[0] < 0:
            raise AssessorError(f"source: stage labels must be >= 0, got {labels[0]}")
        k = labels[-1] + 1
        if self.n_stages is not None and k != self.n_stages:
            raise AssessorError(f"source: labels span {k} stages (0..{k - 1}) but n_stages={self.n_stages}")
        absent = sorted(set(range(k)) - set(labels))
        if absent:
            raise AssessorError(f"source: stage(s) {absent} have no record; stages must be 0..{k - 1}")
        if k < 2:
            raise AssessorError(f"source: need at least 2 stages, got {k}")
        return k

    # ---- training -------------------------------------------------------------------------------
    def fit(self, source, target_unlabelled, *, source_labels=None, monitor=None) -> "Assessor":
        """Train on labelled ``source`` and unlabelled ``target_unlabelled``; return ``self``.

        Parameters
        ----------
        source : path, MeasurementSet, list of Record, Archive, or ndarray (n, window)
            Labelled twin data (record ``label`` = stage); arrays need ``source_labels`` (n,).
        target_unlabelled : same kinds (no labels needed; any label present is ignored)
            Rig data to adapt to.  With ``method="cnn"`` it is only checked, not used.
        monitor : (data, labels or None), optional
            Scored after every epoch into ``history_[i]["monitor_acc"]`` for the learning curves.
            It never influences training (no early stopping, no model selection).

        Raises
        ------
        AssessorError, MeasurementError
            Invalid parameters, shapes, labels, channels (the message names the value).

        Warns
        -----
        ClassPriorWarning
            The class-prior match lowered the adaptation windows' mean confidence by more than
            :data:`CLASS_PRIOR_WARN_DROP` (see ``class_prior_confidence_drop_``): it had to push
            windows the network was sure of into other stages.
        """
        import torch

        from twin._progress import progress_bar
        from twin.transfer.losses import class_contrastive_loss, coral_loss, mmd_loss, pseudo_label_gate
        from twin.transfer.model import Network

        self._check_params()
        pre, aug = self._pre, self._aug()
        src = self._prepared(source, source_labels, "source")
        k = self._check_source_labels(src)
        tgt = self._prepared(target_unlabelled, None, "target", "target")
        xt, _, _ = windows_of(tgt, pre, "target")
        xs_fixed, _, ys_fixed = windows_of(src, pre, "source")
        # "domain" normalisation: one normaliser per domain, from its own (unlabelled) windows.
        self.source_normaliser_ = domain_normaliser(xs_fixed, pre)
        self.target_normaliser_ = domain_normaliser(xt, pre, reference=self.source_normaliser_)
        xs_fixed = self.source_normaliser_(xs_fixed)
        xt = self.target_normaliser_(xt)
        mon = None
        if monitor is not None:
            mdata, mlabels = monitor if isinstance(monitor, tuple) else (monitor, None)
            mx, _, my = windows_of(self._prepared(mdata, mlabels, "monitor", "target"), pre, "monitor")
            mon = (self.target_normaliser_(mx), my)

        device = self._device()
        prev_threads = torch.get_num_threads()
        prev_det = torch.are_deterministic_algorithms_enabled()
        torch.set_num_threads(self.n_threads)
        torch.use_deterministic_algorithms(True)
        try:
            torch.manual_seed(int(self.seed))
            rng = np.random.default_rng(int(self.seed))
            net = Network(k, pre.window).to(device)
            opt = torch.optim.SGD(net.parameters(), lr=self.lr, momentum=0.9, weight_decay=5e-4)
            n_s = xs_fixed.shape[0]
            steps = math.ceil(n_s / self.batch_size)
            total = steps * self.epochs
            xt_t = torch.from_numpy(xt).unsqueeze(1).to(device)
            adapt = self.method != "cnn"
            history = []
            self.target_log_weights_ = np.zeros(k)      # the monitor sees the network as trained
            self.ordinal_anchors_ = None
            bar = progress_bar(self.epochs, self.progress, f"train {self.method}", "epoch")
            t_start = time.perf_counter()
            step = 0
            t_perm = rng.permutation(xt.shape[0])
            t_pos = 0
            for epoch in range(self.epochs):
                if aug is not None:
                    xs, ys = augmented_windows(src, pre, aug, rng)
                    xs = self.source_normaliser_(xs)
                else:
                    xs, ys = xs_fixed, ys_fixed
                xs_t = torch.from_numpy(xs).unsqueeze(1).to(device)
                ys_t = torch.from_numpy(ys.astype(np.int64)).to(device)
                perm = rng.permutation(n_s)
                net.train()
                sums = dict(loss=0.0, cls=0.0, align=0.0, con=0.0, correct=0, seen=0, gated=0, tseen=0)
                for b in range(steps):
                    idx = torch.from_numpy(perm[b * self.batch_size:(b + 1) * self.batch_size])
                    if idx.numel() < 2:         # a batch of one cannot be batch-normalised
                        continue
                    lr = self.lr / (1 + 10 * step / total) ** 0.75
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
                        align = coral_loss(gs, gt) if self.method == "coral" else mmd_loss(gs, gt)
                        if self.method == "proposed":
                            pt = torch.softmax(lt.detach(), dim=1)
                            yt, mask = pseudo_label_gate(pt, epoch, self.threshold, self.warmup_epochs)
                            con = class_contrastive_loss(gs, yb, gt, yt, mask, self.margin, self.pairs,
                                                         self.contrastive_reduction)
                            sums["gated"] += int(mask.sum())
                            sums["tseen"] += int(mask.numel())
                    else:
                        _, ls = net(xb)
                    cls = torch.nn.functional.cross_entropy(ls, yb)
                    loss = cls + self.alpha * align + (self.beta * con if self.method == "proposed" else 0.0)
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
                if mon is not None:
                    self.network_ = net
                    self.n_classes_ = k
                    p = self._proba_windows(mon[0])
                    known = mon[1] >= 0
                    rec["monitor_acc"] = (float(np.mean(p.argmax(1)[known] == mon[1][known]))
                                          if known.any() else None)
                history.append(rec)
                bar.update(1)
            bar.close()
            self.fit_time_ = time.perf_counter() - t_start
        finally:
            torch.set_num_threads(prev_threads)
            torch.use_deterministic_algorithms(prev_det)
        net.eval()
        self.network_ = net
        self.n_classes_ = k
        self.classes_ = np.arange(k)
        self.history_ = history
        self.source_prior_ = np.bincount(ys_fixed.astype(np.int64), minlength=k) / ys_fixed.size
        self._fit_match(self._forward(xt)[1])
        self.n_source_windows_ = int(n_s)
        self.n_target_windows_ = int(xt.shape[0])
        return self

    def rematch(self, target_unlabelled, class_prior: str | None) -> "Assessor":
        """A copy of this fitted assessor that stages rig data by another class-prior rule.

        The network, the normalisers and the history are shared; only the match is fitted anew, on
        the rig's unlabelled adaptation data (the ``target_unlabelled`` given to :meth:`fit`).
        ``fit`` trains the same network under every rule (the match comes after training), so with
        the data ``fit`` saw the copy is what ``fit(..., class_prior=class_prior)`` would have given,
        bit for bit, in the time of one forward pass instead of a training run.  The use: ``fit``
        warned that the match cost confidence (rig data far from the twin's stage proportions, a
        run-to-failure history say), and the rig is to be staged with ``class_prior=None`` or the
        other rule, without retraining.

        Parameters
        ----------
        target_unlabelled : records, HDF5/CSV path, or windows (n, window)
            The rig's adaptation data; labels, if any, are not read.
        class_prior : {"source", "ordinal", None}
            The rule, as for the constructor.

        Returns
        -------
        Assessor
            A new fitted assessor; this one is unchanged.

        Raises
        ------
        AssessorError
            Not fitted; an unknown rule; a match asked of the source-only CNN (it reads no rig data);
            a match asked of an assessor loaded from a file written before ``source_prior_`` was saved
            (retrain it).

        Warns
        -----
        ClassPriorWarning
            As :meth:`fit`, when the offsets would cost the adaptation windows much confidence.
        """
        import copy

        self._check_fitted()
        if class_prior not in CLASS_PRIORS:
            raise AssessorError(f"rematch: class_prior={class_prior!r} is invalid: use 'source', 'ordinal' or None")
        if self.method == "cnn" and class_prior is not None:
            raise AssessorError(f"rematch: class_prior={class_prior!r} asks the source-only CNN to read rig data; "
                                "it matches nothing (use class_prior=None, or a method that adapts)")
        if class_prior is not None and getattr(self, "source_prior_", None) is None:
            raise AssessorError("rematch: this assessor has no record of the twin's stage proportions "
                                "(source_prior_; assessors saved before it was written lack it): retrain it with "
                                f"class_prior={class_prior!r}")
        x, *_ = self._windows(target_unlabelled, "rematch", "target")
        new = copy.copy(self)
        new.class_prior = class_prior
        new._fit_match(self._forward(x)[1])
        return new

    def _fit_match(self, p_adapt: np.ndarray) -> None:
        """Fit this assessor's class-prior rule to the adaptation windows' network probabilities
        ``p_adapt`` (n, K), and record its diagnostics (:meth:`_class_prior_check`)."""
        from twin.transfer.prior import match_class_prior, ordinal_anchors
        self.target_log_weights_, self.ordinal_anchors_ = np.zeros(p_adapt.shape[1]), None
        prior = None
        if self.method != "cnn" and self.class_prior is not None:
            prior = self.source_prior_
            if self.class_prior == "source":
                self.target_log_weights_ = match_class_prior(p_adapt, prior)
            else:
                self.ordinal_anchors_ = ordinal_anchors(p_adapt, prior)
        self._class_prior_check(p_adapt, prior)

    def _class_prior_check(self, p_adapt: np.ndarray, prior: np.ndarray | None) -> None:
        """Record how the match (offsets or ordinal) re-assesses the adaptation windows ``p_adapt``
        (n, K); warn when the offsets cost the windows much confidence (the symptom of rig data that
        break the match's assumption; a rig that only shifts the boundaries moves the windows the
        network was unsure of)."""
        from twin.transfer.prior import confidence_drop, match_class_prior, ordinal_probabilities, stage_moves
        if getattr(self, "ordinal_anchors_", None) is None:
            self.adaptation_stage_counts_, self.class_prior_moved_ = stage_moves(p_adapt, self.target_log_weights_)
            self.class_prior_confidence_drop_ = confidence_drop(p_adapt, self.target_log_weights_)
        else:
            k = p_adapt.shape[1]
            before, after = p_adapt.argmax(1), ordinal_probabilities(p_adapt, self.ordinal_anchors_).argmax(1)
            self.adaptation_stage_counts_ = np.stack([np.bincount(before, minlength=k),
                                                      np.bincount(after, minlength=k)])
            self.class_prior_moved_ = float(np.mean(before != after))
            # The ordinal confidence measures the distance from a boundary, not comparable with the
            # network's.  Whether the rig data break the proportion assumption is a property of the
            # data, so the warning reads what the offsets would have cost (they are not applied).
            self.class_prior_confidence_drop_ = confidence_drop(p_adapt, match_class_prior(p_adapt, prior))
        if prior is not None and class_prior_warns(self.class_prior_confidence_drop_):
            import warnings
            k = p_adapt.shape[1]
            counts = ", ".join(map(str, self.adaptation_stage_counts_[0]))
            warnings.warn(
                f"the class-prior match lowered the mean confidence of the {p_adapt.shape[0]} rig adaptation "
                f"windows by {100 * self.class_prior_confidence_drop_:.1f} points (more than "
                f"{100 * CLASS_PRIOR_WARN_DROP:.0f}) and moved {100 * self.class_prior_moved_:.1f} % of them to "
                f"another stage. Unmatched, they read as stages 0..{k - 1}: {counts}; the match assumes the "
                f"proportions {', '.join(f'{v:.2f}' for v in prior)}. It had to push windows the network was sure "
                f"of into other stages. Either the rig's data do not cover the stages in those proportions (a "
                f"run-to-failure history, say): stage them without the match, no retraining needed "
                f"(rematch(rig, class_prior=None); twin rematch ASSESSOR RIG --class-prior none --out DIR); "
                f"or the rig's records do not fall into the twin's "
                f"stages, and no setting here fixes that: compare the model with the rig (twin compare, "
                f"twin diagnose).",
                ClassPriorWarning, stacklevel=4)

    # ---- inference ------------------------------------------------------------------------------
    def _check_fitted(self) -> None:
        if not hasattr(self, "network_"):
            raise AssessorError("this Assessor is not fitted yet: call fit() or Assessor.load()")

    def _forward(self, x: np.ndarray):
        import torch
        net = self.network_
        was_training = net.training
        net.eval()
        dev = next(net.parameters()).device
        feats, probs = [], []
        with torch.no_grad():
            for i in range(0, x.shape[0], _EVAL_BATCH):
                g, logits = net(torch.from_numpy(np.ascontiguousarray(x[i:i + _EVAL_BATCH])).unsqueeze(1).to(dev))
                feats.append(g.cpu().numpy())
                probs.append(torch.softmax(logits, 1).cpu().numpy())
        net.train(was_training)
        return np.concatenate(feats), np.concatenate(probs)

    def _proba_windows(self, x: np.ndarray, domain: str = "target", batched: bool = False) -> np.ndarray:
        """Stage probabilities of windows under the class-prior rule of ``domain``; ``batched``: by the
        folded network of :mod:`twin.transfer.inference` (CPU; the same numbers to float32 round-off)."""
        if batched and next(self.network_.parameters()).device.type == "cpu":
            from twin.transfer.inference import StackedNetworks
            p = StackedNetworks([self.network_]).probabilities(x)[0]
        else:
            p = self._forward(x)[1]
        anchors = getattr(self, "ordinal_anchors_", None)
        if domain == "target" and anchors is not None:
            from twin.transfer.prior import ordinal_probabilities
            return ordinal_probabilities(p, anchors)
        w = getattr(self, "target_log_weights_", None)
        if domain == "target" and w is not None and np.any(w != 0):
            from twin.transfer.prior import apply_log_weights
            p = apply_log_weights(p, w)
        return p

    def _windows(self, data, what: str, domain: str = "target"):
        """(windows (n, window), record index (n,), labels (n,), prepared records, is_array).

        ``domain`` picks the scale of "domain" normalisation: new data are rig (target) data.
        """
        if domain not in ("target", "source"):
            raise AssessorError(f"{what}: domain must be 'target' or 'source', got {domain!r}")
        pre = self._pre
        is_array = isinstance(data, np.ndarray)
        prepared = self._prepared(data, None, what, domain)
        x, rec, lab = windows_of(prepared, pre, what)
        norm = self.target_normaliser_ if domain == "target" else self.source_normaliser_
        return norm(x), rec, lab, prepared, is_array

    def transform(self, data, domain: str = "target") -> np.ndarray:
        """High-level features G(x) of every window, shape (n_windows, 300).

        ``domain="source"`` scales the windows as the twin's data were scaled in training.
        """
        self._check_fitted()
        x, *_ = self._windows(data, "transform", domain)
        return self._forward(x)[0]

    def predict_proba(self, data, domain: str = "target") -> np.ndarray:
        """Stage probabilities: (n, K) per row for an array of windows (n, window), per record
        (mean over the record's windows) for records.  Data are taken as rig data (``domain``)."""
        self._check_fitted()
        x, rec, _, prepared, is_array = self._windows(data, "predict", domain)
        p = self._proba_windows(x, domain, batched=True)
        if is_array:
            return p
        return np.stack([p[rec == i].mean(0) for i in range(len(prepared))])

    def predict(self, data, domain: str = "target") -> np.ndarray:
        """Stage per window (array input) or per record (record input), shape (n,)."""
        return self.predict_proba(data, domain).argmax(1)

    def assess(self, data, domain: str = "target") -> Assessment:
        """Stage and confidence per record and per window; accuracies when every record is labelled.

        Raises
        ------
        AssessorError
            A record label outside ``0 .. n_classes_ - 1`` (a different stage count).
        """
        self._check_fitted()
        x, rec, lab, prepared, _ = self._windows(data, "assess", domain)
        p = self._proba_windows(x, domain, batched=True)
        self._check_labels([q.label for q in prepared if q.label is not None], "assess")
        out = []
        for i, q in enumerate(prepared):
            pw = p[rec == i]
            mean = pw.mean(0)
            s = int(mean.argmax())
            out.append(RecordAssessment(q.name, s, float(mean[s]), tuple(float(v) for v in mean),
                                        tuple(int(v) for v in pw.argmax(1)),
                                        tuple(float(v) for v in pw.max(1)), q.label))
        labelled = all(q.label is not None for q in prepared)
        rec_acc = float(np.mean([r.stage == r.label for r in out])) if labelled else None
        win_acc = float(np.mean(p.argmax(1) == lab)) if labelled else None
        return Assessment(tuple(out), self.n_classes_, rec_acc, win_acc)

    def _check_labels(self, labels, what: str) -> None:
        bad = sorted({int(v) for v in labels if not 0 <= int(v) < self.n_classes_})
        if bad:
            raise AssessorError(f"{what}: label(s) {bad} outside the model's {self.n_classes_} stages "
                                f"(0..{self.n_classes_ - 1}); the data have a different stage count")

    def score(self, data, labels=None) -> float:
        """Window accuracy on labelled data (records with labels, or windows + ``labels``)."""
        self._check_fitted()
        if isinstance(data, np.ndarray):
            if labels is None:
                raise AssessorError("score: labels are required with an array of windows")
            y = np.asarray(labels)
            p = self.predict_proba(data)
            if y.shape != (p.shape[0],):
                raise AssessorError(f"score: labels must have shape ({p.shape[0]},), got {y.shape}")
            self._check_labels(y, "score")
            return float(np.mean(p.argmax(1) == y))
        a = self.assess(data)
        if a.window_accuracy is None:
            raise AssessorError("score: some records have no label")
        return a.window_accuracy

    # ---- persistence (twin/transfer/assessor_io.py) ----------------------------------------------
    def save(self, directory: str | Path) -> Path:
        """Write ``config.json`` (parameters, preprocessing, history) and ``weights.pt`` atomically.

        The directory is created if its parent exists.  Raises :class:`~twin.errors.OutputPathError`
        for a missing parent or a path that is a file.
        """
        from twin.transfer.assessor_io import save_assessor

        return save_assessor(self, directory)

    @classmethod
    def load(cls, directory: str | Path, device: str | None = None) -> "Assessor":
        """Read an assessor written by :meth:`save`.

        Raises
        ------
        AssessorError
            Missing directory or file, another format or version, inconsistent weights.
        """
        from twin.transfer.assessor_io import load_assessor

        return load_assessor(cls, directory, device)
