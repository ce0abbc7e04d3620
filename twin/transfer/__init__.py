"""Transfer-learning wear assessment: from the twin's labelled archive to unlabelled rig data.

See ``twin/transfer/README.md`` for the method, the preprocessing and the evaluation protocol.
The public names are resolved lazily, so ``twin --help`` (which registers the transfer commands)
imports neither numpy nor torch; :class:`Assessor` imports torch when it trains or loads.
"""
from __future__ import annotations

import importlib

_WHERE = {"METHODS": "assessor", "Assessment": "assessor", "Assessor": "assessor", "RecordAssessment": "assessor",
          "Agreement": "reliability", "agreement": "reliability", "assessor_agreement": "reliability",
          "TargetShift": "domain", "make_target_domain": "domain", "AssessorError": "errors",
          "ClassPriorWarning": "errors",
          "Augmentation": "preprocess", "Preprocessing": "preprocess", "split_records": "preprocess"}

__all__ = sorted(_WHERE)


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(importlib.import_module(f"twin.transfer.{_WHERE[name]}"), name)
    raise AttributeError(f"module 'twin.transfer' has no attribute {name!r}")
