"""The fused per-part transform against its torch ops (float64 autograd) and finite differences."""

import pytest
import torch

from physgs.models.part_transform import transform_parts, _transform_parts_torch


def _inputs(N, K, dtype, seed=0):
    g = torch.Generator().manual_seed(seed)

    def r(*shape):
        return torch.randn(*shape, generator=g, dtype=dtype).requires_grad_(True)

    labels = torch.randint(0, K, (N,), generator=g)
    return r(N, 3), r(N, 4), labels, r(K, 3, 3), r(K, 3), r(K, 3), r(K, 4)


def test_values_and_gradients_equal_the_torch_ops():
    x = _inputs(300, 6, torch.float64)
    w = torch.randn(300, 7, generator=torch.Generator().manual_seed(1), dtype=torch.float64)
    grads = []
    outs = []
    for f in (transform_parts, _transform_parts_torch):
        m, q = f(*x)
        outs.append((m.detach(), q.detach()))
        loss = (torch.cat([m, q], 1) * w).sum()
        diff = [v for i, v in enumerate(x) if i != 2]
        grads.append(torch.autograd.grad(loss, diff))
    for a, b in zip(outs[0], outs[1]):
        torch.testing.assert_close(a, b, rtol=0, atol=1e-14)
    for a, b in zip(grads[0], grads[1]):
        torch.testing.assert_close(a, b, rtol=1e-13, atol=1e-12)


def test_gradients_against_finite_differences():
    means, quats, labels, M, c, t, Q = _inputs(20, 3, torch.float64, seed=2)
    assert torch.autograd.gradcheck(
        lambda *v: transform_parts(v[0], v[1], labels, *v[2:]), (means, quats, M, c, t, Q)
    )


def test_float32_in_float32_out_within_rounding():
    x = _inputs(200, 5, torch.float32, seed=3)
    m, q = transform_parts(*x)
    assert m.dtype == q.dtype == torch.float32
    ref = _transform_parts_torch(*[v.detach().double() if v.is_floating_point() else v for v in x])
    torch.testing.assert_close(m.double(), ref[0], rtol=0, atol=1e-5)
    torch.testing.assert_close(q.double(), ref[1], rtol=0, atol=1e-5)
    (m.sum() + q.sum()).backward()
    assert x[0].grad.dtype == torch.float32 and x[3].grad.dtype == torch.float32


def test_a_zero_transform_leaves_the_gaussians_alone():
    means, quats, labels, M, c, t, Q = _inputs(50, 4, torch.float32, seed=4)
    ident = torch.tensor([1.0, 0.0, 0.0, 0.0]).expand(4, 4)
    m, q = transform_parts(means, quats, labels, torch.zeros(4, 3, 3), c, torch.zeros(4, 3), ident)
    assert torch.equal(m, means.detach()) and torch.equal(q, quats.detach())


def test_bad_labels_and_shapes_are_refused():
    means, quats, labels, M, c, t, Q = _inputs(10, 3, torch.float64)
    with pytest.raises(ValueError, match=r"labels must lie in \[0, 3\)"):
        transform_parts(means, quats, labels + 3, M, c, t, Q)
    with pytest.raises(ValueError, match="expected means"):
        transform_parts(means, quats, labels, M, c, t[:2], Q)


def test_an_in_place_edit_before_the_backward_is_refused():
    means, quats, labels, M, c, t, Q = _inputs(10, 2, torch.float64)
    leaf = means.detach().clone().requires_grad_(True)
    moved = leaf * 1.0  # a non-leaf input, as a model's activated tensors are
    m, q = transform_parts(moved, quats, labels, M, c, t, Q)
    with torch.no_grad():
        moved.add_(1.0)
    with pytest.raises(RuntimeError, match="modified by an inplace operation"):
        (m.sum() + q.sum()).backward()
