"""Deformation-field cost and error in bfloat16 against float32, per field and Gaussian count.

    python benchmarks/field_precision.py [--threads 1] [--reps 5]

For each field architecture of the config (with and without the wind history) and each tree's
Gaussian count of the default profile, times one forward + backward of the field on random
inputs (best of ``--reps``, after two untimed calls) at ``precision: float32`` and
``bfloat16`` (the weights are identical; heads randomised so the outputs are not zero), and
prints the speed-up and the bf16 outputs' error relative to float32 (max |diff| / max |out|).
Whether bf16 changes a *trained* model beyond seed noise is measured with
``benchmarks/fit_recipe.py --set models.d3dgs.precision=bfloat16`` (docs/models.md).
"""

from __future__ import annotations

import argparse
import time

import torch

import physgs.config
from physgs.models.encoding import fourier_dim
from physgs.models.fields import DeformationField, native_bf16


def fwd_bwd_ms(field: DeformationField, x: torch.Tensor, reps: int) -> float:
    def step():
        field.zero_grad()
        sum(o.square().sum() for o in field(x).values()).backward()

    for _ in range(2):
        step()
    best = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        step()
        best = min(best, time.perf_counter() - t0)
    return best * 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    cfg = physgs.config.load("config/trees.yaml", "default")
    m = cfg["models"]
    print(
        f"# torch {torch.__version__}, CPU capability {torch.backends.cpu.get_cpu_capability()}, "
        f"native bf16: {native_bf16()}, {args.threads} thread(s)"
    )
    print(
        f"{'field':12s} {'N':>6s} {'fp32 ms':>8s} {'bf16 ms':>8s} {'speed-up':>8s} {'rel err':>8s}"
    )
    for arch in ("mlp", "d3dgs"):
        a = m[arch]
        heads = ("dx",) if arch == "mlp" else ("dx", "dq", "ds")
        for wind in (False, True):
            in_dim = (
                fourier_dim(3, a["pos_bands"])
                + fourier_dim(1, a["time_bands"])
                + (m["wind_window"]["values"] if wind else 0)
            )
            for n in cfg["testbed"]["vertices"].values():
                torch.manual_seed(0)
                f32 = DeformationField(in_dim, a["depth"], a["width"], a.get("skip"), heads)
                for h in f32.heads.values():
                    torch.nn.init.normal_(h.weight, std=0.05)
                b16 = DeformationField(
                    in_dim, a["depth"], a["width"], a.get("skip"), heads, "bfloat16"
                )
                b16.load_state_dict(f32.state_dict())
                x = torch.rand(n, in_dim) * 2 - 1
                with torch.no_grad():
                    o32, o16 = f32(x), b16(x)
                err = max(float((o32[k] - o16[k]).abs().max() / o32[k].abs().max()) for k in o32)
                t32, t16 = fwd_bwd_ms(f32, x, args.reps), fwd_bwd_ms(b16, x, args.reps)
                name = arch + ("_wind" if wind else "")
                print(f"{name:12s} {n:6d} {t32:8.1f} {t16:8.1f} {t32 / t16:7.2f}x {err:8.4f}")


if __name__ == "__main__":
    main()
