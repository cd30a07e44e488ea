"""What scoring the held-out window frames costs against a training iteration, per model.

    PYTHONPATH=src python benchmarks/holdout_overhead.py results/testbed/sparse [--models ...]

For each model: the mean wall time of a training iteration (``--iterations`` after the warm-up,
the profile's settings otherwise) and of one score of the held-out window frames
(``physgs.train.holdout.HoldoutEval``, ``--repeats`` times), side by side in one process, and the
share of a 3000-iteration training that scores every N iterations would add. Timings on a shared
machine compare only within one run.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import torch

from physgs.config import load
from physgs.experiments.recipe import Job, earliest_stop, heldout_split, job_spec
from physgs.models.registry import build_model, is_reference
from physgs.testbed.dataset import load_observed, load_truth
from physgs.train.holdout import HoldoutEval
from physgs.train.loop import train_model
from physgs.train.seeding import seed_everything


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("testbed", type=Path)
    ap.add_argument("--models", default="static,ours,mlp,mlp_wind,d3dgs,d3dgs_wind")
    ap.add_argument("--iterations", type=int, default=60)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--every", type=int, default=300, help="N: iterations between scores")
    a = ap.parse_args()
    cfg = load("config/trees.yaml", "default")
    obs = load_observed(a.testbed / "observed.npz")
    truth = load_truth(a.testbed / "truth.npz")
    every = a.every
    print(
        f"{'model':>12} {'ms/iter':>8} {'ms/score':>9} {'frames':>6} {'share':>6} (every {every})"
    )
    for m in a.models.split(","):
        job = Job.from_dict(job_spec(cfg, m, "single"))
        w = 10
        tcfg = {**job.train, "iterations": w + a.iterations, "warmup": w}
        tcfg["stopping"] = {**tcfg["stopping"], "enabled": False, "every": 0}
        seed_everything(0)
        model = build_model(m, obs, job.settings, K=job.K, truth=truth if is_reference(m) else None)
        res = train_model(model, obs, tcfg, conditions=[0], seed=0, progress=False)
        secs = np.array([r["seconds"] for r in res.log])
        it_ms = 1e3 * float(np.diff(secs[w:]).mean())
        held = heldout_split(int(obs.n_train), int(job.train["holdout_every"]))[1]
        ev = HoldoutEval.build(obs, held, [0], job.train)
        t = []
        for _ in range(a.repeats):
            t0 = time.perf_counter()
            ev.evaluate(res.model)
            t.append(time.perf_counter() - t0)
        sc_ms = 1e3 * float(np.median(t))
        # the scores of an enabled rule: every N from the recipe's last change, while a trigger
        # (+ the anneal) could still end the run before the cap
        anneal, cap = int(job.train["stopping"]["anneal"]), 3000
        first = max(earliest_stop(job), 1)
        n_scores = len([i for i in range(first, cap - anneal) if i % every == 0])
        share = n_scores * sc_ms / (3000 * it_ms)
        print(f"{m:>12} {it_ms:8.1f} {sc_ms:9.0f} {len(ev.pairs):6d} {100 * share:5.1f}%")


if __name__ == "__main__":
    torch.set_num_threads(1)
    main()
