"""Losses and the pseudo-label gate on inputs small enough to check by hand."""
from __future__ import annotations

import math

import pytest
import torch

from twin.transfer.errors import AssessorError
from twin.transfer.losses import (class_contrastive_loss, coral_loss, median_bandwidth, mmd_loss,
                                  pseudo_label_gate)


def test_mmd_of_identical_sets_is_zero():
    z = torch.randn(12, 5, generator=torch.Generator().manual_seed(0))
    assert float(mmd_loss(z, z.clone())) < 1e-6


def test_mmd_known_value_single_kernel():
    # k(0,0) = k(1,1) = 1, k(0,1) = exp(-1 / (2 * 1)): MMD^2 = 2 - 2 exp(-1/2)
    v = mmd_loss(torch.tensor([[0.0]]), torch.tensor([[1.0]]), s2=1.0, factors=(1.0,))
    assert float(v) == pytest.approx(2 - 2 * math.exp(-0.5), rel=1e-6)


def test_mmd_multi_kernel_is_mean_of_kernels():
    a, b = torch.tensor([[0.0]]), torch.tensor([[1.0]])
    expected = sum(2 - 2 * math.exp(-1 / (2 * f)) for f in (0.5, 2.0)) / 2
    assert float(mmd_loss(a, b, s2=1.0, factors=(0.5, 2.0))) == pytest.approx(expected, rel=1e-6)


def test_mmd_grows_with_the_shift():
    g = torch.Generator().manual_seed(1)
    a = torch.randn(30, 4, generator=g)
    b = torch.randn(30, 4, generator=g)
    near = float(mmd_loss(a, b + 0.2))
    far = float(mmd_loss(a, b + 2.0))
    assert far > 3 * near


def test_median_bandwidth_by_hand():
    # off-diagonal squared distances of {0, 1, 3}: 1, 4, 9 (twice each); lower median 4 -> s^2 = 2
    assert float(median_bandwidth(torch.tensor([[0.0], [1.0], [3.0]]))) == pytest.approx(2.0)
    assert float(median_bandwidth(torch.zeros(4, 2))) == 1.0     # all coincide: fallback


def test_mmd_rejects_mismatched_feature_sizes():
    with pytest.raises(AssessorError, match=r"\(3, 2\).*\(3, 4\)"):
        mmd_loss(torch.zeros(3, 2), torch.zeros(3, 4))


def test_contrastive_hand_example():
    gs = torch.tensor([[2.0, 0.0]])                   # normalised to (1, 0)
    gt = torch.tensor([[1.0, 0.0], [0.0, 5.0]])       # (1, 0) and (0, 1)
    ys = torch.tensor([0])
    yt = torch.tensor([0, 1])
    # same class, d = 0; different class, d = |(1,0)-(0,1)|^2 = 2 -> max(0, m - 2)
    assert float(class_contrastive_loss(gs, ys, gt, yt, margin=1.0)) == pytest.approx(0.0)
    assert float(class_contrastive_loss(gs, ys, gt, yt, margin=3.0)) == pytest.approx((0 + 1) / 2)
    # a same-class pair far apart is pulled: d = 2
    assert float(class_contrastive_loss(gs, ys, gt[1:], torch.tensor([0]))) == pytest.approx(2.0)


def test_contrastive_mask_and_diagonal():
    gs = torch.tensor([[1.0, 0.0], [0.0, 1.0]])
    gt = torch.tensor([[0.0, 1.0], [0.0, 1.0]])
    ys = torch.tensor([0, 1])
    yt = torch.tensor([0, 1])
    # diagonal pairs: (s0, t0) same class d=2; (s1, t1) same class d=0 -> mean 1
    assert float(class_contrastive_loss(gs, ys, gt, yt, pairs="diagonal")) == pytest.approx(1.0)
    # masking t0 out leaves only (s1, t1)
    m = torch.tensor([False, True])
    assert float(class_contrastive_loss(gs, ys, gt, yt, m, pairs="diagonal")) == pytest.approx(0.0)
    # nothing gated in: zero, but still differentiable
    gs.requires_grad_(True)
    v = class_contrastive_loss(gs, ys, gt, yt, torch.tensor([False, False]))
    assert float(v.detach()) == 0.0
    v.backward()
    with pytest.raises(AssessorError, match="pairs"):
        class_contrastive_loss(gs, ys, gt, yt, pairs="some")


def test_contrastive_sum_is_eq18_over_gated_target_windows():
    # source (1,0) class 0 and (0,1) class 1; targets (1,0) and (0,1), pseudo-labels 0 and 0
    gs = torch.tensor([[1.0, 0.0], [0.0, 1.0]])
    gt = torch.tensor([[1.0, 0.0], [0.0, 1.0]])
    ys, yt = torch.tensor([0, 1]), torch.tensor([0, 0])
    # pair terms (margin 3): (s0,t0) same d=0 -> 0; (s1,t0) diff d=2 -> 1;
    #                        (s0,t1) same d=2 -> 2; (s1,t1) diff d=0 -> 3
    # diagonal: 0 + 3 = 3 (Eq. 18), mean 1.5
    assert float(class_contrastive_loss(gs, ys, gt, yt, margin=3.0, pairs="diagonal", reduction="sum")) == \
        pytest.approx(3.0)
    # all pairs: each target window's mean over the sources, summed: (0+1)/2 + (2+3)/2 = 3; mean 1.5
    assert float(class_contrastive_loss(gs, ys, gt, yt, margin=3.0, reduction="sum")) == pytest.approx(3.0)
    assert float(class_contrastive_loss(gs, ys, gt, yt, margin=3.0)) == pytest.approx(1.5)
    # a gated-out target window drops its terms from the sum
    m = torch.tensor([False, True])
    assert float(class_contrastive_loss(gs, ys, gt, yt, m, margin=3.0, reduction="sum")) == pytest.approx(2.5)
    assert float(class_contrastive_loss(gs, ys, gt, yt, m, margin=3.0, pairs="diagonal", reduction="sum")) == \
        pytest.approx(3.0)
    with pytest.raises(AssessorError, match="reduction"):
        class_contrastive_loss(gs, ys, gt, yt, reduction="max")


def test_pseudo_label_gate_threshold_and_warmup():
    p = torch.tensor([[0.95, 0.05], [0.6, 0.4], [0.1, 0.9]])
    labels, mask = pseudo_label_gate(p, epoch=4, threshold=0.9, warmup_epochs=5)
    assert labels.tolist() == [0, 0, 1]
    assert mask.tolist() == [False, False, False]             # still warming up
    labels, mask = pseudo_label_gate(p, epoch=5, threshold=0.9, warmup_epochs=5)
    assert mask.tolist() == [True, False, True]               # 0.9 passes (>=), 0.6 does not
    _, mask = pseudo_label_gate(p, epoch=5, threshold=0.5, warmup_epochs=0)
    assert mask.tolist() == [True, True, True]


def test_coral_zero_for_same_covariance_and_positive_otherwise():
    g = torch.Generator().manual_seed(2)
    a = torch.randn(50, 3, generator=g)
    assert float(coral_loss(a, a + 5.0)) < 1e-10            # a mean shift has the same covariance
    assert float(coral_loss(a, 3 * a)) > 0.01
