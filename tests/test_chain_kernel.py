"""The chained transforms' fused pass (physgs.models.chain_kernel) against the torch ops in
float64 under autograd, and central finite differences."""

import numpy as np
import pytest
import torch

from physgs.models.chain import _chain_transforms_torch, chain_transforms, depth_levels
from physgs.models.chain_kernel import fused_chain_transforms, parent_of_levels


def _tree(K, seed):
    """A random tree numbered parents first (one root, part 0) and its inputs."""
    rng = np.random.default_rng(seed)
    parent = np.array([-1] + [int(rng.integers(0, p)) for p in range(1, K)])
    axis = rng.normal(size=(K, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    theta = rng.uniform(-1.2, 1.2, K)
    pivot = rng.normal(size=(K, 3))
    return parent, *(torch.tensor(x, requires_grad=True) for x in (axis, theta, pivot))


@pytest.mark.parametrize("K,seed", [(1, 0), (2, 1), (7, 2), (40, 3)])
def test_values_and_gradients_equal_the_torch_ops_in_float64(K, seed):
    parent, axis, theta, pivot = _tree(K, seed)
    levels = depth_levels(parent)
    assert np.array_equal(parent_of_levels(levels, K), parent)
    rng = np.random.default_rng(seed + 10)
    w = [torch.tensor(rng.normal(size=s)) for s in ((K, 3, 3), (K, 3), (K, 4))]
    got, want = [], []
    for f, out in ((chain_transforms, got), (_chain_transforms_torch, want)):
        res = f(axis, theta, pivot, levels)
        sum((r * wi).sum() for r, wi in zip(res, w)).backward()
        out.extend([r.detach().clone() for r in res])
        # no gradient reaches a lone root's pivot through the torch ops: zeros, as the pass
        out.extend(
            [
                torch.zeros_like(x) if x.grad is None else x.grad.clone()
                for x in (axis, theta, pivot)
            ]
        )
        for x in (axis, theta, pivot):
            x.grad = None
    for g, h in zip(got, want):
        np.testing.assert_allclose(g.numpy(), h.numpy(), rtol=0, atol=1e-12)


def test_gradients_against_finite_differences():
    parent, axis, theta, pivot = _tree(6, 5)
    assert torch.autograd.gradcheck(
        lambda a, t, c: fused_chain_transforms(a, t, c, parent), (axis, theta, pivot), atol=1e-8
    )


def test_one_output_alone_and_float32_inputs():
    # a backward through E alone (u and q get no gradient), and float32 in gives float32 out,
    # equal to the float64 computation on the same rounded inputs to float32 rounding
    parent, axis, theta, pivot = _tree(9, 7)
    a32, t32, c32 = (x.detach().float().requires_grad_(True) for x in (axis, theta, pivot))
    E, u, q = fused_chain_transforms(a32, t32, c32, parent)
    assert E.dtype == u.dtype == q.dtype == torch.float32
    E.sum().backward()
    a64, t64_, c64 = (x.detach().double().requires_grad_(True) for x in (a32, t32, c32))
    E64, _, _ = _chain_transforms_torch(a64, t64_, c64, depth_levels(parent))
    E64.sum().backward()
    np.testing.assert_allclose(E.detach().numpy(), E64.detach().numpy(), atol=1e-6)
    assert c64.grad is None and not c32.grad.any()  # E does not depend on the pivots
    for x, y in ((a32, a64), (t32, t64_)):
        assert x.grad.dtype == torch.float32
        np.testing.assert_allclose(x.grad.numpy(), y.grad.numpy(), rtol=1e-5, atol=1e-5)
