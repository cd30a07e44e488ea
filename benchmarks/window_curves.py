"""Held-out-window fit curves: each model's loss on the frames its training window holds out
(every ``train.holdout_every``-th, of the trained wind) every ``--every`` iterations of one
full-budget training (the profile's). What the stopping rule's N, tolerance and patience are
chosen on (docs/models.md); never the views, the tail or another wind.

    PYTHONPATH=src nice -n 10 env OMP_NUM_THREADS=1 python benchmarks/window_curves.py \
        --tree sparse --out curves/sparse.csv [--models static,mlp,...] [--every 50]

Writes one CSV row per (model, iteration): the held-out loss (the training loss, L1 + D-SSIM),
its PSNR (dB), the training loss (mean of the last ``--every`` iterations), the wall time.

``--rule`` instead trains each model as the pipeline does (``recipe.fit``, the config's
``train.stopping``, overridable with ``--stop-every/--tol/--patience/--anneal``) and writes one
row per model: the iterations used, why it stopped, the held-out loss and PSNR at its end, its
wall time and the time its held-out scores took.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import os
import time

import numpy as np
import torch

from physgs.config import load
from physgs.experiments.recipe import Job, fit, heldout_split, job_spec
from physgs.models.registry import BLIND_PRIORS, is_reference, training_jobs
from physgs.testbed.dataset import load_observed, load_truth
from physgs.train.holdout import HoldoutEval
from physgs.train.loop import condition_indices

RULE_OFF = {"enabled": False, "every": 0, "patience": 1, "tol": 0.0, "anneal": 1}
FIELDS = (
    "model",
    "tree",
    "seed",
    "iteration",
    "holdout_loss",
    "holdout_psnr",
    "train_loss",
    "seconds",
)


def models_that_train(cfg: dict) -> list[str]:
    """Every model kind trained in `single`: the methods, the forcing-free priors, the parts
    study's variants and the ceiling."""
    ms = [m for m, c in training_jobs(cfg["models"]["configs"]) if c == "single"]
    ms += [m for m in BLIND_PRIORS] + [m for m in cfg["parts_study"]["models"] if m not in ms]
    return [*ms, "truth_motion"]


