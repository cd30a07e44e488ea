"""fit_recipe.py with coarse-to-fine Fourier bands: does annealing the bands help the fields fit?

A recipe candidate (SPEC: "annealing the Fourier bands (coarse to fine)"), measured and not kept
(README, *How the training recipe was chosen*). Band k of every learned field's position and time
encoding is weighted by the Nerfies window (1 - cos(pi * clip(alpha - k, 0, 1))) / 2, with alpha
rising linearly from 0 to the field's band count over the first ``--fraction`` of the
deformation iterations (after the static warm-up); after training every band has weight 1, so
scoring sees the plain encoding. Every other argument goes to fit_recipe.py, so it scores only
training-window frames.

    python benchmarks/band_anneal.py --fraction 0.5 results/testbed/medium --models mlp_wind
"""

from __future__ import annotations

import argparse
import math

import torch

import fit_recipe  # its sibling: run as python benchmarks/<this>.py
import physgs.models.fields
import physgs.train.loop
from physgs.models.encoding import fourier


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, add_help=False, formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument(
        "--fraction",
        type=float,
        default=0.5,
        help="share of the deformation iterations over which the bands open",
    )
    args, rest = ap.parse_known_args()
    progress = {"p": 1.0}  # 0 -> 1 over the annealing; 1 outside training

    def annealed(x: torch.Tensor, bands: int) -> torch.Tensor:  # x [..., d]
        enc = fourier(x, bands)  # [..., d (1 + 2 bands)]
        if bands == 0 or progress["p"] >= 1.0:
            return enc
        d = x.shape[-1]
        alpha = progress["p"] * bands
        w = torch.tensor(
            [(1 - math.cos(math.pi * min(max(alpha - k, 0.0), 1.0))) / 2 for k in range(bands)],
            dtype=x.dtype,
        )  # [bands]
        w = torch.cat([torch.ones(d, dtype=x.dtype), w.repeat_interleave(2 * d)])
        return enc * w

    train_model = physgs.train.loop.train_model

    def train_annealed(model, observed, train_cfg, *, on_iteration=None, **kw):
        iters, warm = int(train_cfg["iterations"]), int(train_cfg["warmup"])
        span = max(1.0, args.fraction * (iters - warm))

        def hook(it, m, opt):
            progress["p"] = min(1.0, max(0, it - warm) / span)
            return on_iteration(it, m, opt) if on_iteration is not None else None

        try:
            return train_model(model, observed, train_cfg, on_iteration=hook, **kw)
        finally:
            progress["p"] = 1.0

    physgs.models.fields.fourier = annealed  # the fields look it up in their own module
    physgs.train.loop.train_model = train_annealed  # the recipe imports it at call time
    fit_recipe.main(rest)


if __name__ == "__main__":
    main()
