"""Fast inference: the networks of an ensemble run over many windows at once.

::

    from twin.transfer.inference import StackedNetworks
    fast = StackedNetworks([m.network_ for m in ensemble.members])
    p = fast.probabilities(x)            # (members, n, K) stage probabilities of windows x (n, window)
    p, rec, lab, prepared, records, features = assess_stream(ensemble, "rig.h5", features=True)

It computes what ``Assessor._forward`` computes for each member (the reference path, kept for
training), to float32 round-off (``tests/twin/transfer/test_inference.py``), with less work:

* **batch norm folded**: in eval mode a ``BatchNorm1d`` is the affine map ``gamma (y - mean) /
  sqrt(var + eps) + beta`` of its running statistics, so it is folded into the weights and bias of
  the convolution or linear layer before it, once per ensemble instead of once per window;
* **ReLU after the max-pool**: ``max`` is monotone, so ``relu(max(a, b)) = max(relu(a), relu(b))``
  exactly, and the ReLU touches half the samples;
* **the first layer in blocks**: its one input channel seen as 4 channels of blocks of 4
  consecutive samples, and its 9 taps as a 3-tap convolution over blocks (:func:`_blocked`):
  the same products, in a layout oneDNN has a fast kernel for (6 x faster); the linear layer's
  weights are reordered to the channels-last flattening, so the activations are not copied;
* **channels last**: the convolutions run as 2-D convolutions of height 1 on (n, channels, 1,
  samples) tensors stored channels innermost, the layout in which oneDNN's kernels for these narrow
  layers are fastest (2.3 x over ``conv1d`` for the five layers, 1 thread, trial of 2026-11-26),
  and the pool is the elementwise maximum of the even and odd samples, whole contiguous rows of
  channels;
* **windows in chunks** of ``chunk`` (bounded memory: the first layer's output of a 128-window
  chunk is 4 MB), under :func:`torch.inference_mode` (no autograd bookkeeping);
* **chunks and members in parallel**: each member's pass over a chunk is one task (so the last
  chunk's members still share the cores) on ``threads`` worker threads, each running torch with
  one intra-op thread.  On a 2-core machine that other work shares, torch's own two OpenMP threads wait for
  each other at every layer and lose to a descheduled partner (with two other jobs running, the
  per-member path took 2.1 x as long with torch's 2 threads as with 1, trial of 2026-11-26);
  independent chunks do not wait.  torch's thread count is restored afterwards.

The result does not depend on ``threads``: every chunk goes through the same single-threaded
kernels whichever worker takes it.
"""
from __future__ import annotations

import os
import threading
from collections import deque
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["DEFAULT_CHUNK", "StackedNetworks", "Stream", "assess_stream", "default_threads"]

DEFAULT_CHUNK = 128
# samples per block of each convolution layer (_blocked), 1 = the plain convolution: the first
# layer, of one input channel, runs 6 x faster as 4 channels of blocks of 4 samples (oneDNN has
# no fast kernel for one input channel); for the others blocks gained nothing that held (1
# thread, 128-window chunks, trial of 2026-11-26)
BLOCKS = (4, 1, 1, 1, 1)
# torch.set_num_threads is process-wide: concurrent calls must not restore each other's setting
_THREADS_LOCK = threading.Lock()


def default_threads() -> int:
    """Worker threads for inference: the cores this process may use (more workers than cores
    only queue)."""
    return max(1, len(os.sched_getaffinity(0)))