@contextlib.contextmanager
def appending(path: str, fields: tuple[str, ...]):
    """A CSV writer appending to ``path`` (the header only when the file is new): one output
    file gathers the runs of several trees and models."""
    new = not os.path.exists(path)
    with open(path, "a", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        if new:
            w.writeheader()
        yield w, fh


def window_holdout(obs, job: Job) -> HoldoutEval:
    """The evaluator of the frames ``job``'s training window holds out, of its trained winds."""
    held = heldout_split(int(obs.n_train), int(job.train["holdout_every"]))[1]
    conds = condition_indices(job.conditions, len(obs.conditions))
    return HoldoutEval.build(obs, held, conds, job.train)


RULE_FIELDS = (
    "model",
    "tree",
    "seed",
    "every",
    "patience",
    "tol",
    "anneal",
    "iterations",
    "stopped",
    "stop_trigger",
    "holdout_loss",
    "holdout_psnr",
    "wall_s",
    "holdout_s",
    "holdout_evals",
)


def run_rule(a, cfg: dict, obs, truth, models: list[str]) -> None:
    """Train each model with the stopping rule on and append its row to ``a.out``."""
    st = dict(cfg["train"]["stopping"], enabled=True)
    for k, v in (
        ("every", a.stop_every),
        ("tol", a.tol),
        ("patience", a.patience),
        ("anneal", a.anneal),
    ):
        if v is not None:
            st[k] = v
    cfg["train"]["stopping"] = st
    with appending(a.out, RULE_FIELDS) as (w, fh):
        for m in models:
            job = Job.from_dict(job_spec(cfg, m, "single", seed=a.seed))
            res = fit(obs, job, truth=truth if is_reference(m) else None, progress=False)
            loss, p = window_holdout(obs, job).evaluate(res.model)
            s = res.stats
            w.writerow(
                dict(
                    model=m,
                    tree=a.tree,
                    seed=a.seed,
                    every=st["every"],
                    patience=st["patience"],
                    tol=st["tol"],
                    anneal=st["anneal"],
                    iterations=s["iterations"],
                    stopped=s["stopped"],
                    stop_trigger=s["stop_trigger"],
                    holdout_loss=loss,
                    holdout_psnr=p,
                    wall_s=s["wall_s"],
                    holdout_s=s["holdout_s"],
                    holdout_evals=s["holdout_evals"],
                )
            )
            fh.flush()
            print(
                f"{a.tree} {m}: {s['iterations']} it ({s['stopped']}), {s['wall_s']:.0f} s "
                f"(scores {s['holdout_s']:.1f} s), holdout loss {loss:.4f}, {p:.2f} dB",
                flush=True,
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--tree", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--models", default="")
    ap.add_argument("--every", type=int, default=50)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--profile", default="default")
    ap.add_argument("--rule", action="store_true", help="train with the stopping rule on")
    ap.add_argument("--budget", type=int, default=None, help="train this many iterations")
    ap.add_argument("--stop-every", type=int, default=None)
    ap.add_argument("--tol", type=float, default=None)
    ap.add_argument("--patience", type=int, default=None)
    ap.add_argument("--anneal", type=int, default=None)
    a = ap.parse_args()
    cfg = load("config/trees.yaml", a.profile)
    obs = load_observed(f"results/testbed/{a.tree}/observed.npz")
    truth = load_truth(f"results/testbed/{a.tree}/truth.npz")
    models = a.models.split(",") if a.models else models_that_train(cfg)
    if a.rule:
        run_rule(a, cfg, obs, truth, models)
        return
    with appending(a.out, FIELDS) as (w, fh):
        for m in models:
            job = Job.from_dict(job_spec(cfg, m, "single", seed=a.seed))
            # the full budget, scored by the hook below: the curve the rule is chosen on
            train = {**job.train, "stopping": {**RULE_OFF}}
            if a.budget:  # a per-model budget: the schedule and the recipe's fractions over it
                frac = train["warmup"] / train["iterations"]
                train.update(iterations=a.budget, warmup=int(round(frac * a.budget)))
            job = job.replace(train=train)
            ev = window_holdout(obs, job)
            t0 = time.perf_counter()
            rows = []

            warmup = int(job.train["warmup"])

            def record(it, mdl, opt, _ev=ev, _rows=rows, _m=m, _t0=t0, _w=warmup):
                if it % a.every == 0 and it > 0:
                    loss, p = _ev.evaluate(mdl, warm=it < _w)
                    _rows.append(
                        dict(
                            model=_m,
                            tree=a.tree,
                            seed=a.seed,
                            iteration=it,
                            holdout_loss=loss,
                            holdout_psnr=p,
                            seconds=time.perf_counter() - _t0,
                        )
                    )

            truth_m = truth if is_reference(m) else None
            res = fit(obs, job, truth=truth_m, progress=False, name=m, hooks=(record,))
            loss, p = ev.evaluate(res.model, warm=False)
            rows.append(
                dict(
                    model=m,
                    tree=a.tree,
                    seed=a.seed,
                    iteration=len(res.log),
                    holdout_loss=loss,
                    holdout_psnr=p,
                    seconds=time.perf_counter() - t0,
                )
            )
            tl = np.array([r["loss"] for r in res.log])
            for r in rows:
                i = r["iteration"]
                r["train_loss"] = float(tl[max(0, i - a.every) : i].mean())
                w.writerow(r)
            fh.flush()
            print(
                f"{a.tree} {m}: {len(res.log)} it, {res.stats['wall_s']:.0f} s, "
                f"holdout loss {loss:.4f}, {p:.2f} dB",
                flush=True,
            )


if __name__ == "__main__":
    torch.set_num_threads(1)
    main()
