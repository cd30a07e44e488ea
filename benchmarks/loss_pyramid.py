"""fit_recipe.py with a multi-scale L1: did a wider photometric basin help the fields fit?

A recipe candidate that was measured and not kept (README, *How the training recipe was
chosen*). The L1 term becomes the mean of L1 over the image average-pooled by each factor of
``--levels`` (1 = full resolution); the D-SSIM term is unchanged. The idea: a thin branch that
has swung farther than its own width gives the full-resolution L1 no gradient towards where it
went; a pooled image does. Every other argument goes to fit_recipe.py, so it scores only
training-window frames.

    python benchmarks/loss_pyramid.py --levels 1,2,4,8 results/testbed/medium --models mlp_wind
"""

from __future__ import annotations

import argparse

import torch
import torch.nn.functional as F

import fit_recipe  # its sibling: run as python benchmarks/<this>.py
import physgs.train.loop
from physgs.train.losses import ssim


def pyramid_loss(levels: list[int]):
    """photometric_loss with its L1 averaged over average-pooled copies of the [H, W, 3] images."""

    def loss(render: torch.Tensor, target: torch.Tensor, ssim_weight: float = 0.2):
        r, t = render.permute(2, 0, 1)[None], target.permute(2, 0, 1)[None]  # [1, 3, H, W]
        l1s = [
            ((F.avg_pool2d(r, k) - F.avg_pool2d(t, k)) if k > 1 else (r - t)).abs().mean()
            for k in levels
        ]
        dssim = 1.0 - ssim(render, target)
        return (1 - ssim_weight) * torch.stack(l1s).mean() + ssim_weight * dssim, l1s[0], dssim

    return loss


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, add_help=False, formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument("--levels", default="1,2,4,8", help="pooling factors, 1 = full resolution")
    args, rest = ap.parse_known_args()
    # the training loop looks the loss up in its own module at every iteration
    physgs.train.loop.photometric_loss = pyramid_loss([int(k) for k in args.levels.split(",")])
    fit_recipe.main(rest)


if __name__ == "__main__":
    main()
