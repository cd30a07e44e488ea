"""The loss's passes beside their alternatives, forward + backward: fused numba vs torch, SSIM's blurs.

    python benchmarks/passes.py fused [--reps 100] [--threads 1] [--side 128]
    python benchmarks/passes.py blur [--sides 64 128 192 256 384 512] [--reps 5] [--threads 1]

``fused``: for the photometric loss on one ``--side`` px RGB frame (`fused_photometric_loss`
against the torch ops of `physgs.train.losses`) and for the chained prior's transforms on random
trees of 32 and 96 parts (`chain_transforms` against its torch form, one depth at a time), the
best and median milliseconds of ``--reps`` calls and the largest difference of their outputs
(the value and the gradient): the torch forms run in the inputs' float32, the fused passes in
float64, so the difference is float32's rounding, growing with the tree's depth.

``blur``: SSIM's Gaussian blur, one banded [n, n] matmul per side against block-Toeplitz tiles.
Times forward + backward of the 15 blurred maps of one 3-channel SSIM (5 maps x 3 channels, an
n x n image, float32, best of ``--reps``) on each path of ``physgs.train.losses.blur`` and prints
the largest difference between them. The loss switches to the tiles at
``TILED_BLUR_MIN_SIDE`` pixels; this table is where that number comes from.

Run two commits side by side from their worktrees (docs/performance.md) to compare a change.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from physgs.models.chain import _chain_transforms_torch, chain_transforms, depth_levels
from physgs.train.fused_loss import fused_photometric_loss
from physgs.train.losses import TILED_BLUR_MIN_SIDE, _photometric_loss_torch, blur


def timed(fn, reps: int) -> tuple[float, float, tuple]:
    """(best ms, median ms, last outputs) of ``fn`` over ``reps`` calls after one warm-up."""
    out = fn()
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn()
        t.append(time.perf_counter() - t0)
    return min(t) * 1e3, float(np.median(t)) * 1e3, out


def loss_case(side: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    x = torch.tensor(rng.random((side, side, 3)), dtype=torch.float32, requires_grad=True)
    y = torch.tensor(rng.random((side, side, 3)), dtype=torch.float32)

    def run(f):
        def call():
            x.grad = None
            loss = f(x, y, 0.2)[0]
            loss.backward()
            return float(loss.detach()), x.grad.clone()

        return call

    return run(fused_photometric_loss), run(_photometric_loss_torch)


def chain_case(K: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    # each part hangs from one of the three before it: a tree some K / 2 depths deep
    parent = np.array([-1] + [int(rng.integers(max(0, p - 3), p)) for p in range(1, K)])
    levels = depth_levels(parent)
    axis = rng.normal(size=(K, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    args = [
        torch.tensor(v, dtype=torch.float32, requires_grad=True)
        for v in (axis, rng.uniform(-1, 1, K), rng.normal(size=(K, 3)))
    ]

    def run(f):
        def call():
            for a in args:
                a.grad = None
            E, u, q = f(*args, levels)
            (E.sum() + u.sum() + q.sum()).backward()
            return E.detach().clone(), args[1].grad.clone()

        return call

    return len(levels), run(chain_transforms), run(_chain_transforms_torch)


def fused(a: argparse.Namespace) -> None:
    """The fused passes against their torch forms: ms and the largest difference."""
    torch.set_num_threads(a.threads)
    print(f"forward + backward, ms (best / median of {a.reps}), {a.threads} thread(s)")
    print(f"{'pass':34s} {'fused':>15s} {'torch':>15s} {'max |diff|':>11s}")
    rows = [(f"photometric loss {a.side} px RGB", *loss_case(a.side))]
    for K in (32, 96):
        depths, fast, ref = chain_case(K)
        rows.append((f"chained transforms K={K} ({depths} depths)", fast, ref))
    for name, fast, ref in rows:
        bf, mf, out_f = timed(fast, a.reps)
        bt, mt, out_t = timed(ref, a.reps)
        diff = max(
            float(np.max(np.abs(np.asarray(u) - np.asarray(v)))) for u, v in zip(out_f, out_t)
        )
        print(f"{name:34s} {bf:6.3f} / {mf:6.3f} {bt:6.3f} / {mt:6.3f} {diff:11.2e}")


def fwd_bwd_ms(z: torch.Tensor, tiled: bool, reps: int) -> float:
    best = float("inf")
    for _ in range(reps + 1):  # the first call builds the cached matrices
        t0 = time.perf_counter()
        blur(z, 11, 1.5, tiled=tiled).square().sum().backward()
        best = min(best, time.perf_counter() - t0)
        z.grad = None
    return best * 1e3


def blur_paths(args: argparse.Namespace) -> None:
    """SSIM's blur, banded against tiled, per image side: ms and the largest difference."""
    torch.set_num_threads(args.threads)
    print(f"# {args.threads} thread(s); the loss takes the tiles from {TILED_BLUR_MIN_SIDE} px")
    print(f"{'side':>5} {'banded ms':>10} {'tiled ms':>9} {'max |diff|':>11}")
    for n in args.sides:
        z = torch.rand(15, n, n, generator=torch.Generator().manual_seed(n), requires_grad=True)
        banded, tiled = fwd_bwd_ms(z, False, args.reps), fwd_bwd_ms(z, True, args.reps)
        with torch.no_grad():
            diff = (blur(z, tiled=False) - blur(z, tiled=True)).abs().max().item()
        print(f"{n:>5} {banded:>10.2f} {tiled:>9.2f} {diff:>11.1e}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("fused", help="the fused numba passes against their torch forms")
    p.add_argument("--reps", type=int, default=100)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--side", type=int, default=128)
    p.set_defaults(run=fused)
    p = sub.add_parser("blur", help="SSIM's blur: banded matmul against tiles per image side")
    p.add_argument("--sides", type=int, nargs="*", default=[64, 128, 192, 256, 384, 512])
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    p.set_defaults(run=blur_paths)
    args = ap.parse_args()
    args.run(args)


if __name__ == "__main__":
    main()
