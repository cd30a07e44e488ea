"""Rasterizer speed: fast (numba) vs reference (PyTorch autograd) side by side.

Two kinds of scene:

* blob: the canopy-like random blob of :func:`physgs.render.scenes.random_scene`, for N in
  ``--sizes`` Gaussians at each of ``--res`` pixels (square); it covers most of the image.
* tree: each testbed tree's initial canonical Gaussians from its training camera
  (:func:`physgs.render.scenes.tree_scene`), read from ``--datasets`` folders
  (results/testbed/<tree>, each holding observed.npz; a folder without one is skipped with a
  message). They time the sparse case: the initial sets cover about 9 / 50 / 35 % of the
  pixels (sparse / medium / dense, column 'cover': alpha > 1/255), the trees' frames 1.6-20 %.

The work count (fast path): the pixel-Gaussian pairs that compositing touches before
transmittance saturates ('pairs', thousands), times the flops of the forward and backward inner
loops per pair (``kernels.FLOPS_PER_PAIR_FORWARD`` + ``_BACKWARD``, 76 for RGB), gives the
arithmetic ('Mflop') and its time at ``--gflops`` (default 4: a scalar float64 core sustaining
~1.5 flops a cycle at 2.6 GHz); 'ns/pair' is the measured forward+backward (fastest, CPU) per
pair. The distance between 'ideal' and 'cpu min' is what projection, binning, allocation, the
torch boundary and the kernels' own overheads (row spans, exps, branches) cost; a second
table splits each fast cell's forward + backward into those components (:func:`breakdown`).

Per cell: median forward (no autograd) and forward+backward milliseconds, the fastest fast-path
forward+backward in wall and in CPU seconds of the process (the best estimates on a shared
machine; CPU time is the steadier when other processes compete for the cores), and peak extra memory (MiB, resident
set growth during the timed calls), each cell in a fresh subprocess. Usage:

    NUMBA_NUM_THREADS=1 python benchmarks/rasterizer.py [--reps 15] [--ref-reps 2]
        [--sizes 2000,10000,30000] [--res 128,256]
        [--datasets results/testbed/sparse results/testbed/medium results/testbed/dense]
        [--no-reference] [--gflops 4]
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

TREES = ("sparse", "medium", "dense")


def rss_mib() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20


def load_scene(spec: str):
    """'blob:N:RES' -> random_scene(N, RES, RES, seed=0); 'tree:DIR' -> tree_scene(DIR) at the
    default profile's models.canonical settings."""
    from physgs.render.scenes import random_scene, tree_scene

    kind, _, rest = spec.partition(":")
    if kind == "blob":
        n, res = (int(v) for v in rest.split(":"))
        return random_scene(n, res, res, seed=0)
    import physgs.config

    cfg = physgs.config.load("config/trees.yaml", "default")
    return tree_scene(rest, cfg["models"]["canonical"])


def one(backend: str, spec: str, reps: int) -> dict:
    """Time one cell in this process (called in a subprocess), with the allocator as a
    workflow job sets it (:func:`physgs.allocator.retain_freed_memory`)."""
    import torch

    from physgs.allocator import retain_freed_memory

    retain_freed_memory()

    from physgs.render import kernels, rasterization
    from physgs.render.fast import work_count
    from physgs.render.scenes import random_scene

    warm = random_scene(200, 32, 32, seed=1)  # loads the numba cache, warms torch
    rasterization(*warm[:5], warm[5], warm[6], backend=backend)
    means, quats, scales, opac, colors, cam, bg = load_scene(spec)
    params = [x.requires_grad_(True) for x in (means, quats, scales, opac, colors)]
    work = work_count(means, quats, scales, opac, colors, cam, bg) if backend == "fast" else {}
    flops = work.get("pairs", 0) * (
        kernels.FLOPS_PER_PAIR_FORWARD + kernels.FLOPS_PER_PAIR_BACKWARD
    )
    base = rss_mib()
    fwd, fb, fb_cpu = [], [], []
    for _ in range(reps):
        t0 = time.perf_counter()
        with torch.no_grad():
            rasterization(*params, cam, bg, backend=backend)
        fwd.append(time.perf_counter() - t0)
        t0, c0 = time.perf_counter(), time.process_time()
        out = rasterization(*params, cam, bg, backend=backend)
        (out.rgb.sum() + out.alpha.sum() + out.depth.sum()).backward()
        fb.append(time.perf_counter() - t0)
        fb_cpu.append(time.process_time() - c0)
        for p in params:
            p.grad = None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 - base
    parts = breakdown(params, cam, bg, reps) if backend == "fast" else {}
    return {
        "n": int(means.shape[0]),
        "res": f"{cam.width}x{cam.height}",
        "fwd_ms": 1e3 * statistics.median(fwd),
        "fb_ms": 1e3 * statistics.median(fb),
        "fb_min_ms": 1e3 * min(fb),
        "fb_cpu_min_ms": 1e3 * min(fb_cpu),
        "peak_mib": max(peak, 0.0),
        "cover": float((out.alpha > 1.0 / 255.0).float().mean()),
        "pairs": work.get("pairs", 0),
        "flops": flops,
        "parts": parts,
    }


