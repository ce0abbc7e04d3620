"""The assessor's class-prior match: fitted after training, refitted by :meth:`rematch` without it.

:class:`ClassPriorMatch` is the part of :class:`twin.transfer.assessor.Assessor` that fits the
class-prior rule (``class_prior="source"`` offsets or ``"ordinal"`` anchors, the functions of
:mod:`twin.transfer.prior`) to the network's probabilities on the rig's adaptation windows, records
how it re-assesses them and warns when it costs them much confidence.  It relies on the assessor's
``method``, ``class_prior``, ``source_prior_`` and its ``_check_fitted``, ``_windows`` and
``_forward``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from twin.transfer.errors import AssessorError, ClassPriorWarning

if TYPE_CHECKING:
    from twin.transfer.assessor import Assessor

__all__ = ["CLASS_PRIORS", "CLASS_PRIOR_WARN_DROP", "ClassPriorMatch", "class_prior_warns"]

CLASS_PRIORS = ("source", "ordinal", None)
# How far the class-prior match may lower the adaptation windows' mean confidence before fit warns
# (twin.transfer.prior.confidence_drop).  The middle of the gap in the runs that chose it
# (2026-11-23, docs/experiments.md): on the balanced benchmark and blind rigs the match cost at most 0.019, on
# run-to-failure-like subsets of the benchmark rig, where it costs 7-16 points of accuracy, at least
# 0.066.  Unseen imbalanced sets afterwards: at least 0.053.  The share of windows moved (the earlier
# statistic, 8 %) overlapped: up to 14 % on balanced data, from 7.8 % on imbalanced.
CLASS_PRIOR_WARN_DROP = 0.04


def class_prior_warns(confidence_drop: float) -> bool:
    """``fit``'s rule: does a class-prior match that cost this much mean confidence warn?"""
    return confidence_drop > CLASS_PRIOR_WARN_DROP


class ClassPriorMatch:
    """The class-prior match of a fitted assessor (mixed into :class:`~twin.transfer.assessor.Assessor`)."""

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
