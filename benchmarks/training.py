"""Training cost: seconds per iteration of every model on every tree, and RK4 cost.

    python benchmarks/training.py [--profile default] [--iters 8] [--threads 1]

For each tree the testbed's own geometry and cameras are generated (no frame rendering: the
per-iteration cost does not depend on the target image's content), every model is built at the
profile's settings and timed over ``--iters`` deformation iterations of the real training loop
(after one untimed iteration that compiles kernels). Prints a table of s/iter, then the total
wall time the profile's training jobs imply (3 trees x 5 baselines `single` + ours
single/joint32/joint96; the static warm-up iterations are charged at the static model's rate),
and the RK4 forward+backward cost for K = 96 over the whole recording (lead-in + 350 frames).
"""

from __future__ import annotations

import argparse
import time
from types import SimpleNamespace

import numba
import numpy as np
import torch

import physgs.config
from physgs.models import build_model, training_jobs
from physgs.models.oscillator import integrate
from physgs.testbed import scene
from physgs.testbed.dataset import simulate_tree, swept_points
from physgs.train import train_model


def tree_dataset(cfg: dict, tree: str) -> SimpleNamespace:
    """Observed-like stand-in with the tree's real canonical set, wind and training camera."""
    tb = cfg["testbed"]
    sim = simulate_tree(tb, cfg["presets"][tree], seed=cfg["seed"], tree=tree)
    xyz = sim.truth.rest_vertices.astype(np.float32)
    # the testbed's own framing (swept extent of every frame and condition)
    cam = scene.frame_cameras(
        swept_points(sim.truth),
        [0.0],
        fov_deg=tb["fov_deg"],
        resolution=tb["resolution"],
        fill_height=tb["fill_height"],
    )[0]
    R = tb["resolution"]
    F = tb["n_train"] + tb["n_tail"]
    frame = np.full((R, R, 3), 128, np.uint8)
    frames = np.broadcast_to(frame, (sim.wind.shape[0], F, R, R, 3))
    return SimpleNamespace(
        fps=tb["fps"],
        n_train=tb["n_train"],
        n_tail=tb["n_tail"],
        lead_in_frames=sim.truth.lead_in_frames,
        conditions=sim.conditions,
        wind=sim.wind,
        frames=frames,
        train_camera=cam,
        background=np.asarray(tb["background"]),
        canonical_xyz=xyz,
    )


def time_model(data, cfg: dict, model: str, config: str, iters: int) -> tuple[float, float]:
    """(CPU seconds, wall seconds) per deformation iteration of the training loop, each the best
    of three runs. CPU time (all threads of this process) is what a dedicated core would spend;
    on a shared machine it is far steadier than wall time."""
    tcfg = dict(cfg["train"], iterations=iters, warmup=0)
    conds = [0] if config == "single" else [0, 1, 2]
    m = build_model(model, data, cfg["models"], config=config, seed=cfg["seed"])
    train_model(m, data, dict(tcfg, iterations=1), conditions=conds, seed=0, progress=False)
    cpu, wall = [], []
    for s in range(3):
        c0, t0 = time.process_time(), time.perf_counter()
        train_model(m, data, tcfg, conditions=conds, seed=s, progress=False)
        cpu.append((time.process_time() - c0) / iters)
        wall.append((time.perf_counter() - t0) / iters)
    return float(np.min(cpu)), float(np.min(wall))


def rk4_cost(T: int, K: int = 96, reps: int = 20) -> tuple[float, float]:
    """(fast, reference) seconds (best of ``reps`` / 1) for theta [K, T] forward + backward,
    substeps 2."""
    rng = np.random.default_rng(0)
    wind = 6.0 + 1.5 * rng.standard_normal(T)
    p = [
        torch.tensor(a, requires_grad=True)
        for a in (np.linspace(2.0, 10.0, K), np.full(K, 0.1), np.full(K, 0.01))
    ]
    out = []
    for backend, n in (("fast", reps), ("reference", 1)):
        integrate(*p, wind, 6.0, 1 / 24, 2, backend=backend).sum().backward()  # compile / warm
        best = np.inf
        for _ in range(n):
            t0 = time.perf_counter()
            integrate(*p, wind, 6.0, 1 / 24, 2, backend=backend).square().sum().backward()
            best = min(best, time.perf_counter() - t0)
        out.append(best)
    return out[0], out[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", default="default")
    ap.add_argument("--iters", type=int, default=8, help="timed iterations per model")
    ap.add_argument("--threads", type=int, default=1, help="torch and numba threads")
    ap.add_argument("--trees", nargs="*", default=None)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    numba.set_num_threads(args.threads)
    cfg = physgs.config.load("config/trees.yaml", args.profile)
    trees = args.trees or cfg["trees"]
    it_total, warm = cfg["train"]["iterations"], cfg["train"]["warmup"]
    jobs = training_jobs(cfg["models"]["configs"])
    print(
        f"profile {args.profile}: {cfg['testbed']['resolution']} px, {it_total} iterations "
        f"({warm} warm-up), {args.threads} thread(s) per job; CPU s/iter (wall s/iter)"
    )
    print(f"{'tree':<7} {'N':>6} " + " ".join(f"{m + '_' + c:>17}" for m, c in jobs))
    cpu_total = 0.0
    for tree in trees:
        data = tree_dataset(cfg, tree)
        t = {job: time_model(data, cfg, *job, args.iters) for job in jobs}
        static = t[("static", "single")][0]
        cpu_total += sum(warm * static + (it_total - warm) * v[0] for v in t.values())
        print(
            f"{tree:<7} {data.canonical_xyz.shape[0]:>6} "
            + " ".join(f"{t[j][0]:>8.3f} ({t[j][1]:>6.3f})" for j in jobs)
        )
    print(
        f"implied training CPU time, {len(jobs)} jobs x {len(trees)} trees: "
        f"{cpu_total / 60:.1f} CPU-min -> about {cpu_total / 120:.1f} min wall on 2 idle cores "
        "(2 jobs at once, 1 thread each)"
    )
    T = data.wind.shape[1]  # whole recording of the last tree: lead-in + 350 frames
    fast, ref = rk4_cost(T)
    print(
        f"RK4 forward+backward, K=96, T={T} samples, 2 substeps: fast {fast * 1e3:.2f} ms, "
        f"torch autograd reference {ref * 1e3:.0f} ms ({ref / fast:.0f}x)"
    )


if __name__ == "__main__":
    main()
