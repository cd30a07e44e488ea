"""The fused numba passes of an iteration against their torch forms, forward + backward.

    python benchmarks/fused_passes.py [--reps 100] [--threads 1] [--side 128]

Prints, for the photometric loss on one ``--side`` px RGB frame (`fused_photometric_loss`
against the torch ops of `physgs.train.losses`) and for the chained prior's transforms on random
trees of 32 and 96 parts (`chain_transforms` against its torch form, one depth at a time), the
best and median milliseconds of ``--reps`` calls and the largest difference of their outputs
(the value and the gradient): the torch forms run in the inputs' float32, the fused passes in
float64, so the difference is float32's rounding, growing with the tree's depth.
Run two commits side by side from their worktrees (docs/performance.md) to compare a change.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from physgs.models.chain import _chain_transforms_torch, chain_transforms, depth_levels
from physgs.train.fused_loss import fused_photometric_loss
from physgs.train.losses import _photometric_loss_torch


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=100)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--side", type=int, default=128)
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    print(f"forward + backward, ms (best / median of {a.reps}), {a.threads} thread(s)")
    print(f"{'pass':34s} {'fused':>15s} {'torch':>15s} {'max |diff|':>11s}")
    rows = [(f"photometric loss {a.side} px RGB", *loss_case(a.side))]
    for K in (32, 96):
        depths, fused, ref = chain_case(K)
        rows.append((f"chained transforms K={K} ({depths} depths)", fused, ref))
    for name, fused, ref in rows:
        bf, mf, out_f = timed(fused, a.reps)
        bt, mt, out_t = timed(ref, a.reps)
        diff = max(
            float(np.max(np.abs(np.asarray(u) - np.asarray(v)))) for u, v in zip(out_f, out_t)
        )
        print(f"{name:34s} {bf:6.3f} / {mf:6.3f} {bt:6.3f} / {mt:6.3f} {diff:11.2e}")


if __name__ == "__main__":
    main()
