"""What the search over omega does, step by step, on training-window data only.

    python benchmarks/omega_search.py results/testbed/sparse [--model ours_chain] [--seeds 0,1,2]
        [--set models.omega_search.until=0.3 ...] [--save DIR]

Trains the prior by the profile's recipe (the hooks of ``physgs.experiments.fit``, from
``training_hooks``: freezing and the search) and prints per seed the mean PSNR (dB, training camera and wind) of the bank at
the end of its phase, of the oscillators just after the projection, and after the descent, on
every 6th trained frame; the share of the bank angles' energy the projected oscillators explain
(median over parts); and at the end the fit (every 3rd trained frame) and held-out frames
(every 10th training frame, never trained on), as ``benchmarks/fit_recipe.py`` prints them.
With ``--static`` and ``--ceiling`` (the fit dB of static and truth_motion, e.g. from
``results/tables/tab_fit.csv``) it also gives the share of the ceiling's gain. The settings of
``models.omega_search`` were chosen from this table (docs/parts.md).
"""

from __future__ import annotations

import argparse
import copy
from pathlib import Path

import numpy as np

import physgs.config
from physgs.evaluate.run import training_camera_scores
from physgs.experiments import job_spec
from physgs.experiments.recipe import Job, heldout_split, training_hooks
from physgs.models.omega_search import SearchHook
from physgs.models.checkpoint import save_checkpoint
from physgs.models.registry import build_model, condition_indices
from physgs.testbed.dataset import load_observed
from physgs.train.loop import train_model
from physgs.train.seeding import seed_everything


def run(obs, cfg: dict, model_id: str, seed: int, save: Path | None = None) -> dict:
    """Train one prior as ``physgs.experiments.fit`` does (its hooks, ``training_hooks``),
    scoring the probe frames just before and just after the projection; with ``save`` (a
    folder) the trained model is written there as ``<model>_seed<seed>.pt``."""
    job = Job.from_dict(job_spec(copy.deepcopy(cfg), model_id, "single", seed))
    trained, held = heldout_split(int(obs.n_train), int(job.train["holdout_every"]) or 10)
    probe = trained[::6]
    seed_everything(seed)
    model = build_model(model_id, obs, job.settings, K=job.K, seed=seed)
    conds = condition_indices(job.conditions, len(obs.conditions))
    hooks = training_hooks(obs, job, conds)
    search = next((h for h in hooks if isinstance(h, SearchHook)), None)
    if search is None:
        raise SystemExit(f"{model_id} is not in models.omega_search.models: nothing to show")
    out: dict = {}

    def score(m) -> float:
        m.eval()
        p = float(np.mean(training_camera_scores(m, obs, probe)[1]))
        m.train()
        return p

    def around(it, m, opt):
        before = score(m) if it == search.at else None
        stats = search(it, m, opt)
        if stats:
            out.update(
                bank=before, projected=score(m), explained=stats["omega_search_explained_median"]
            )
        return stats

    res = train_model(
        model,
        obs,
        job.train,
        conditions=conds,
        seed=seed,
        progress=False,
        frame_pool=trained,
        on_iteration=[around if h is search else h for h in hooks],
    )
    out["fit"] = float(np.mean(training_camera_scores(res.model, obs, trained[::3])[1]))
    out["held"] = float(np.mean(training_camera_scores(res.model, obs, held)[1]))
    out["wall_s"] = res.stats["wall_s"]
    if save is not None:
        save.mkdir(parents=True, exist_ok=True)
        save_checkpoint(
            save / f"{model_id}_seed{seed}.pt",
            res.model,
            name=model_id,
            config=job.config,
            seed=seed,
            models_cfg=job.settings,
            train_cfg=job.train,
            stats=res.stats,
        )
    return out


def main(argv: list[str] | None = None) -> None:
    """Run with ``argv`` (default: the command line)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("dataset", type=Path, help="folder with observed.npz")
    ap.add_argument("--model", default="ours_chain")
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--profile", default="default")
    ap.add_argument("--set", action="append", default=[], help="KEY.PATH=VALUE override")
    ap.add_argument("--static", type=float, help="static's fit dB (for the ceiling share)")
    ap.add_argument("--ceiling", type=float, help="truth_motion's fit dB")
    ap.add_argument("--save", type=Path, help="write each trained model to this folder")
    args = ap.parse_args(argv)
    cfg = physgs.config.apply_overrides(
        physgs.config.load("config/trees.yaml", args.profile), args.set
    )
    obs = load_observed(args.dataset / "observed.npz")
    print(f"# {args.dataset} {args.model} overrides={args.set}")
    print(
        f"{'seed':>4s} {'bank dB':>8s} {'proj dB':>8s} {'explained':>9s} {'fit dB':>8s} "
        f"{'held dB':>8s} {'share':>6s} {'train s':>8s}"
    )
    fits, helds = [], []
    for seed in (int(s) for s in args.seeds.split(",")):
        r = run(obs, cfg, args.model, seed, args.save)
        share = (
            f"{100 * (r['fit'] - args.static) / (args.ceiling - args.static):5.0f}%"
            if args.static is not None and args.ceiling is not None
            else "     -"
        )
        fits.append(r["fit"])
        helds.append(r["held"])
        print(
            f"{seed:4d} {r['bank']:8.2f} {r['projected']:8.2f} {r['explained']:9.3f} "
            f"{r['fit']:8.2f} {r['held']:8.2f} {share} {r['wall_s']:8.1f}",
            flush=True,
        )
    print(f"mean {'':8s} {'':8s} {'':9s} {np.mean(fits):8.2f} {np.mean(helds):8.2f}")


if __name__ == "__main__":
    main()
