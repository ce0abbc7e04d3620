"""An ensemble of assessors: the answer does not hang on one seed, and says how far to trust it.

::

    from twin.transfer.ensemble import train_ensemble, Ensemble
    ens = train_ensemble("archive.h5", "rig.h5", "assessor/")      # 5 members, settings from the archive
    res = ens.assess("rig.h5")           # ensemble stage per record, agreement, order check, reliability
    Ensemble.load("assessor/").assess("rig_new.h5")

A single assessor's answer on a rig the twin did not generate can depend on its seed by tens of
points, and two seeds can read the stages in opposite orders.  The ensemble trains ``members``
assessors that differ only in their seed (initialisation, batches, augmentation) on the same data
and settings, and

* **stages** each record by the mean of the members' network probabilities, with the class-prior
  rule fitted once on that mean over the rig's adaptation windows (the members' mean is the model);
* **measures its own agreement**, without labels: each member stages the windows with its own rule,
  and the mean share of windows two members give the same stage bounds their mean accuracy by
  ``(1 + agreement) / 2`` (:mod:`twin.transfer.reliability`);
* **checks the stage order** against a physically monotone feature whose trend it took from the
  twin's archive (:mod:`twin.transfer.order`);
* **uses the time order** when the records carry one (``time_start`` or ``cycles``): damage does not
  heal, so the stages of a history are decoded as a non-decreasing sequence
  (:func:`~twin.transfer.order.monotone_stages`), and the assessment says how many records that moved;
* calls the result **reliable** only when the members agree on at least :data:`RELIABLE_AGREEMENT`
  of the windows and the order check is consistent.

Every setting follows from the archive (:mod:`twin.transfer.settings`): the window length from the
test's shaft speed, the level handling from its damage kind, the ordinal class-prior rule from its
ordered stages.  Rig records whose speed, load or damage kind do not fit the test are refused by
name, and resampling is reported.  The verdict's records (:class:`EnsembleAssessment`,
:class:`EnsembleRecord`) are in :mod:`twin.transfer.ensemble_result`.

Cost: ``members`` training runs; the members train in ``jobs`` processes, one torch thread each.
On 2 cores a 5-member ensemble of the paper's 80 epochs on the shipped archives takes about 2.5 x
the time of one fit (BENCHMARKS.md).
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from twin.transfer.ensemble_result import RELIABLE_AGREEMENT, EnsembleAssessment, EnsembleRecord
from twin.transfer.errors import AssessorError

__all__ = ["DEFAULT_MEMBERS", "Ensemble", "EnsembleAssessment", "EnsembleRecord", "RELIABLE_AGREEMENT",
           "train_ensemble"]

DEFAULT_MEMBERS = 5
ENSEMBLE_FORMAT = "gear-twin-assessor-ensemble"
ENSEMBLE_VERSION = 1


# ---- training ---------------------------------------------------------------------------------------
def _fit_member(source: str, target, out: str, method: str, seed: int, epochs: int, pre_dict: dict,
                class_prior: str) -> str:
    """Train and save one member (top level: it runs in a worker process)."""
    import warnings

    from twin.transfer.assessor import Assessor
    from twin.transfer.errors import ClassPriorWarning
    from twin.transfer.preprocess import Preprocessing

    a = Assessor(method, epochs=epochs, seed=seed, preprocessing=Preprocessing(**pre_dict), progress=False,
                 class_prior=class_prior)
    with warnings.catch_warnings():
        # the ensemble reports on the rule it applies itself; a member's own match only serves agreement
        warnings.simplefilter("ignore", ClassPriorWarning)
        a.fit(source, target)
    a.save(out)
    return out


def _member_key(source: Path, method: str, seed: int, epochs: int, pre: dict, class_prior: str,
                target_names: tuple) -> str:
    import hashlib
    st = source.stat()
    blob = json.dumps({"source": str(source.resolve()), "size": st.st_size, "mtime": st.st_mtime_ns,
                       "method": method, "seed": seed, "epochs": epochs, "pre": pre, "class_prior": class_prior,
                       "target": list(target_names)}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def train_ensemble(source, target, out, *, members: int = DEFAULT_MEMBERS, method: str = "proposed",
                   epochs: int = 80, first_seed: int = 0, jobs: int = 2, channel: str = "accel_pinion_casing",
                   target_channel: str | None = None, progress: bool = True, log=print) -> "Ensemble":
    """Train an ensemble on the archive ``source`` and the unlabelled rig records ``target``; save it in ``out``.

    Parameters
    ----------
    source : path
        The twin's archive (``twin archive``); its test decides every setting (module docstring).
    target : path, MeasurementSet or list of Record
        The rig's records to adapt to; labels are never read.
    out : path
        Directory for the ensemble; a member already trained there with the same data and settings
        is kept (an interrupted training resumes).
    members : int
        Number of members (seeds ``first_seed .. first_seed + members - 1``), at least 2.
    jobs : int
        Members trained in parallel (processes, one torch thread each); 1 trains them one after the
        other in this process.
    log : callable
        Where the notes go (resampling, records without a speed, progress of the members).

    Raises
    ------
    AssessorError
        A bad count, an archive that is not one, rig records that do not fit its test (named).
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    from twin._atomic import check_output_dir
    from twin._progress import progress_bar
    from twin.measurements import MeasurementSet, load_measurements
    from twin.transfer.settings import (archive_facts, check_records, class_prior_for, preprocessing_for,
                                        resampling_note)

    for name, v, lo in (("members", members, 2), ("jobs", jobs, 1), ("epochs", epochs, 1)):
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise AssessorError(f"{name} must be an integer >= {lo}, got {v!r}")
    source = Path(source)
    facts = archive_facts(source)
    pre = preprocessing_for(facts, channel=channel, target_channel=target_channel)
    rule = class_prior_for(facts)
    rig_channel = pre.channel_of("target")
    if isinstance(target, (str, Path)):
        target = load_measurements(target, channels=[rig_channel])
    recs = list(target.records if isinstance(target, MeasurementSet) else target)
    if not recs:
        raise AssessorError("target: no records")
    notes = check_records(recs, facts, "rig")
    note = resampling_note([r.sample_rate for r in recs], pre.sample_rate)
    notes += [note] if note else []
    for n in notes:
        log(f"note: {n}")
    out = check_output_dir(out, "assessor ensemble", create=True)
    # The members train in other processes, which read the rig's records from a file: the ones given,
    # the assessor's channel only (records do not pickle, and the file documents what was adapted to).
    adaptation = out / "adaptation.h5"
    if not _same_records(adaptation, recs, rig_channel):
        from twin.measurements import Record, write_measurements
        write_measurements([Record(r.name, {rig_channel: r[rig_channel]}, {rig_channel: r.units[rig_channel]},
                                   r.sample_rate, nominal_speed=r.nominal_speed, load=r.load,
                                   time_start=r.time_start) for r in recs], adaptation)
    pre_dict = pre.to_dict()
    names = tuple(r.name for r in recs)
    seeds = list(range(first_seed, first_seed + members))
    keys = {s: _member_key(source, method, s, epochs, pre_dict, rule, names) for s in seeds}
    todo = [s for s in seeds if not _member_done(out / f"member_{s}", keys[s])]
    if len(todo) < len(seeds):
        log(f"ensemble: {len(seeds) - len(todo)} of {len(seeds)} members already trained in {out}")
    t0 = time.perf_counter()
    bar = progress_bar(len(todo), progress, f"ensemble {method}", "member")
    if todo and min(jobs, len(todo)) == 1:
        # one at a time: in this process (a worker would pay torch's and scipy's imports again)
        for s in todo:
            _fit_member(str(source), str(adaptation), str(out / f"member_{s}"), method, s, epochs, pre_dict, rule)
            (out / f"member_{s}" / "ensemble_key").write_text(keys[s])
            bar.update(1)
    elif todo:
        with ProcessPoolExecutor(max_workers=min(jobs, len(todo)), mp_context=mp.get_context("spawn")) as pool:
            futures = {s: pool.submit(_fit_member, str(source), str(adaptation), str(out / f"member_{s}"), method,
                                      s, epochs, pre_dict, rule) for s in todo}
            for s, fut in futures.items():
                fut.result()
                (out / f"member_{s}" / "ensemble_key").write_text(keys[s])
                bar.update(1)
    bar.close()
    train_time = time.perf_counter() - t0
    ens = Ensemble([out / f"member_{s}" for s in seeds], facts)
    ens.fit_match(recs, source)
    ens.train_time_ = train_time
    ens.notes_ = tuple(notes)
    ens.save(out)
    return ens


