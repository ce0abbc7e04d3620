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
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from twin.transfer.assessment import Assessment, RecordAssessment
from twin.transfer.errors import AssessorError
from twin.transfer.matching import CLASS_PRIOR_WARN_DROP, CLASS_PRIORS, ClassPriorMatch, class_prior_warns
from twin.transfer.preprocess import Augmentation, Preprocessing, Prepared, domain_normaliser, prepare, windows_of

__all__ = ["Assessment", "Assessor", "CLASS_PRIOR_WARN_DROP", "CLASS_PRIORS", "METHODS", "RecordAssessment",
           "class_prior_warns"]

METHODS = ("cnn", "mmd", "proposed", "coral")
_EVAL_BATCH = 256


class Assessor(ClassPriorMatch):
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
        from twin.transfer.training import train_network

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
        score_monitor = None
        if monitor is not None:
            mdata, mlabels = monitor if isinstance(monitor, tuple) else (monitor, None)
            mx, _, my = windows_of(self._prepared(mdata, mlabels, "monitor", "target"), pre, "monitor")
            mx, known = self.target_normaliser_(mx), my >= 0

            def score_monitor(net) -> float | None:
                self.network_, self.n_classes_ = net, k
                p = self._proba_windows(mx)
                return float(np.mean(p.argmax(1)[known] == my[known])) if known.any() else None

        self.target_log_weights_ = np.zeros(k)      # the monitor sees the network as trained
        self.ordinal_anchors_ = None
        net, history, self.fit_time_ = train_network(self, src, xs_fixed, ys_fixed, xt, k, pre, aug,
                                                     self.source_normaliser_, self._device(), score_monitor)
        self.network_ = net
        self.n_classes_ = k
        self.classes_ = np.arange(k)
        self.history_ = history
        self.source_prior_ = np.bincount(ys_fixed.astype(np.int64), minlength=k) / ys_fixed.size
        self._fit_match(self._forward(xt)[1])
        self.n_source_windows_ = int(xs_fixed.shape[0])
        self.n_target_windows_ = int(xt.shape[0])
        return self

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
