"""Benchmark: wall time and peak memory to generate each tree and render its frames.

    python benchmarks/testbed.py [--profile default|quick] [--trees sparse medium dense]

Each tree runs in a fresh process (clean peak RSS). Prints a table; the Snakemake workflow runs
the trees in parallel on 2 cores, so its wall time is about the larger of (sum / 2, max).
"""

import argparse
import multiprocessing as mp
import resource
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _one(profile: str, tree: str, q):
    from physgs.config import load
    from physgs.testbed.dataset import build_dataset, simulate_tree

    cfg = load(ROOT / "config/trees.yaml", profile)
    tb, preset = cfg["testbed"], cfg["presets"][tree]
    t0 = time.perf_counter()
    sim = simulate_tree(tb, preset, seed=cfg["seed"], tree=tree)
    t_gen = time.perf_counter() - t0
    t0 = time.perf_counter()
    obs, _ = build_dataset(tb, preset, seed=cfg["seed"], tree=tree, progress=False)
    t_all = time.perf_counter() - t0
    n_frames = (
        obs["frames"].shape[0] * obs["frames"].shape[1]
        + obs["heldout_frames"].shape[0] * obs["heldout_frames"].shape[1]
    )
    q.put(
        dict(
            tree=tree,
            bones=sim.truth.omega.size,
            vertices=len(sim.mesh.vertices),
            frames=n_frames,
            gen_s=t_gen,
            render_s=t_all - t_gen,
            total_s=t_all,
            peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        )
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--profile", default="default")
    ap.add_argument("--trees", nargs="+", default=["sparse", "medium", "dense"])
    a = ap.parse_args()
    ctx = mp.get_context("spawn")
    rows = []
    for tree in a.trees:
        q = ctx.Queue()
        p = ctx.Process(target=_one, args=(a.profile, tree, q))
        p.start()
        rows.append(q.get())
        p.join()
    print(f"profile: {a.profile}")
    print(
        f"{'tree':8s} {'bones':>5s} {'verts':>6s} {'frames':>6s} {'gen s':>7s} {'render s':>9s} "
        f"{'total s':>8s} {'ms/frame':>8s} {'peak MB':>8s}"
    )
    for r in rows:
        print(
            f"{r['tree']:8s} {r['bones']:5d} {r['vertices']:6d} {r['frames']:6d} {r['gen_s']:7.2f} "
            f"{r['render_s']:9.1f} {r['total_s']:8.1f} {1000 * r['render_s'] / r['frames']:8.1f} "
            f"{r['peak_mb']:8.0f}"
        )
    tot = sum(r["total_s"] for r in rows)
    print(
        f"sum {tot:.1f} s; on 2 cores about {max(tot / 2, max(r['total_s'] for r in rows)):.1f} s"
    )


if __name__ == "__main__":
    main()
