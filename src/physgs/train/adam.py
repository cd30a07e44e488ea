"""Adam as torch's fused kernel, without torch.optim's Optimizer machinery.

`torch.optim.Adam(fused=True)` runs one `torch._fused_adam_` call per parameter group; building
any `torch.optim.Optimizer` first imports `torch._dynamo` (and sympy with it): ~1 CPU-s of every
training job's start-up, a third of a training at the quick profile
(`benchmarks/job_startup.py`). [`FusedAdam`][physgs.train.adam.FusedAdam] makes the same kernel
calls on the same state, so its steps equal torch's bit for bit (tests/test_adam.py), and keeps
the parts of the optimiser interface the training loop and its hooks use: ``param_groups``
(dicts with ``params`` and ``lr``; other keys are the caller's), ``state`` (per parameter:
``step``, ``exp_avg``, ``exp_avg_sq``, created at its first step), ``zero_grad`` and ``step``.
"""

from __future__ import annotations

import math

import torch


class FusedAdam:
    """Adam (no weight decay, no AMSGrad) by torch's fused kernel, one call per group and dtype.

    Args:
        groups (list[dict]): parameter groups, each with ``params`` (leaf tensors) and ``lr``
            (the step size, >= 0; the caller may change it between steps); other keys are kept.
        betas (tuple[float, float]): the moment decay rates, each in [0, 1).
        eps (float): the denominator's floor (>= 0).

    Raises:
        ValueError: a group without params or lr, a negative or non-finite lr or eps, betas
            outside [0, 1), or a parameter that is not a floating-point leaf tensor.
        RuntimeError: a torch without the fused kernel.
    """

    def __init__(self, groups, betas=(0.9, 0.999), eps: float = 1e-8):
        """Check the settings and keep the groups (arguments as the class's)."""
        if not hasattr(torch, "_fused_adam_"):  # a private op: say so rather than fail mid-run
            raise RuntimeError(
                f"FusedAdam: this torch ({torch.__version__}) has no torch._fused_adam_; install "
                "the pinned version (pyproject.toml)"
            )
        b1, b2 = (float(b) for b in betas)
        if not (0.0 <= b1 < 1.0 and 0.0 <= b2 < 1.0):
            raise ValueError(f"FusedAdam: betas must lie in [0, 1); got {betas}")
        if not (math.isfinite(eps) and eps >= 0.0):
            raise ValueError(f"FusedAdam: eps must be finite and >= 0; got {eps}")
        self.betas = (b1, b2)
        self.eps = float(eps)
        self.param_groups: list[dict] = []
        for g in groups:
            if "params" not in g or "lr" not in g:
                raise ValueError(f"FusedAdam: a group needs 'params' and 'lr'; got {sorted(g)}")
            params = list(g["params"])
            for p in params:
                if not (isinstance(p, torch.Tensor) and p.is_leaf and p.is_floating_point()):
                    raise ValueError("FusedAdam: parameters must be floating-point leaf tensors")
            self.param_groups.append({**g, "params": params})
        self.state: dict[torch.Tensor, dict[str, torch.Tensor]] = {}

    def zero_grad(self, set_to_none: bool = True) -> None:
        """Clear every parameter's gradient (None, or zeros in place).

        Args:
            set_to_none: drop the gradients rather than zero them.
        """
        for g in self.param_groups:
            for p in g["params"]:
                if p.grad is None:
                    continue
                if set_to_none:
                    p.grad = None
                else:
                    p.grad.detach_().zero_()

    @torch.no_grad()
    def step(self) -> None:
        """One Adam step of every parameter that has a gradient, at its group's current lr."""
        b1, b2 = self.betas
        for g in self.param_groups:
            lr = float(g["lr"])
            if not (math.isfinite(lr) and lr >= 0.0):
                raise ValueError(f"FusedAdam: lr must be finite and >= 0; got {lr}")
            batches: dict[tuple, tuple[list, ...]] = {}
            for p in g["params"]:
                if p.grad is None:
                    continue
                st = self.state.get(p)
                if not st:
                    # as torch.optim.Adam(fused=True): a float32 step counter beside p
                    st = {
                        "step": torch.zeros((), dtype=torch.float32, device=p.device),
                        "exp_avg": torch.zeros_like(p, memory_format=torch.preserve_format),
                        "exp_avg_sq": torch.zeros_like(p, memory_format=torch.preserve_format),
                    }
                    self.state[p] = st
                lists = batches.setdefault((p.device, p.dtype), ([], [], [], [], []))
                for lst, t in zip(lists, (p, p.grad, st["exp_avg"], st["exp_avg_sq"], st["step"])):
                    lst.append(t)
            for params, grads, m1, m2, steps in batches.values():
                torch._foreach_add_(steps, 1)
                torch._fused_adam_(
                    params,
                    grads,
                    m1,
                    m2,
                    [],
                    steps,
                    amsgrad=False,
                    lr=lr,
                    beta1=b1,
                    beta2=b2,
                    weight_decay=0.0,
                    eps=self.eps,
                    maximize=False,
                    grad_scale=None,
                    found_inf=None,
                )
