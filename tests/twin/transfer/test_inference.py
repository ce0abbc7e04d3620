"""twin.transfer.inference: the members' networks folded and run together give each network's own numbers."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from twin.transfer.errors import AssessorError
from twin.transfer.inference import StackedNetworks
from twin.transfer.model import Network


def _trained_like(seed: int, n_classes: int = 4, window: int = 128) -> Network:
    """A network with seeded weights and batch-norm statistics far from the identity (as training leaves them)."""
    torch.manual_seed(seed)
    net = Network(n_classes, window)
    with torch.no_grad():
        for m in net.modules():
            if isinstance(m, torch.nn.BatchNorm1d):
                m.running_mean.normal_(0.0, 0.5)
                m.running_var.uniform_(0.2, 3.0)
                m.weight.normal_(1.0, 0.5)            # some negative scales: the fold must keep their sign
                m.bias.normal_(0.0, 0.3)
    return net.eval()


def _reference(nets, x: np.ndarray) -> np.ndarray:
    with torch.no_grad():
        return np.stack([torch.softmax(n(torch.from_numpy(x).unsqueeze(1))[1], 1).numpy() for n in nets])


@pytest.fixture(scope="module")
def nets():
    return [_trained_like(s) for s in range(3)]


@pytest.fixture(scope="module")
def windows():
    return np.random.default_rng(0).standard_normal((70, 128)).astype(np.float32)


def test_folded_networks_give_each_networks_probabilities(nets, windows):
    ref = _reference(nets, windows)
    fast = StackedNetworks(nets, chunk=16, threads=2).probabilities(windows)
    assert fast.shape == (3, 70, 4) and fast.dtype == np.float32
    np.testing.assert_allclose(fast, ref, rtol=0, atol=2e-6)
    assert np.array_equal(fast.argmax(2), ref.argmax(2))


def test_chunks_and_threads_do_not_change_the_numbers(nets, windows):
    a = StackedNetworks(nets, chunk=16, threads=1).probabilities(windows)
    b = StackedNetworks(nets, chunk=16, threads=2).probabilities(windows)
    c = StackedNetworks(nets, chunk=70, threads=1).probabilities(windows)
    assert np.array_equal(a, b)
    np.testing.assert_allclose(a, c, rtol=0, atol=2e-6)
    before = torch.get_num_threads()
    StackedNetworks(nets, threads=2).probabilities(windows)
    assert torch.get_num_threads() == before                 # torch's setting restored


def test_each_member_can_see_its_own_windows(nets, windows):
    per_member = np.stack([windows, 2 * windows, windows[::-1].copy()])
    fast = StackedNetworks(nets, chunk=32).probabilities(per_member)
    ref = np.stack([_reference([n], w)[0] for n, w in zip(nets, per_member)])
    np.testing.assert_allclose(fast, ref, rtol=0, atol=2e-6)


def test_bad_networks_and_windows_are_refused(nets, windows):
    with pytest.raises(AssessorError, match="no networks"):
        StackedNetworks([])
    with pytest.raises(AssessorError, match="differ in shape"):
        StackedNetworks([nets[0], _trained_like(5, n_classes=3)])
    with pytest.raises(AssessorError, match="chunk must be"):
        StackedNetworks(nets, chunk=0)
    with pytest.raises(AssessorError, match=r"shape \(n, 128\)"):
        StackedNetworks(nets).probabilities(windows[:, :64])
    with pytest.raises(AssessorError, match=r"\(3, n, 128\)"):
        StackedNetworks(nets).probabilities(np.stack([windows, windows]))