def _same_records(path: Path, recs, channel: str) -> bool:
    """Does the file at ``path`` hold exactly these records' ``channel`` (names, rates, samples)?"""
    if not path.is_file():
        return False
    from twin.errors import MeasurementError
    from twin.measurements import load_measurements
    try:
        old = load_measurements(path, channels=[channel])
    except (MeasurementError, OSError):       # a damaged or foreign file is simply rewritten
        return False
    return old.names == tuple(r.name for r in recs) and all(
        a.sample_rate == b.sample_rate and np.array_equal(a[channel], b[channel]) for a, b in zip(old.records, recs))


def _member_done(d: Path, key: str) -> bool:
    k = d / "ensemble_key"
    return (d / "config.json").is_file() and (d / "weights.pt").is_file() and k.is_file() and k.read_text() == key


# ---- the ensemble -----------------------------------------------------------------------------------
class Ensemble:
    """Fitted assessors that differ in their seed, with the ensemble's own class-prior rule.

    Parameters
    ----------
    members : sequence of fitted Assessor or directories written by ``Assessor.save``
    facts : ArchiveFacts
        The test of the archive the members were trained on.

    Attributes (after :meth:`fit_match` or :meth:`load`)
    ---------------------------------------------------
    anchors_ : ndarray (2K - 1,) or None
        The ordinal anchors of the members' mean probability on the rig's adaptation windows.
    log_weights_ : ndarray (K,)
        Per-stage offsets (the "source" rule); zeros otherwise.
    twin_trends_ : dict
        Rank correlation of each monotone feature with the stage in the archive.
    train_time_ : float
        Wall time of training the members [s] (0 when all were already trained).
    """

    def __init__(self, members, facts):
        from twin.transfer.assessor import Assessor
        self.members = [m if isinstance(m, Assessor) else Assessor.load(m) for m in members]
        self.member_dirs = [None if isinstance(m, Assessor) else str(Path(m)) for m in members]
        self.facts = facts
        if len(self.members) < 2:
            raise AssessorError(f"an ensemble needs at least 2 members, got {len(self.members)}")
        ks = {m.n_classes_ for m in self.members}
        pres = {json.dumps(m._pre.to_dict(), sort_keys=True) for m in self.members}
        if len(ks) > 1 or len(pres) > 1:
            raise AssessorError("ensemble members differ in their stages or preprocessing; train them on one archive")
        self.n_classes_ = ks.pop()
        self.rule = self.members[0].class_prior

    @property
    def preprocessing(self):
        return self.members[0]._pre

    # -- probabilities ----------------------------------------------------------------------------
    def _raw(self, data, what: str = "assess"):
        """Members' raw network probabilities on the windows of ``data``: (members, n, K), record
        index (n,), labels (n,), prepared records (:meth:`_streamed`)."""
        return self._streamed(data, what)[:4]

    def _streamed(self, data, what: str = "assess", features: bool = False, facts=None):
        """:meth:`_raw`, the records read from a path (None otherwise) and, with ``features``,
        the records' order-check features: :func:`twin.transfer.inference.assess_stream` (which
        checks each record read from a path against ``facts`` as it is read)."""
        from twin.transfer.inference import assess_stream
        return assess_stream(self, data, what, features, facts)

    def _networks(self):
        """(the members' folded networks, the windows' domain normalisation for them)."""
        from twin.transfer.inference import StackedNetworks
        key = tuple(id(m.network_) for m in self.members)
        if getattr(self, "_stacked_key", None) != key:          # folded once per set of members
            self._stacked, self._stacked_key = StackedNetworks([m.network_ for m in self.members]), key
        norms = [m.target_normaliser_ for m in self.members]
        first = norms[0]
        if all(np.array_equal(n.centre, first.centre) and n.scale == first.scale for n in norms[1:]):
            return self._stacked, first
        return self._stacked, lambda raw: np.stack([n(raw) for n in norms])

    def _network_probabilities(self, raw: np.ndarray) -> np.ndarray:
        """The members' network probabilities (members, n, K) of represented windows ``raw`` (n, window):
        all members over all windows together; each member's own ``Assessor._forward`` gives the
        same numbers to float32 round-off."""
        stacked, normalise = self._networks()
        return stacked.probabilities(normalise(raw))

    def _match(self, p: np.ndarray) -> np.ndarray:
        from twin.transfer.prior import apply_log_weights, ordinal_probabilities
        if self.anchors_ is not None:
            return ordinal_probabilities(p, self.anchors_)
        if np.any(self.log_weights_ != 0):
            return apply_log_weights(p, self.log_weights_)
        return p

    def _member_stages(self, raw: np.ndarray) -> np.ndarray:
        """Each member's window stages under its own rule, (members, n)."""
        from twin.transfer.prior import apply_log_weights, ordinal_probabilities
        out = []
        for m, p in zip(self.members, raw):
            if getattr(m, "ordinal_anchors_", None) is not None:
                p = ordinal_probabilities(p, m.ordinal_anchors_)
            elif np.any(m.target_log_weights_ != 0):
                p = apply_log_weights(p, m.target_log_weights_)
            out.append(p.argmax(1))
        return np.array(out, dtype=np.int64)

    def fit_match(self, adaptation, source=None) -> "Ensemble":
        """Fit the ensemble's class-prior rule on the rig's adaptation records, and read the twin's
        feature trends from the archive ``source`` (path)."""
        from twin.transfer.prior import match_class_prior, ordinal_anchors
        raw, _, _, _ = self._raw(adaptation, "adaptation")
        p = raw.mean(0)
        prior = self.members[0].source_prior_
        self.anchors_, self.log_weights_ = None, np.zeros(self.n_classes_)
        if self.members[0].method != "cnn" and self.rule == "ordinal":
            self.anchors_ = ordinal_anchors(p, prior)
        elif self.members[0].method != "cnn" and self.rule == "source":
            self.log_weights_ = match_class_prior(p, prior)
        self.twin_trends_ = self._twin_trends(source) if source is not None else {}
        self.train_time_ = getattr(self, "train_time_", 0.0)
        self.notes_ = getattr(self, "notes_", ())
        return self

    def _features(self, prepared) -> dict:
        from twin.transfer.order import record_features
        return record_features([q.signal for q in prepared], self.preprocessing.sample_rate, self.facts.nominal_speed)

    def _twin_trends(self, source) -> dict:
        from twin.transfer.order import feature_trends
        from twin.transfer.preprocess import prepare
        prepared = prepare(source, self.preprocessing, "source", "source")
        return feature_trends(self._features(prepared), np.array([q.label for q in prepared]))

    # -- assessment -------------------------------------------------------------------------------
    def assess(self, data, *, time_ordered: bool | None = None) -> EnsembleAssessment:
        """The ensemble's verdict on rig records (module docstring).

        Parameters
        ----------
        data : path, MeasurementSet or list of Record
        time_ordered : bool or None
            None: use the records' own time stamps (``time_start``, ``cycles``) when they have them.
            True: the records are given in time order (a run-to-failure history in file order).
            False: ignore any time order.
        """
        from twin.measurements import MeasurementSet
        from twin.transfer.order import check_order, monotone_stages, time_order
        from twin.transfer.reliability import pairwise_agreement
        from twin.transfer.settings import check_records, resampling_note

        self._check()
        pre = self.preprocessing
        streamed = None
        if isinstance(data, (str, Path)):              # read record by record beside the work on them,
            streamed = self._streamed(data, features=True, facts=self.facts)   # each checked as read
            recs = streamed[4]
        else:
            recs = list(data.records if isinstance(data, MeasurementSet) else data)
        if not recs:
            raise AssessorError("assess: no records")
        notes = check_records(recs, self.facts, "assess")
        note = resampling_note([r.sample_rate for r in recs], pre.sample_rate, "assess")
        notes += [note] if note else []
        if self.anchors_ is not None:
            notes.append(f"stage boundaries placed along the expected stage of the rig's adaptation records (the "
                         f"ordinal rule), which assumes those records covered the {self.n_classes_} stages in about "
                         "the archive's equal shares")
        raw, rec, lab, prepared, _, features = streamed or self._streamed(recs, features=True)
        p = self._match(raw.mean(0))
        members = self._member_stages(raw)
        g = pairwise_agreement(members)
        m = g.shape[0]
        agreement = float((g.sum() - m) / (m * (m - 1)))
        k = self.n_classes_
        record_p = np.stack([p[rec == i].mean(0) for i in range(len(prepared))])
        expected = record_p @ np.arange(k)
        order = check_order(features, expected, self.twin_trends_)
        if time_ordered is False:
            idx, how = None, "not used"
        elif time_ordered:
            idx, how = np.arange(len(recs)), "the order given"
        else:
            idx, how = time_order(recs)
        ordered = None
        if idx is not None:
            ordered = np.empty(len(recs), dtype=np.int64)
            ordered[idx] = monotone_stages(record_p[idx])
        out = []
        for i, q in enumerate(prepared):
            sel = rec == i
            ms = members[:, sel]
            ag = float(np.mean([np.mean(ms[a] == ms[b]) for a in range(m) for b in range(a + 1, m)]))
            member_rec = tuple(int(np.bincount(s, minlength=k).argmax()) for s in ms)
            s = int(record_p[i].argmax())
            out.append(EnsembleRecord(q.name, s, float(record_p[i, s]), tuple(float(v) for v in record_p[i]),
                                      float(expected[i]), member_rec, ag,
                                      None if ordered is None else int(ordered[i]), q.label))
        moved = 0 if ordered is None else int(np.sum(ordered != record_p.argmax(1)))
        reliable = agreement >= RELIABLE_AGREEMENT and order.verdict == "consistent"
        return EnsembleAssessment(tuple(out), k, m, int(p.shape[0]), agreement, (1 + agreement) / 2, order, how, moved,
                                  reliable, tuple(notes), p.argmax(1).astype(np.int64), lab.astype(np.int64))

    def _check(self) -> None:
        if not hasattr(self, "anchors_"):
            raise AssessorError("this ensemble has no class-prior rule yet: call fit_match() or Ensemble.load()")

    # -- persistence ------------------------------------------------------------------------------
    def save(self, directory) -> Path:
        """Write ``ensemble.json`` beside the members' directories (members given as objects are saved
        as ``member_<i>``)."""
        from twin._atomic import atomic_path, check_output_dir
        self._check()
        d = check_output_dir(directory, "assessor ensemble", create=True)
        dirs = []
        for i, (m, md) in enumerate(zip(self.members, self.member_dirs)):
            if md is None or Path(md).resolve().parent != d.resolve():
                md = str(d / f"member_{m.seed}_{i}")
                m.save(md)
            dirs.append(Path(md).name)
        cfg = {"format": ENSEMBLE_FORMAT, "format_version": ENSEMBLE_VERSION, "members": dirs,
               "facts": self.facts.to_dict(), "rule": self.rule,
               "anchors": None if self.anchors_ is None else [float(v) for v in self.anchors_],
               "log_weights": [float(v) for v in self.log_weights_], "twin_trends": self.twin_trends_,
               "train_time": self.train_time_, "notes": list(self.notes_)}
        with atomic_path(d / "ensemble.json") as tmp:
            Path(tmp).write_text(json.dumps(cfg, indent=1))
        return d

    @classmethod
    def load(cls, directory) -> "Ensemble":
        """Read an ensemble written by :meth:`save` (or :func:`train_ensemble`).

        Raises
        ------
        AssessorError
            Not an ensemble directory, another format, a missing or damaged member.
        """
        from twin.transfer.settings import ArchiveFacts
        d = Path(directory)
        f = d / "ensemble.json"
        if not f.is_file():
            raise AssessorError(f"'{d}' is not a saved assessor ensemble: 'ensemble.json' is missing")
        from twin.transfer.assessor_io import read_saved_json

        cfg = read_saved_json(f, ENSEMBLE_FORMAT, (ENSEMBLE_VERSION,))
        ens = cls([d / m for m in cfg["members"]], ArchiveFacts.from_dict(cfg["facts"]))
        k = ens.n_classes_
        anchors = cfg.get("anchors")
        ens.anchors_ = None if anchors is None else np.asarray(anchors, dtype=float)
        ens.log_weights_ = np.asarray(cfg.get("log_weights", [0.0] * k), dtype=float)
        if (ens.anchors_ is not None and ens.anchors_.shape != (2 * k - 1,)) or ens.log_weights_.shape != (k,):
            raise AssessorError(f"'{f}': anchors must be {2 * k - 1} numbers and log_weights {k}")
        ens.twin_trends_ = {str(n): float(v) for n, v in cfg.get("twin_trends", {}).items()}
        ens.train_time_ = float(cfg.get("train_time", 0.0))
        ens.notes_ = tuple(cfg.get("notes", ()))
        return ens
