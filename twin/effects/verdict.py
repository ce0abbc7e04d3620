"""The verdict of a diagnosis: its records (:class:`Evidence`, :class:`Candidate`,
:class:`Diagnosis`) and the rule that says whether a candidate earns its place (:func:`judge`).

A candidate's score is the relative cut of the log-spectral distance (LSD, dB) it achieves on the
record it was fitted on; a baseline finding is *explained* by it when the squared dB error in the
finding's band falls by at least half (:func:`_explained`). :func:`judge` turns the ranked
candidates into one of ``missing_effect``, ``tie``, ``base_not_calibrated``, ``unexplained``,
``nothing_missing``; :mod:`twin.effects.diagnose` runs the trials that produce the candidates.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from twin.compare import Comparison, Finding
from twin.effects.catalogue import Effect
from twin.operating import Operating

MIN_CUT = 0.25      # relative LSD cut for a candidate to count as the missing effect
MIN_DB = 0.15       # and absolute cut [dB] (the LSD floor of a complete model is about 0.3-0.4 dB)
MIN_SHARE = 0.05    # findings below this share of the error are not reported as unexplained
BASE_BANDS = 2      # separate bands of broadband level off by 6 dB or more ...
BASE_SHARE = 0.5    # ... holding this share of the error: the base model, not an effect, is wrong
#: findings measured in a domain of their own (not the log spectrum): a candidate explains one when
#: it is gone from the candidate's comparison
OWN_EVIDENCE = ("impulsive", "envelope_line")
HELD_OUT_DB = 0.05  # LSD cut [dB] a candidate must keep on every record it was not fitted on
TIE_RATIO = 0.8     # two candidates explaining the same findings within this score ratio are a tie


@dataclass(frozen=True)
class Evidence:
    finding: str             # the finding's description
    kind: str
    reason: str              # why the effect explains it, physically
    error_before: float      # squared dB error in the finding's band, baseline
    error_after: float       # the same with the effect fitted


@dataclass(frozen=True)
class Candidate:
    effect: str
    title: str
    score: float                         # relative cut of the LSD (0..1)
    lsd_after_db: float                  # expected discrepancy after adding it [dB]
    fitted: dict[str, float]             # FMU parameter name -> value
    evidence: tuple[Evidence, ...]       # baseline findings it explains
    findings_after: tuple[Finding, ...]
    n_evaluations: int
    error: str | None = None             # set when the trial failed
    # records it was not fitted on: (record, LSD of the base model [dB], LSD with it [dB])
    held_out: tuple[tuple[str, float, float], ...] = ()
    signature_present: bool | None = None   # its physical signature in the data (None: not tested)
    signature: str = ""                     # what was looked for and found

    def held_out_cut(self) -> float | None:
        """Smallest LSD cut [dB] over the held-out records (None without one)."""
        return min((b - a for _, b, a in self.held_out), default=None)


@dataclass(frozen=True)
class Diagnosis:
    record: str
    lsd_db: float                        # baseline headline discrepancy [dB]
    findings: tuple[Finding, ...]        # baseline findings
    candidates: tuple[Candidate, ...]    # best first
    verdict: str                         # "missing_effect", "nothing_missing", "unexplained", "base_not_calibrated"
    missing: str | None                  # id of the effect to add
    unexplained: tuple[str, ...]         # findings no candidate explains
    message: str
    operating: Operating
    wall_time_s: float
    held_out_records: tuple[str, ...] = ()   # records scored but not fitted on
    runup: str | None = None                 # the run-up the signatures were read from
    tied: tuple[str, ...] = ()               # verdict "tie": the effects that explain the same thing
    baseline: tuple[str, ...] = ()           # baseline records whose model discrepancy was taken out
    encoder: bool = False                    # the pinion encoder compared too: lsd_db is the two channels' RMS
    baseline_repeats: tuple[str, ...] = ()   # baseline records whose scatter raised the line threshold

    def to_dict(self) -> dict:
        return {"record": self.record, "held_out_records": list(self.held_out_records), "runup": self.runup,
                "baseline": list(self.baseline), "baseline_repeats": list(self.baseline_repeats),
                "encoder": self.encoder, "verdict": self.verdict, "missing": self.missing, "tied": list(self.tied),
                "message": self.message, "headline": {"log_spectral_distance_db": self.lsd_db},
                "operating": asdict(self.operating),
                "findings": [asdict(f) for f in self.findings],
                "candidates": [{"effect": c.effect, "title": c.title, "score": c.score,
                                "expected_log_spectral_distance_db": c.lsd_after_db,
                                "fitted_parameters": c.fitted, "n_evaluations": c.n_evaluations,
                                "error": c.error,
                                "held_out": [{"record": r, "log_spectral_distance_db": {"before": b, "after": a}}
                                             for r, b, a in c.held_out],
                                "signature_present": c.signature_present, "signature": c.signature,
                                "evidence": [asdict(e) for e in c.evidence]} for c in self.candidates],
                "unexplained": list(self.unexplained), "wall_time_s": self.wall_time_s}

    def table(self) -> str:
        """Plain-text ranking for the terminal."""
        rows = [f"baseline log-spectral distance {self.lsd_db:.2f} dB on {self.record}"
                + (" (casing and encoder, RMS of the two)" if self.encoder else "")
                + f", {len(self.findings)} findings"
                + (f"; held out: {', '.join(self.held_out_records)}" if self.held_out_records else "")
                + (f"; the model's discrepancy on baseline {', '.join(self.baseline)} taken out" if self.baseline
                   else "")
                + (f", the line threshold raised by how far {', '.join(self.baseline_repeats)} differs"
                   if self.baseline_repeats else ""),
                f"{'rank':>4}  {'effect':<24} {'score':>6}  {'LSD after':>9}  {'held-out cut':>12}  signature  explains"]
        for i, c in enumerate(self.candidates):
            ex = "; ".join(e.kind for e in c.evidence) or ("failed: " + c.error if c.error else "-")
            cut = c.held_out_cut()
            held = f"{cut:+9.2f} dB" if cut is not None else f"{'-':>12}"
            sig = {True: "present", False: "absent", None: "-"}[c.signature_present]
            rows.append(f"{i + 1:>4}  {c.effect:<24} {c.score:>6.2f}  {c.lsd_after_db:>7.2f} dB  {held:>12}  "
                        f"{sig:<9}  {ex}")
        rows.append(self.message)
        return "\n".join(rows)


def fits(before: Comparison, c: Candidate, min_cut: float = MIN_CUT, min_db: float = MIN_DB) -> bool:
    """The candidate cuts the LSD of the record it was fitted on by ``min_cut`` and ``min_db``."""
    return c.error is None and c.score >= min_cut and before.lsd_db - c.lsd_after_db >= min_db


def judge(before: Comparison, candidates: Sequence[Candidate], *, min_cut: float = MIN_CUT,
          min_db: float = MIN_DB, held_out_db: float = HELD_OUT_DB,
          tie_ratio: float = TIE_RATIO) -> tuple[str, str | None, tuple[str, ...], str, tuple[str, ...]]:
    """The verdict on a baseline comparison and its ranked candidates (best first):
    ``(verdict, missing effect id or None, unexplained findings, message, tied effect ids)``.

    A candidate **earns its place** when (a) it cuts the LSD of the record it was fitted on by
    ``min_cut`` and ``min_db``; (b) on every record it was not fitted on (``Candidate.held_out``:
    another steady record, the run-up) it still cuts the LSD by ``held_out_db``: the held-out
    test is the penalty for its added freedom, since a free mode that absorbs what the base
    model gets wrong on one record does not carry to another; and (c) its physical signature
    is not absent from the data (``Candidate.signature_present``, :mod:`twin.effects.signatures`).
    With one record (b) and (c) are not tested.

    ``missing_effect``: the best candidate that earns its place. ``tie``: another that earned
    its place explains the same findings (one's explained findings contain the other's) and
    scores at least ``tie_ratio`` of it; both are named, neither is added (only among
    candidates tested on held-out records: with one record the fit score is all there is).
    Otherwise ``base_not_calibrated`` when the discrepancy is mostly broadband level off in two
    or more separate bands (resonance findings of +-``resonance_db``, by default 6 dB: modes or
    a transfer path in the wrong place, which one added effect cannot mend and which would mask
    any effect); ``unexplained`` for other large findings; else ``nothing_missing``. Candidates
    that fitted but did not earn their place are named in the message, with the reason.
    """
    # an envelope series counts whatever its share of the spectral error: it is thresholded in the
    # envelope, and its band often lies above the compared one
    big = [fd for fd in before.findings if fd.share >= MIN_SHARE or fd.kind == "envelope_line"]
    fitted = [c for c in candidates if fits(before, c, min_cut, min_db)]

    def held_ok(c: Candidate) -> bool:
        cut = c.held_out_cut()
        return cut is None or cut >= held_out_db

    earned = [c for c in fitted if held_ok(c) and c.signature_present is not False]
    if earned:
        best = earned[0]
        explained = {e.finding for e in best.evidence}
        same = [c for c in earned[1:] if best.held_out and c.held_out and c.score >= tie_ratio * best.score
                and ({e.finding for e in c.evidence} <= explained or explained <= {e.finding for e in c.evidence})]
        unexplained = tuple(fd.description for fd in big if fd.description not in explained)
        if same:
            tied = (best.effect, *(c.effect for c in same))
            msg = (f"tie: {' and '.join(tied)} explain the same findings (scores "
                   f"{', '.join(f'{c.score:.2f}' for c in (best, *same))}) and each holds on the held-out records; "
                   "the records cannot tell them apart: add a record that separates them (another speed or load)")
            return "tie", None, unexplained, msg, tied
        msg = (f"missing: {best.effect} ({best.title}); adding it is expected to cut the log-spectral distance "
               f"from {before.lsd_db:.2f} to {best.lsd_after_db:.2f} dB ({100 * best.score:.0f} %)")
        if best.held_out:
            msg += "; held out: " + ", ".join(f"{r} {b:.2f} -> {a:.2f} dB" for r, b, a in best.held_out)
        if best.signature_present:
            msg += f"; signature: {best.signature}"
        if unexplained:
            msg += "; unexplained: " + "; ".join(unexplained)
        return "missing_effect", best.effect, unexplained, msg, ()
    refused = ""
    if fitted:
        why = []
        for c in fitted:
            r = []
            if not held_ok(c):
                r.append("held out " + ", ".join(f"{n} {b:.2f} -> {a:.2f} dB" for n, b, a in c.held_out))
            if c.signature_present is False:
                r.append(c.signature)
            why.append(f"{c.effect} (cut {100 * c.score:.0f} % where fitted; {'; '.join(r)})")
        refused = "; fitted but did not earn its place: " + "; ".join(why)
    bands = [fd for fd in big if fd.kind == "resonance"]
    share = sum(fd.share for fd in bands)
    if len(bands) >= BASE_BANDS and share >= BASE_SHARE:
        where = ", ".join(f"{fd.frequency_hz:.0f} Hz ({fd.size_db:+.0f} dB)"
                          for fd in sorted(bands, key=lambda fd: fd.frequency_hz))
        msg = (f"base model not calibrated well enough to diagnose: its level is off in {len(bands)} bands "
               f"({where}), {100 * share:.0f} % of the discrepancy, which no single effect mends; calibrate the "
               "modes near these frequencies first (twin modes RUNUP, then twin calibrate --modes-from RUNUP)")
        return "base_not_calibrated", None, tuple(fd.description for fd in big), msg + refused, ()
    if big:
        unexplained = tuple(fd.description for fd in big)
        return "unexplained", None, unexplained, ("no catalogue effect explains the discrepancy; unexplained: "
                                                  + "; ".join(unexplained) + refused), ()
    return "nothing_missing", None, (), (f"nothing missing: no localised finding, and no catalogue effect cuts the "
                                         f"log-spectral distance ({before.lsd_db:.2f} dB) by {100 * min_cut:.0f} %"
                                         + refused), ()


def _band_error(comp: Comparison, band: tuple[float, float]) -> float:
    d2 = (comp.level_measured - comp.level_model) ** 2
    sel = (comp.freqs >= band[0] - 1e-9) & (comp.freqs <= band[1] + 1e-9)
    return float(np.sum(d2[sel]))


def finding_error(comp: Comparison, fd: Finding) -> float:
    """Sum of the squared dB differences in a finding's band, on the channel it was found on
    (the encoder's for an ``angular_line``; 0 when the comparison has no encoder channel)."""
    if fd.kind == "angular_line":
        from twin.angular import band_error
        return band_error(comp.angular, fd.band_hz) if comp.angular is not None else 0.0
    return _band_error(comp, fd.band_hz)


def _explained(before: Comparison, after: Comparison, eff: Effect) -> tuple[Evidence, ...]:
    out = []
    for fd in before.findings:
        if fd.kind in OWN_EVIDENCE:
            left = [g for g in after.findings if g.kind == fd.kind and (fd.order is None or g.order is None
                                                                        or abs(g.order - fd.order) <= 0.02 * fd.order)]
            if not left and fd.kind in eff.evidence:
                out.append(Evidence(fd.description, fd.kind, eff.evidence[fd.kind], fd.size_db, 0.0))
            continue
        e0, e1 = finding_error(before, fd), finding_error(after, fd)
        if e0 > 0 and e1 <= 0.5 * e0:
            reason = eff.evidence.get(fd.kind, "fitting the effect removes this part of the error")
            out.append(Evidence(fd.description, fd.kind, reason, e0, e1))
    return tuple(out)
