"""The network of section 2.3.1: shapes and the pooling shortcut."""
from __future__ import annotations

import torch

from twin.transfer.model import FeatureExtractor, MaxPool2, Network


def test_maxpool2_equals_maxpool1d():
    x = torch.randn(3, 4, 34)
    assert torch.equal(MaxPool2()(x), torch.nn.MaxPool1d(2)(x))


def test_architecture_shapes_and_channels():
    g = FeatureExtractor(2048)
    convs = [m for m in g.modules() if isinstance(m, torch.nn.Conv1d)]
    assert [c.out_channels for c in convs] == [4, 8, 16, 32, 64]
    assert all(c.kernel_size == (9,) for c in convs)
    net = Network(6, 2048).eval()
    with torch.no_grad():
        f, logits = net(torch.zeros(2, 1, 2048))
    assert f.shape == (2, 300) and logits.shape == (2, 6)
    assert float(f.min()) >= 0                                # after the final ReLU
