"""How well each model fits its training window under a recipe, on training-window data only.

Trains the given models on one tree's dataset with config overrides and prints, per model: the
mean PSNR (dB) at the training camera and wind over the trained frames (fit) and over the
held-out every-k-th training frames (interpolation), the fraction of the true-motion ceiling's
gain over the static pose, and the training wall time. Never reads the view, time or transfer
splits: this is what recipe settings are chosen on.

    python benchmarks/fit_recipe.py results/testbed/medium --models static,mlp,truth_motion \
        --set train.iterations=3000 --set train.lr.deform=2e-3

``--set KEY.PATH=VALUE`` overrides any config key. The recipe log in docs/models.md lists what
each candidate bought.
"""

from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import numpy as np

import physgs.config
from physgs.evaluate.run import training_camera_scores
from physgs.experiments import fit, job_spec
from physgs.experiments.recipe import heldout_split
from physgs.models.registry import is_reference
from physgs.testbed.dataset import load_observed, load_truth


def main(argv: list[str] | None = None) -> None:
    """Run with ``argv`` (default: the command line)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("dataset", type=Path, help="folder with observed.npz (and truth.npz)")
    ap.add_argument("--models", default="static,mlp,mlp_wind,d3dgs,d3dgs_wind,ours,truth_motion")
    ap.add_argument("--profile", default="default")
    ap.add_argument("--set", action="append", default=[], help="KEY.PATH=VALUE override")
    ap.add_argument("--every", type=int, default=3, help="score every k-th trained frame")
    args = ap.parse_args(argv)
    cfg = physgs.config.load("config/trees.yaml", args.profile)
    # the same schema and cross-key checks as the config: a bad --set stops here, key named
    cfg = physgs.config.apply_overrides(cfg, args.set)
    obs = load_observed(args.dataset / "observed.npz")
    truth = load_truth(args.dataset / "truth.npz")
    n = int(obs.n_train)
    every = int(cfg["train"].get("holdout_every", 0)) or 10
    trained, held = heldout_split(n, every)
    print(f"# {args.dataset} overrides={args.set}")
    print(f"{'model':14s} {'fit dB':>8s} {'held dB':>8s} {'train s':>8s}")
    res = {}
    for m in args.models.split(","):
        job = job_spec(copy.deepcopy(cfg), m, "single")
        t0 = time.perf_counter()
        r = fit(obs, job, truth=truth if is_reference(m) else None, progress=False)
        wall = time.perf_counter() - t0
        _, p_fit = training_camera_scores(r.model, obs, trained[:: args.every])
        _, p_held = training_camera_scores(r.model, obs, held)
        res[m] = (float(np.mean(p_fit)), float(np.mean(p_held)), wall)
        print(f"{m:14s} {res[m][0]:8.2f} {res[m][1]:8.2f} {wall:8.1f}", flush=True)
    if "static" in res and "truth_motion" in res:
        s, c = res["static"][0], res["truth_motion"][0]
        for m, (f, h, _) in res.items():
            print(
                f"{m:14s} of ceiling: fit {100 * (f - s) / (c - s):5.0f}%  held "
                f"{100 * (h - res['static'][1]) / (res['truth_motion'][1] - res['static'][1]):5.0f}%"
            )


if __name__ == "__main__":
    main()
