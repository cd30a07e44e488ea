"""Recipe candidates that are code, not config: measured with fit_recipe.py and not adopted.

    python benchmarks/fit_recipe.py results/testbed/medium --models mlp_wind \
        --candidate loss_pyramid=1,2,4,8

Each candidate patches the library for this process only (the training loop and the fields
look these names up at call time) and is selected by ``fit_recipe.py --candidate NAME=VALUE``;
the recipe log (docs/models.md) has the command and what each bought. They are kept runnable so a
changed model or recipe can be re-measured, but they are not config keys: none paid.

- ``loss_pyramid=LEVELS``: the L1 term becomes the mean of L1 over the image average-pooled by
  each factor of the comma-separated LEVELS (1 = full resolution); D-SSIM unchanged. A thin
  branch that swung farther than its own width gets a gradient back from a pooled image.
- ``output_scale=S``: every head of every learned field (position offset in scene units; for
  Deformable-3DGS also rotation and log-scale offsets) is multiplied by S. Under Adam a step is
  about the learning rate whatever the gradient, so S sets how far one step moves a Gaussian.
- ``band_anneal=F``: band k of every learned field's position and time encoding is weighted by
  the Nerfies window (1 - cos(pi * clip(alpha - k, 0, 1))) / 2, alpha rising from 0 to the band
  count over the first fraction F of the deformation iterations (after the static warm-up);
  after training every band has weight 1, so scoring sees the plain encoding.
"""

from __future__ import annotations

import math
from collections.abc import Callable


def loss_pyramid(value: str) -> None:
    import torch
    import torch.nn.functional as F

    import physgs.train.loop
    from physgs.train.losses import ssim

    levels = [int(k) for k in value.split(",")]

    def loss(render: torch.Tensor, target: torch.Tensor, ssim_weight: float = 0.2):
        r, t = render.permute(2, 0, 1)[None], target.permute(2, 0, 1)[None]  # [1, 3, H, W]
        l1s = [
            ((F.avg_pool2d(r, k) - F.avg_pool2d(t, k)) if k > 1 else (r - t)).abs().mean()
            for k in levels
        ]
        dssim = 1.0 - ssim(render, target)
        return (1 - ssim_weight) * torch.stack(l1s).mean() + ssim_weight * dssim, l1s[0], dssim

    physgs.train.loop.photometric_loss = loss  # looked up in the loop's module every iteration


def output_scale(value: str) -> None:
    from physgs.models.fields import DeformationField

    scale, forward = float(value), DeformationField.forward

    def scaled(self, x):  # x [N, in_dim]
        return {name: scale * out for name, out in forward(self, x).items()}

    DeformationField.forward = scaled


def band_anneal(value: str) -> None:
    import torch

    import physgs.models.fields
    import physgs.train.loop
    from physgs.models.encoding import fourier

    fraction = float(value)
    progress = {"p": 1.0}  # 0 -> 1 over the annealing; 1 outside training

    def annealed(x: torch.Tensor, bands: int) -> torch.Tensor:  # x [..., d]
        enc = fourier(x, bands)  # [..., d (1 + 2 bands)]
        if bands == 0 or progress["p"] >= 1.0:
            return enc
        d, alpha = x.shape[-1], progress["p"] * bands
        w = torch.tensor(
            [(1 - math.cos(math.pi * min(max(alpha - k, 0.0), 1.0))) / 2 for k in range(bands)],
            dtype=x.dtype,
        )  # [bands]
        return enc * torch.cat([torch.ones(d, dtype=x.dtype), w.repeat_interleave(2 * d)])

    train_model = physgs.train.loop.train_model

    def train_annealed(model, observed, train_cfg, *, on_iteration=None, **kw):
        iters, warm = int(train_cfg["iterations"]), int(train_cfg["warmup"])
        span = max(1.0, fraction * (iters - warm))

        def hook(it, m, opt):
            progress["p"] = min(1.0, max(0, it - warm) / span)
            return on_iteration(it, m, opt) if on_iteration is not None else None

        try:
            return train_model(model, observed, train_cfg, on_iteration=hook, **kw)
        finally:
            progress["p"] = 1.0

    physgs.models.fields.fourier = annealed  # the fields look it up in their own module
    physgs.train.loop.train_model = train_annealed  # the recipe imports it at call time


CANDIDATES: dict[str, Callable[[str], None]] = {
    "loss_pyramid": loss_pyramid,
    "output_scale": output_scale,
    "band_anneal": band_anneal,
}


def apply(assignment: str) -> None:
    """Apply one ``NAME=VALUE`` candidate; a bad name stops with the valid ones."""
    name, _, value = assignment.partition("=")
    if name not in CANDIDATES or not value:
        raise SystemExit(
            f"--candidate {assignment!r}: use NAME=VALUE, NAME one of {list(CANDIDATES)}"
        )
    CANDIDATES[name](value)
