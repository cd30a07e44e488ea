"""FusedAdam against torch.optim.Adam(fused=True) (the same kernel: equal bit for bit) and
against Adam's update written out in float64 numpy."""

import numpy as np
import pytest
import torch

from physgs.train.adam import FusedAdam


def _params(seed):
    g = torch.Generator().manual_seed(seed)
    return [
        torch.randn(50, 3, generator=g).requires_grad_(True),
        torch.randn(7, generator=g, dtype=torch.float64).requires_grad_(True),
        torch.randn(4, 4, generator=g).requires_grad_(True),
        torch.randn(5, generator=g).requires_grad_(True),  # never gets a gradient
    ]


def _groups(ps):
    return [
        {"params": ps[:2], "lr": 1e-2, "name": "a"},
        {"params": ps[2:], "lr": 3e-3, "name": "b"},
    ]


def test_steps_equal_torchs_fused_adam_bit_for_bit():
    mine, ref = _params(0), _params(0)
    opt_m = FusedAdam(_groups(mine), eps=1e-15)
    opt_r = torch.optim.Adam(_groups(ref), eps=1e-15, fused=True)
    gen = torch.Generator().manual_seed(1)
    for it in range(6):
        grads = [torch.randn(p.shape, generator=gen, dtype=p.dtype) for p in mine[:3]]
        for ps in (mine, ref):
            for p, gr in zip(ps[:3], grads):
                p.grad = gr.clone()
        for opt in (opt_m, opt_r):
            for g in opt.param_groups:  # the loop's schedule changes the rates every step
                g["lr"] = g["lr"] * 0.9
            if it == 3:  # the omega search's hand-over: a group's moments start again
                opt.state.pop(opt.param_groups[1]["params"][0], None)
            opt.step()
            opt.zero_grad(set_to_none=True)
        for a, b in zip(mine, ref):
            assert torch.equal(a, b)
    assert mine[3] not in opt_m.state and torch.equal(mine[3], ref[3])
    for a, b in zip(mine[:3], ref[:3]):
        for k in ("exp_avg", "exp_avg_sq", "step"):
            assert torch.equal(opt_m.state[a][k], opt_r.state[b][k])


def test_update_equals_adams_formula():
    # Oracle: Adam's bias-corrected update in float64 numpy, three steps.
    p = torch.tensor([0.5, -1.0, 2.0], dtype=torch.float64, requires_grad=True)
    opt = FusedAdam([{"params": [p], "lr": 0.1}], betas=(0.9, 0.99), eps=1e-8)
    x, m, v = p.detach().numpy().copy(), np.zeros(3), np.zeros(3)
    for t, gr in enumerate(([1.0, -2.0, 0.5], [0.3, 0.3, -1.0], [-0.2, 4.0, 0.0]), start=1):
        p.grad = torch.tensor(gr, dtype=torch.float64)
        opt.step()
        g = np.array(gr)
        m = 0.9 * m + 0.1 * g
        v = 0.99 * v + 0.01 * g * g
        x = x - 0.1 * (m / (1 - 0.9**t)) / (np.sqrt(v / (1 - 0.99**t)) + 1e-8)
        np.testing.assert_allclose(p.detach().numpy(), x, rtol=1e-13, atol=1e-15)


def test_zero_grad_and_bad_settings():
    p = torch.zeros(3, requires_grad=True)
    p.grad = torch.ones(3)
    opt = FusedAdam([{"params": [p], "lr": 0.1}])
    opt.zero_grad(set_to_none=False)
    assert torch.equal(p.grad, torch.zeros(3))
    opt.zero_grad()
    assert p.grad is None
    with pytest.raises(ValueError, match="betas"):
        FusedAdam([{"params": [p], "lr": 0.1}], betas=(1.0, 0.9))
    with pytest.raises(ValueError, match="'params' and 'lr'"):
        FusedAdam([{"params": [p]}])
    with pytest.raises(ValueError, match="leaf"):
        FusedAdam([{"params": [p * 2], "lr": 0.1}])
    opt = FusedAdam([{"params": [p], "lr": float("nan")}])
    p.grad = torch.ones(3)
    with pytest.raises(ValueError, match="lr must be finite"):
        opt.step()


def test_a_torch_without_the_fused_kernel_is_named(monkeypatch):
    monkeypatch.delattr(torch, "_fused_adam_")
    with pytest.raises(RuntimeError, match="no torch._fused_adam_"):
        FusedAdam([{"params": [torch.zeros(1, requires_grad=True)], "lr": 0.1}])
