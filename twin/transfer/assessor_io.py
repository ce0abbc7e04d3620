"""Saving and loading a fitted :class:`twin.transfer.Assessor`: ``config.json`` (parameters,
preprocessing, normalisers, class-prior match, history) and ``weights.pt``, written atomically and
checked field by field when read (:meth:`Assessor.save` and :meth:`Assessor.load` call these)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.transfer.errors import AssessorError
from twin.transfer.preprocess import Augmentation, DomainNormaliser, Preprocessing

if TYPE_CHECKING:
    from twin.transfer.assessor import Assessor

SAVE_FORMAT = "gear-twin-assessor"
SAVE_VERSION = 4
# version 1: waveform only, one scale per domain; version 2: log spectra under one Hann taper, level removed;
# version 3: no class-prior match (its assessors load with zero offsets, as they were trained)
_READABLE_VERSIONS = (1, 2, 3, 4)


def _finite_numbers(value, n: int) -> np.ndarray | None:
    """A saved list of ``n`` finite numbers as an array (n,); None for anything else."""
    if not (isinstance(value, list) and len(value) == n
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        return None
    arr = np.asarray(value, dtype=np.float64)
    return arr if np.all(np.isfinite(arr)) else None


def read_saved_json(path: Path, fmt: str, versions: tuple[int, ...]) -> dict:
    """The JSON file of a saved assessor or ensemble, checked for its ``format`` and one of the
    readable ``versions`` (the last is the current one); AssessorError naming the file otherwise."""
    try:
        cfg = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise AssessorError(f"'{path}' is not valid JSON: {exc}") from None
    if not isinstance(cfg, dict) or cfg.get("format") != fmt or cfg.get("format_version") not in versions:
        found = cfg if not isinstance(cfg, dict) else cfg.get("format")
        version = cfg.get("format_version") if isinstance(cfg, dict) else None
        raise AssessorError(f"'{path}' has format {found!r} version {version!r}; expected {fmt!r} {versions[-1]}")
    return cfg


def save_assessor(self, directory: str | Path) -> Path:
    """Write ``config.json`` (parameters, preprocessing, history) and ``weights.pt`` atomically.

    The directory is created if its parent exists.  Raises :class:`~twin.errors.OutputPathError`
    for a missing parent or a path that is a file.
    """
    import torch

    from twin._atomic import atomic_path, check_output_dir

    self._check_fitted()
    d = check_output_dir(directory, "assessor", create=True)
    aug = self._aug()
    params = {k: getattr(self, k) for k in self._PARAMS if k not in ("preprocessing", "augmentation")}
    config = {"format": SAVE_FORMAT, "format_version": SAVE_VERSION, "params": params,
              "preprocessing": self._pre.to_dict(), "augmentation": aug.to_dict() if aug else None,
              "n_classes": self.n_classes_, "history": self.history_,
              "n_source_windows": self.n_source_windows_, "n_target_windows": self.n_target_windows_,
              "fit_time": getattr(self, "fit_time_", None),
              "source_normaliser": self.source_normaliser_.to_dict(),
              "target_normaliser": self.target_normaliser_.to_dict(),
              "source_prior": (None if getattr(self, "source_prior_", None) is None
                               else [float(v) for v in self.source_prior_]),
              "target_log_weights": [float(v) for v in self.target_log_weights_],
              "ordinal_anchors": (None if getattr(self, "ordinal_anchors_", None) is None
                                  else [float(v) for v in self.ordinal_anchors_]),
              "adaptation_stage_counts": (self.adaptation_stage_counts_.tolist()
                                          if hasattr(self, "adaptation_stage_counts_") else None),
              "class_prior_moved": getattr(self, "class_prior_moved_", None),
              "class_prior_confidence_drop": getattr(self, "class_prior_confidence_drop_", None)}
    with atomic_path(d / "weights.pt") as tmp:
        torch.save({k: v.cpu() for k, v in self.network_.state_dict().items()}, tmp)
    with atomic_path(d / "config.json") as tmp:
        tmp.write_text(json.dumps(config, indent=1))
    return d


def load_assessor(cls, directory: str | Path, device: str | None = None) -> "Assessor":
    """Read an assessor written by :meth:`save`.

    Raises
    ------
    AssessorError
        Missing directory or file, another format or version, inconsistent weights.
    """
    import torch

    from twin.transfer.model import Network

    d = Path(directory)
    cfg_file, w_file = d / "config.json", d / "weights.pt"
    for f in (cfg_file, w_file):
        if not f.is_file():
            raise AssessorError(f"'{d}' is not a saved assessor: '{f.name}' is missing")
    cfg = read_saved_json(cfg_file, SAVE_FORMAT, _READABLE_VERSIONS)
    params = dict(cfg["params"])
    version = cfg["format_version"]
    if version < 4:     # trained before the class-prior match existed
        params["class_prior"] = None
    # saved before the reduction was a parameter: those were trained with the mean
    params.setdefault("contrastive_reduction", "mean")
    if device is not None:
        params["device"] = device
    aug = Augmentation(**cfg["augmentation"]) if cfg["augmentation"] else None
    # version 1 predates the log-spectrum representation: its networks were trained on waveforms
    pre_cfg = {"representation": "waveform", **cfg["preprocessing"]} if version == 1 else cfg["preprocessing"]
    if version < 3:     # before the multitaper spectrum and the kept level
        pre_cfg = {**pre_cfg, "time_bandwidth": 0.0, "remove_level": True}
    a = cls(**params, preprocessing=Preprocessing(**pre_cfg), augmentation=aug)
    net = Network(int(cfg["n_classes"]), a._pre.window)
    try:
        state = torch.load(w_file, map_location="cpu", weights_only=True)
        net.load_state_dict(state)
    except (RuntimeError, KeyError, ValueError, OSError) as exc:   # torch reports bad files as these
        raise AssessorError(f"'{w_file}' does not hold weights for this network: {exc}") from None
    net.to(a._device()).eval()
    a.network_ = net
    a.n_classes_ = int(cfg["n_classes"])
    a.classes_ = np.arange(a.n_classes_)
    a.history_ = cfg["history"]
    a.n_source_windows_ = cfg["n_source_windows"]
    a.n_target_windows_ = cfg["n_target_windows"]
    try:
        if version == 1:
            norms = [DomainNormaliser(0.0, float(cfg[f"{d}_scale"])) for d in ("source", "target")]
        else:
            norms = [DomainNormaliser.from_dict(cfg[f"{d}_normaliser"]) for d in ("source", "target")]
    except (KeyError, TypeError, ValueError) as exc:
        raise AssessorError(f"'{cfg_file}' has no valid domain normalisers: {exc!r}") from None
    for n in norms:
        if np.ndim(n.centre) and np.shape(n.centre) != (a._pre.window,) or not n.scale > 0:
            raise AssessorError(f"'{cfg_file}': a domain normaliser has centre shape {np.shape(n.centre)} "
                                f"and scale {n.scale!r}; expected ({a._pre.window},) or a number, and > 0")
    a.source_normaliser_, a.target_normaliser_ = norms
    # version 4 always writes the offsets: a file without them is damaged, not "no offsets"
    weights = cfg.get("target_log_weights") if version >= 4 else [0.0] * a.n_classes_
    w = _finite_numbers(weights, a.n_classes_)
    if w is None:
        raise AssessorError(f"'{cfg_file}': target_log_weights must be {a.n_classes_} finite numbers, "
                            f"got {weights!r}")
    a.target_log_weights_ = w
    # written since 2026-11-25, for rematch; without it, rematch can only drop the match
    prior, a.source_prior_ = cfg.get("source_prior"), None
    if prior is not None:
        arr = _finite_numbers(prior, a.n_classes_)
        if arr is None or np.any(arr <= 0) or not np.isclose(arr.sum(), 1.0, atol=1e-9):
            raise AssessorError(f"'{cfg_file}': source_prior must be {a.n_classes_} numbers > 0 that sum to 1, "
                                f"got {prior!r}")
        a.source_prior_ = arr
    # written since 2026-11-24; an adapting ordinal assessor cannot assess without them
    anchors, a.ordinal_anchors_ = cfg.get("ordinal_anchors"), None
    if a.class_prior == "ordinal" and a.method != "cnn":
        arr = _finite_numbers(anchors, 2 * a.n_classes_ - 1)
        if arr is None or np.any(np.diff(arr) < 0):
            raise AssessorError(f"'{cfg_file}': class_prior 'ordinal' needs ordinal_anchors, "
                                f"{2 * a.n_classes_ - 1} finite non-decreasing numbers; got {anchors!r}")
        a.ordinal_anchors_ = arr
    elif anchors is not None:
        raise AssessorError(f"'{cfg_file}': ordinal_anchors are only read with class_prior 'ordinal' and a "
                            f"method that adapts; this file has class_prior {a.class_prior!r} and method "
                            f"{a.method!r}")
    # diagnostics of the match, written since 2026-11-23; an older version-4 file has none
    if cfg.get("class_prior_moved") is not None:
        try:
            a.class_prior_moved_ = float(cfg["class_prior_moved"])
            a.adaptation_stage_counts_ = np.asarray(cfg["adaptation_stage_counts"], dtype=np.int64)
        except (KeyError, TypeError, ValueError) as exc:
            raise AssessorError(f"'{cfg_file}': damaged class-prior diagnostics: {exc!r}") from None
        if a.adaptation_stage_counts_.shape != (2, a.n_classes_) or not 0 <= a.class_prior_moved_ <= 1:
            raise AssessorError(f"'{cfg_file}': adaptation_stage_counts must be 2 x {a.n_classes_} and "
                                f"class_prior_moved in [0, 1], got {cfg['adaptation_stage_counts']!r} and "
                                f"{cfg['class_prior_moved']!r}")
    # written since the confidence-drop warning (2026-11-23)
    if cfg.get("class_prior_confidence_drop") is not None:
        drop = cfg["class_prior_confidence_drop"]
        if isinstance(drop, bool) or not isinstance(drop, (int, float)) or not -1 < drop < 1:
            raise AssessorError(f"'{cfg_file}': class_prior_confidence_drop must be a number in (-1, 1), "
                                f"got {drop!r}")
        a.class_prior_confidence_drop_ = float(drop)
    if cfg.get("fit_time") is not None:
        a.fit_time_ = cfg["fit_time"]
    return a
