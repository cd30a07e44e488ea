"""Rasterizer speed: fast (numba) vs reference (PyTorch autograd) side by side.

Prints median forward and forward+backward milliseconds (and the fastest fast-path
forward+backward, the best estimate on a shared machine) and peak extra memory (MiB, resident
set growth during the timed calls, measured in a fresh subprocess per cell) for N in
{2k, 10k, 30k} Gaussians at 128x128 and 256x256 on the canopy-like random scene of
physgs.render.scenes. Usage:

    python benchmarks/rasterizer.py [--reps 7] [--ref-reps 2] [--sizes 2000,10000,30000]
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time


def rss_mib() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20


def one(backend: str, n: int, res: int, reps: int) -> dict:
    """Time one cell in this process (called in a subprocess)."""
    import torch

    from physgs.render import rasterization
    from physgs.render.scenes import random_scene

    warm = random_scene(200, 32, 32, seed=1)  # loads the numba cache, warms torch
    rasterization(*warm[:5], warm[5], warm[6], backend=backend)
    means, quats, scales, opac, colors, cam, bg = random_scene(n, res, res, seed=0)
    params = [x.requires_grad_(True) for x in (means, quats, scales, opac, colors)]
    base = rss_mib()
    fwd, fb = [], []
    for _ in range(reps):
        t0 = time.perf_counter()
        with torch.no_grad():
            rasterization(*params, cam, bg, backend=backend)
        fwd.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        out = rasterization(*params, cam, bg, backend=backend)
        (out.rgb.sum() + out.alpha.sum() + out.depth.sum()).backward()
        fb.append(time.perf_counter() - t0)
        for p in params:
            p.grad = None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 - base
    return {
        "fwd_ms": 1e3 * statistics.median(fwd),
        "fb_ms": 1e3 * statistics.median(fb),
        "fb_min_ms": 1e3 * min(fb),
        "peak_mib": max(peak, 0.0),
        "alpha_mean": float(out.alpha.mean()),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=15, help="timed calls per fast cell")
    ap.add_argument("--ref-reps", type=int, default=2, help="timed calls per reference cell")
    ap.add_argument("--sizes", default="2000,10000,30000")
    ap.add_argument("--res", default="128,256")
    ap.add_argument(
        "--one", nargs=4, metavar=("BACKEND", "N", "RES", "REPS"), help=argparse.SUPPRESS
    )
    a = ap.parse_args()
    if a.one:
        print(json.dumps(one(a.one[0], int(a.one[1]), int(a.one[2]), int(a.one[3]))))
        return
    print(
        f"{'N':>6} {'res':>4} | {'fast fwd':>9} {'fast f+b':>9} {'(min)':>7} {'MiB':>6} | "
        f"{'ref fwd':>9} {'ref f+b':>9} {'MiB':>6} | {'speed-up f+b':>12}"
    )
    for res in (int(r) for r in a.res.split(",")):
        for n in (int(s) for s in a.sizes.split(",")):
            row = {}
            for backend, reps in (("fast", a.reps), ("reference", a.ref_reps)):
                cmd = [sys.executable, __file__, "--one", backend, str(n), str(res), str(reps)]
                out = subprocess.run(cmd, capture_output=True, text=True, check=True)
                row[backend] = json.loads(out.stdout.strip().splitlines()[-1])
            f, r = row["fast"], row["reference"]
            print(
                f"{n:>6} {res:>4} | {f['fwd_ms']:>9.1f} {f['fb_ms']:>9.1f} "
                f"{f['fb_min_ms']:>7.1f} {f['peak_mib']:>6.0f} | "
                f"{r['fwd_ms']:>9.1f} {r['fb_ms']:>9.1f} {r['peak_mib']:>6.0f} | "
                f"{r['fb_ms'] / f['fb_ms']:>11.1f}x",
                flush=True,
            )


if __name__ == "__main__":
    main()