def _blocked(weight, bias, block: int):
    """A 'same'-padded convolution of odd kernel K over (n, c_in, 1, L) samples, as one of kernel
    ``2 ceil((K // 2) / block) + 1`` over (n, block c_in, 1, L / block) blocks of ``block``
    consecutive samples.

    ``weight`` (c_out, c_in, 1, K) -> ((block c_out, block c_in, 1, taps) channels last, bias
    (block c_out,), padding in blocks).  Output channel ``r c_out + o`` of block ``j`` is channel
    ``o`` at sample ``block j + r``, so in channels-last memory the blocked input and output are
    the plain channels-last ones, read with other strides.  The same products with the same
    weights; the extra taps are zeros."""
    import torch
    c_out, c_in, _, k = weight.shape
    half = k // 2
    m = -(-half // block)
    w = torch.zeros(block * c_out, block * c_in, 1, 2 * m + 1, dtype=weight.dtype)
    for r in range(block):                       # output sample within the block
        for s in range(block):                   # input sample within its block
            for j in range(2 * m + 1):           # input block, relative to the output's, + m
                tap = s - r + half + block * (j - m)
                if 0 <= tap < k:
                    w[r * c_out:(r + 1) * c_out, s * c_in:(s + 1) * c_in, 0, j] = weight[:, :, 0, tap]
    return w.contiguous(memory_format=torch.channels_last), bias.repeat(block).contiguous(), m


def _fold(weight, bias, bn):
    """(weight, bias) of a conv or linear layer followed by an eval-mode batch norm, as one layer.

    ``weight`` (out, ...), ``bias`` (out,); returns detached float32 tensors."""
    import torch
    with torch.no_grad():
        s = bn.weight / torch.sqrt(bn.running_var + bn.eps)
        w = weight * s.reshape(-1, *([1] * (weight.dim() - 1)))
        b = (bias - bn.running_mean) * s + bn.bias
    return w.detach().contiguous(), b.detach().contiguous()


class StackedNetworks:
    """Several trained :class:`~twin.transfer.model.Network` of one shape, evaluated together.

    Parameters
    ----------
    networks : sequence of Network
        Trained networks (their batch norms' running statistics are used, as in eval mode); the
        weights are copied, later changes to the networks are not seen.
    chunk : int
        Windows per forward pass.
    threads : int, optional
        Worker threads (default :func:`default_threads`).

    Raises
    ------
    AssessorError
        No networks, networks of different shapes, a bad chunk or thread count.
    """

    def __init__(self, networks: Sequence, *, chunk: int = DEFAULT_CHUNK, threads: int | None = None):
        import torch
        from torch import nn

        from twin.transfer.model import MaxPool2

        nets = list(networks)
        if not nets:
            raise AssessorError("StackedNetworks: no networks")
        threads = default_threads() if threads is None else threads
        for name, v in (("chunk", chunk), ("threads", threads)):
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise AssessorError(f"StackedNetworks: {name} must be an integer >= 1, got {v!r}")
        self.chunk, self.threads = chunk, threads
        self._members = []
        for net in nets:
            layers = list(net.G.conv)
            convs = []
            # the flattened features are (last channels) x (window halved by every pool)
            window = net.G.fc[1].in_features // layers[-4].out_channels << len(layers) // 4
            for i in range(0, len(layers), 4):
                conv, bn, relu, pool = layers[i:i + 4]
                if not (isinstance(conv, nn.Conv1d) and isinstance(bn, nn.BatchNorm1d) and isinstance(relu, nn.ReLU)
                        and isinstance(pool, MaxPool2)):
                    raise AssessorError("StackedNetworks: a convolution module is not Conv1d, BatchNorm1d, ReLU, "
                                        "MaxPool2")
                w, b = _fold(conv.weight, conv.bias, bn)
                w = w.unsqueeze(2)
                length = window >> (i // 4)              # samples into this layer
                block = BLOCKS[i // 4] if i // 4 < len(BLOCKS) else 1
                if block > 1 and length % block == 0 and conv.padding[0] == w.shape[-1] // 2:
                    convs.append(_blocked(w, b, block) + (block,))
                else:
                    convs.append((w.contiguous(memory_format=torch.channels_last), b, conv.padding[0], 1))
            _, lin, bn, _ = list(net.G.fc)
            lw, lb = _fold(lin.weight, lin.bias, bn)
            # the features flattened channel by channel, as the channels-last activations lie in memory
            c_last = layers[-4].out_channels
            lw = lw.reshape(lw.shape[0], c_last, -1).transpose(1, 2).reshape(lw.shape[0], -1).contiguous()
            self._members.append((convs, lw, lb, net.C.weight.detach().clone(), net.C.bias.detach().clone()))
        shapes = {tuple(tuple(t.shape) for c in m[0] for t in c[:2]) + (tuple(m[1].shape), tuple(m[3].shape))
                  for m in self._members}
        if len(shapes) > 1:
            raise AssessorError("StackedNetworks: the networks differ in shape (window or stage count)")
        self.window = window
        self.n_classes = int(self._members[0][3].shape[0])
        self._torch = torch

    def __len__(self) -> int:
        return len(self._members)

    def _member(self, x, k: int):
        """Probabilities (n, K) of member ``k`` on one chunk x (n, 1, window)."""
        import torch.nn.functional as F
        torch = self._torch
        convs, lw, lb, cw, cb = self._members[k]
        # (n, channels, 1, samples) with the channels innermost ("channels last"): oneDNN's fast
        # layout for narrow convolutions, and the pool's pairs are whole contiguous rows
        h = x.unsqueeze(2).contiguous(memory_format=torch.channels_last)
        for w, b, pad, block in convs:
            if block > 1:                         # the same memory seen as blocks of samples (_blocked)
                n, c, _, length = h.shape
                h = h.as_strided((n, block * c, 1, length // block), (length * c, 1, length * c, block * c))
                h = F.conv2d(h, w, b, padding=(0, pad)).contiguous(memory_format=torch.channels_last)
                c = w.shape[0] // block
                h = h.as_strided((n, c, 1, length), (length * c, 1, length * c, c))
            else:
                h = F.conv2d(h, w, b, padding=(0, pad))
            length = h.shape[-1] - h.shape[-1] % 2
            h = torch.maximum(h[..., 0:length:2], h[..., 1:length:2]).relu_() \
                .contiguous(memory_format=torch.channels_last)
        g = F.linear(h.permute(0, 2, 3, 1).flatten(1), lw, lb).relu_()
        return torch.softmax(F.linear(g, cw, cb), 1)

    def _run(self, x: np.ndarray, k: int) -> np.ndarray:
        """Member ``k``'s probabilities (n, K) of windows x (n, window) or (members, n, window)."""
        with self._torch.inference_mode():
            return self._member(self._torch.from_numpy(x if x.ndim == 2 else x[k]).unsqueeze(1), k).numpy()

    def _checked(self, x) -> np.ndarray:
        m = len(self._members)
        x = np.ascontiguousarray(x, dtype=np.float32)
        if x.shape[-1:] != (self.window,) or x.ndim not in (2, 3) or (x.ndim == 3 and x.shape[0] != m):
            raise AssessorError(f"StackedNetworks: windows must have shape (n, {self.window}) or ({m}, n, "
                                f"{self.window}), got {x.shape}")
        return x

    def stream(self) -> "Stream":
        """A context in which windows are given piece by piece (:meth:`Stream.add`) and evaluated
        on the worker threads while the caller prepares the next piece; :meth:`Stream.result`
        after the context gives what :meth:`probabilities` gives for all the pieces at once."""
        return Stream(self)

    def probabilities(self, x: np.ndarray) -> np.ndarray:
        """Stage probabilities of every member, (members, n, K) float32.

        ``x``: the windows as every member sees them, (n, window), or each member's own, (members,
        n, window) (members whose domain normalisers differ).
        """
        with self.stream() as s:
            s.add(x)
        return s.result()


class Stream:
    """Windows in pieces, evaluated in chunks of ``chunk`` as they fill (:meth:`StackedNetworks.stream`).

    The chunks are cut from the windows in the order given, whatever the pieces, so the numbers
    do not depend on how the windows were split.  torch runs with one thread inside the context.
    """

    def __init__(self, nets: StackedNetworks):
        self._nets = nets
        self._pending, self._n_pending, self._parts = [], 0, []
        self._pool, self._result = None, None

    def __enter__(self) -> "Stream":
        torch = self._nets._torch
        _THREADS_LOCK.acquire()
        self._before = torch.get_num_threads()
        torch.set_num_threads(1)
        if self._nets.threads > 1:
            self._pool = ThreadPoolExecutor(max_workers=self._nets.threads)
        return self

    def add(self, x: np.ndarray) -> None:
        """Windows (n, window) or (members, n, window), after those already given."""
        x = self._nets._checked(x)
        if x.shape[-2] == 0:
            return
        self._pending.append(x)
        self._n_pending += x.shape[-2]
        chunk = self._nets.chunk
        while self._n_pending >= chunk:
            self._submit(chunk)

    def _submit(self, n: int) -> None:
        """Cut the first ``n`` pending windows into one chunk and start it."""
        taken, need = [], n
        while need:
            x = self._pending[0]
            if x.shape[-2] <= need:
                taken.append(self._pending.pop(0))
                need -= x.shape[-2]
            else:
                taken.append(x[..., :need, :])
                self._pending[0] = x[..., need:, :]
                need = 0
        self._n_pending -= n
        x = taken[0] if len(taken) == 1 else np.concatenate(taken, axis=-2)
        # one task per member: the last chunk's members still spread over the workers
        run = self._nets._run
        self._parts.append([self._pool.submit(run, x, k) if self._pool else run(x, k) for k in range(len(self._nets))])

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            if exc_type is None and self._n_pending:
                self._submit(self._n_pending)
            parts = [np.stack([p.result() if self._pool else p for p in ps]) for ps in self._parts] \
                if exc_type is None else []
        finally:
            if self._pool is not None:
                self._pool.shutdown(wait=True, cancel_futures=exc_type is not None)
            self._nets._torch.set_num_threads(self._before)
            _THREADS_LOCK.release()
        if exc_type is None:
            m, k = len(self._nets), self._nets.n_classes
            self._result = np.concatenate(parts, axis=1) if parts else np.zeros((m, 0, k), np.float32)

    def result(self) -> np.ndarray:
        """(members, n, K) probabilities of every window given, in order (after the context)."""
        if self._result is None:
            raise AssessorError("Stream.result: the stream has not finished (use it as a context)")
        return self._result


def assess_stream(ensemble, data, what: str = "assess", features: bool = False, facts=None):
    """An ensemble's raw network probabilities on the windows of ``data`` (members, n, K), record
    index (n,), labels (n,), prepared records, the records read from a path (None otherwise)
    and, with ``features``, the records' order-check features
    (:func:`~twin.transfer.order.record_features`).

    A file is read record by record; each record is resampled, represented (and its
    features computed) on worker threads as soon as it is read, once for all members, while
    the members' networks run on the windows already represented
    (:class:`StackedNetworks`): the two cores share reading, preparing and the networks.

    With ``facts`` (:class:`~twin.transfer.settings.ArchiveFacts`), each record read from a path
    is checked against the assessor's test as it is read
    (:func:`~twin.transfer.settings.record_misfit`): after the first misfit no record is
    prepared any more and the work queued is cancelled; the rest of the file is still read (a
    file with problems gets its :class:`~twin.errors.MeasurementError` first) and its records'
    attributes checked, and one :class:`AssessorError` names every misfit
    (:func:`~twin.transfer.settings.misfit_error`).
    """
    from twin.measurements import MeasurementSet, iter_measurements
    from twin.transfer.preprocess import Prepared, windows_of
    from twin.transfer.settings import misfit_error, record_misfit
    first, pre = ensemble.members[0], ensemble.preprocessing
    records, misfits = None, []
    if isinstance(data, (str, Path)):
        records = []

        def read(path):
            for r in iter_measurements(path, channels=[pre.channel_of("target")], tachometer=False):
                records.append(r)
                reason = None if facts is None else record_misfit(r, facts)
                if reason is not None:
                    misfits.append(reason)
                    if len(misfits) == 1:      # the first: stop preparing (below)
                        yield None
                elif not misfits:              # after a misfit the records are only checked
                    yield [r]
        pieces = read(data)
    else:
        if isinstance(data, MeasurementSet):
            data = list(data.records)
        if isinstance(data, (list, tuple)) and data and not isinstance(data[0], np.ndarray):
            pieces = [list(data[i:i + 1]) for i in range(len(data))]
        else:                                  # window arrays, archives: prepared (and judged) whole
            pieces = [first._prepared(data, None, what, "target")]
    stacked, normalise = ensemble._networks()

    def represent(piece):
        p = piece if isinstance(piece[0], Prepared) else first._prepared(piece, None, what, "target")
        raw, rec, lab = windows_of(p, pre, what)
        return p, normalise(raw), rec, lab, ensemble._features(p) if features else None

    prepared, recs, labs, feats = [], [], [], []
    # numpy's FFTs, scipy's filters and torch release the GIL: the main thread reads while
    # worker threads prepare the records read, handed to the networks in their order
    with stacked.stream() as stream, ThreadPoolExecutor(max_workers=stacked.threads) as pool:
        queue = deque()

        def take():
            p, x, rec, lab, f = queue.popleft().result()
            stream.add(x)
            recs.append(rec + len(prepared))
            labs.append(lab)
            feats.append(f)
            prepared.extend(p)

        for piece in pieces:
            if piece is None:                  # a misfit: what is queued is not prepared, and the
                for fut in queue:              # rest of the file is only read and checked
                    fut.cancel()
                for _ in pieces:
                    pass
                raise misfit_error(misfits, facts, what)
            queue.append(pool.submit(represent, piece))
            while queue and queue[0].done():
                take()
        while queue:
            take()
    if not prepared:
        raise AssessorError(f"{what}: no records")
    f = {k: np.concatenate([v[k] for v in feats]) for k in feats[0]} if features else None
    return stream.result(), np.concatenate(recs), np.concatenate(labs), prepared, records, f
