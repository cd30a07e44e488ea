"""SSIM's Gaussian blur: one banded [n, n] matmul per side against block-Toeplitz tiles.

    python benchmarks/ssim_blur.py [--sides 64 128 192 256 384 512] [--reps 5] [--threads 1]

Times forward + backward of the 15 blurred maps of one 3-channel SSIM (5 maps x 3 channels, an
n x n image, float32, best of ``--reps``) on each path of ``physgs.train.losses.blur`` and prints
the largest difference between them. The loss switches to the tiles at
``TILED_BLUR_MIN_SIDE`` pixels; this table is where that number comes from.
"""

from __future__ import annotations

import argparse
import time

import torch

from physgs.train.losses import TILED_BLUR_MIN_SIDE, blur


def fwd_bwd_ms(z: torch.Tensor, tiled: bool, reps: int) -> float:
    best = float("inf")
    for _ in range(reps + 1):  # the first call builds the cached matrices
        t0 = time.perf_counter()
        blur(z, 11, 1.5, tiled=tiled).square().sum().backward()
        best = min(best, time.perf_counter() - t0)
        z.grad = None
    return best * 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sides", type=int, nargs="*", default=[64, 128, 192, 256, 384, 512])
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    print(f"# {args.threads} thread(s); the loss takes the tiles from {TILED_BLUR_MIN_SIDE} px")
    print(f"{'side':>5} {'banded ms':>10} {'tiled ms':>9} {'max |diff|':>11}")
    for n in args.sides:
        z = torch.rand(15, n, n, generator=torch.Generator().manual_seed(n), requires_grad=True)
        banded, tiled = fwd_bwd_ms(z, False, args.reps), fwd_bwd_ms(z, True, args.reps)
        with torch.no_grad():
            diff = (blur(z, tiled=False) - blur(z, tiled=True)).abs().max().item()
        print(f"{n:>5} {banded:>10.2f} {tiled:>9.2f} {diff:>11.1e}")


if __name__ == "__main__":
    main()