#: the fast path's numba kernels by the component of :data:`PARTS` they belong to
KERNEL_PARTS = {
    "project_forward": "project",
    "pixel_boxes": "project",
    "bin_tiles": "bin",
    "forward": "composite",
    "backward": "composite_bwd",
    "reduce_pairs": "reduce",
    "project_backward": "project_bwd",
}
PARTS = ("project", "bin", "composite", "composite_bwd", "reduce", "project_bwd", "rest")


def breakdown(params, cam, bg, reps: int) -> dict[str, float]:
    """Mean CPU ms per forward + backward call in each component (:data:`PARTS`), timed by
    wrapping the fast path's kernels; 'rest' is the call's CPU time outside them: the depth sort,
    per-call allocation, float64 copies in and out, input checks and the autograd boundary."""
    from physgs.render import kernels, rasterization

    sec = dict.fromkeys(PARTS, 0.0)
    saved = {name: getattr(kernels, name) for name in KERNEL_PARTS}

    def timed(name, fn):
        def call(*a):
            c0 = time.process_time()
            try:
                return fn(*a)
            finally:
                sec[KERNEL_PARTS[name]] += time.process_time() - c0

        return call

    total = 0.0
    try:
        for name, fn in saved.items():
            setattr(kernels, name, timed(name, fn))
        for _ in range(reps):
            c0 = time.process_time()
            out = rasterization(*params, cam, bg)
            (out.rgb.sum() + out.alpha.sum() + out.depth.sum()).backward()
            total += time.process_time() - c0
            for p in params:
                p.grad = None
    finally:
        for name, fn in saved.items():
            setattr(kernels, name, fn)
    sec["rest"] = total - sum(sec.values())
    return {k: 1e3 * v / reps for k, v in sec.items()}


def run_cell(backend: str, spec: str, reps: int) -> dict:
    cmd = [sys.executable, __file__, "--one", backend, spec, str(reps)]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=15, help="timed calls per fast cell")
    ap.add_argument("--ref-reps", type=int, default=2, help="timed calls per reference cell")
    ap.add_argument("--sizes", default="2000,10000,30000", help="blob sizes (empty: none)")
    ap.add_argument("--res", default="128,256", help="blob resolutions, px")
    ap.add_argument(
        "--datasets",
        nargs="*",
        default=[f"results/testbed/{t}" for t in TREES],
        help="testbed folders (each with observed.npz) whose canonical sets are tree scenes",
    )
    ap.add_argument("--no-reference", action="store_true", help="time the fast path only")
    ap.add_argument(
        "--gflops", type=float, default=4.0, help="arithmetic rate for the ideal time, Gflop/s"
    )
    ap.add_argument("--one", nargs=3, metavar=("BACKEND", "SCENE", "REPS"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(one(a.one[0], a.one[1], int(a.one[2]))))
        return
    specs = []
    for res in (int(r) for r in a.res.split(",") if r):
        specs += [(f"blob:{n}:{res}", "blob") for n in (int(s) for s in a.sizes.split(",") if s)]
    for d in a.datasets:
        if not (Path(d) / "observed.npz").is_file():
            print(f"skipping tree {d}: no {Path(d) / 'observed.npz'} (generate the testbed first)")
            continue
        specs.append((f"tree:{d}", Path(d).name))
    print(
        f"{'scene':<8} {'N':>6} {'res':>7} {'cover':>6} | {'fast fwd':>9} {'fast f+b':>9} "
        f"{'(min)':>7} {'cpu min':>7} {'MiB':>6} | {'pairs k':>7} {'Mflop':>6} {'ideal':>6} "
        f"{'ns/pair':>7} | {'ref fwd':>9} {'ref f+b':>9} {'MiB':>6} | "
        f"{'speed-up f+b':>12}"
    )
    parts = []
    for spec, name in specs:
        f = run_cell("fast", spec, a.reps)
        line = (
            f"{name:<8} {f['n']:>6} {f['res']:>7} {100 * f['cover']:>5.1f}% | "
            f"{f['fwd_ms']:>9.1f} {f['fb_ms']:>9.1f} {f['fb_min_ms']:>7.1f} "
            f"{f['fb_cpu_min_ms']:>7.1f} "
            f"{f['peak_mib']:>6.0f} | {f['pairs'] / 1e3:>7.0f} {f['flops'] / 1e6:>6.1f} "
            f"{f['flops'] / (a.gflops * 1e6):>6.1f} "
            f"{1e6 * f['fb_cpu_min_ms'] / max(f['pairs'], 1):>7.1f} |"
        )
        if not a.no_reference:
            r = run_cell("reference", spec, a.ref_reps)
            line += (
                f" {r['fwd_ms']:>9.1f} {r['fb_ms']:>9.1f} {r['peak_mib']:>6.0f} | "
                f"{r['fb_ms'] / f['fb_ms']:>11.1f}x"
            )
        print(line, flush=True)
        parts.append((name, f["parts"]))
    print("\nfast path, CPU ms per forward + backward (mean of the reps) by component:")
    print(f"{'scene':<8} " + " ".join(f"{p:>13}" for p in PARTS))
    for name, p in parts:
        print(f"{name:<8} " + " ".join(f"{p[k]:>13.2f}" for k in PARTS))


if __name__ == "__main__":
    main()
