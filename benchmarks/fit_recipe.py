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

``--capacity`` asks what the oscillator priors' parts can hold of the tree's true motion
(``physgs.models.capacity``; a diagnostic of a shortfall, no setting is chosen on it): after static,
the ceiling, ours and the chained prior train, each prior's parts are fitted to the ceiling's true
trajectories over the window (the chained prior's as a chain, each part on its parent's turn), as
rigid turns with a free angle per frame (rows ``<prior>_free``) and with one oscillator each
(``<prior>_osc``: the best of a grid over the prior's bounds, driven by the measured wind, refined
by Nelder-Mead); each motion is held while the appearance trains as the ceiling's does (from the
same start, the same iterations), and is scored like the models: the ceiling with the parts' motion
in place of the true one.

    python benchmarks/fit_recipe.py results/testbed/sparse --capacity
"""

from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import numpy as np
import pandas as pd
import torch

import physgs.config
from physgs.evaluate.run import training_camera_scores
from physgs.experiments import fit, job_spec
from physgs.experiments.recipe import heldout_split
from physgs.models.capacity import (
    PartsAtAngles,
    chain_turns,
    oscillator_angles,
    refine_oscillators,
    rigid_part_angles,
    turned,
)
from physgs.models.omega_search import unit_responses
from physgs.models.oscillator_params import condition_vbar
from physgs.models.registry import is_reference
from physgs.testbed.dataset import load_observed, load_truth
from physgs.train.loop import train_model


def main(argv: list[str] | None = None) -> None:
    """Run with ``argv`` (default: the command line)."""
    # the first paragraph: the rest (the module docstring) is the reference
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", type=Path, help="folder with observed.npz (and truth.npz)")
    ap.add_argument("--models", default="static,mlp,mlp_wind,d3dgs,d3dgs_wind,ours,truth_motion")
    ap.add_argument("--profile", default="default")
    ap.add_argument("--set", action="append", default=[], help="KEY.PATH=VALUE override")
    ap.add_argument("--every", type=int, default=3, help="score every k-th trained frame")
    ap.add_argument("--capacity", action="store_true", help="the priors' parts at the true motion")
    ap.add_argument("--markdown", type=Path, help="write the rows as a Markdown table here")
    args = ap.parse_args(argv)
    if args.capacity:
        args.models = "static,truth_motion,ours,ours_chain"
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
    res, trained_models, motion_px = {}, {}, {}
    for m in args.models.split(","):
        job = job_spec(copy.deepcopy(cfg), m, "single")
        t0 = time.perf_counter()
        r = fit(obs, job, truth=truth if is_reference(m) else None, progress=False)
        wall = time.perf_counter() - t0
        _, p_fit = training_camera_scores(r.model, obs, trained[:: args.every])
        _, p_held = training_camera_scores(r.model, obs, held)
        res[m] = (float(np.mean(p_fit)), float(np.mean(p_held)), wall)
        trained_models[m] = (r.model, job)
        print(f"{m:14s} {res[m][0]:8.2f} {res[m][1]:8.2f} {wall:8.1f}", flush=True)
    priors = ("ours", "ours_chain") if args.capacity else ()
    for prior in priors:  # each prior's parts at the true motion, trained as the ceiling is
        for m, model, err_px in capacity_models(
            obs, *trained_models["truth_motion"], prior, trained_models[prior][0]
        ):
            motion_px[m] = err_px
            t0 = time.perf_counter()
            train = trained_models[prior][1]["train"]
            train_model(model, obs, train, conditions=[0], seed=0, progress=False)
            _, p_fit = training_camera_scores(model, obs, trained[:: args.every])
            _, p_held = training_camera_scores(model, obs, held)
            res[m] = (float(np.mean(p_fit)), float(np.mean(p_held)), time.perf_counter() - t0)
            print(f"{m:14s} {res[m][0]:8.2f} {res[m][1]:8.2f} {res[m][2]:8.1f}", flush=True)
    rows = pd.DataFrame(res, index=["fit_db", "held_db", "train_s"]).T
    if {"static", "truth_motion"} <= set(res):  # each split's share of the ceiling's gain
        for col, share in (("fit_db", "fit_of_ceiling"), ("held_db", "held_of_ceiling")):
            s, c = rows.at["static", col], rows.at["truth_motion", col]
            rows[share] = (rows[col] - s) / (c - s)
            for m, v in rows[share].items():
                print(f"{m:16s} {col[:-3]} of ceiling {100 * v:5.0f}%")
    rows["motion_error_px"] = pd.Series(motion_px, dtype=float)
    if args.markdown:
        args.markdown.write_text(
            f"`{args.dataset}`, {args.profile} profile, overrides {args.set or 'none'}: "
            f"{int(cfg['train']['iterations'])} iterations\n\n"
            + rows.rename_axis("model").reset_index().to_markdown(index=False, floatfmt=".2f")
            + "\n"
        )


def capacity_models(obs, truth_model, truth_job, prior_id, prior):
    """The prior's parts at the true motion: free angles, then one oscillator each (a chained
    prior's parts fitted as a chain). Their canonical sets start as the ceiling's did: only the
    motion differs.

    Args:
        obs: the dataset.
        truth_model: the trained ceiling (its trajectories).
        truth_job: its job (the canonical settings).
        prior_id: the prior's registry id (names the rows).
        prior: the trained oscillator prior (its parts, bounds, RK4 steps).

    Returns:
        ``[(name, PartsAtAngles, image error px)]``: the mean image error of each motion against
            the truth (also printed).
    """
    n, lead = int(obs.n_train), int(obs.lead_in_frames)
    wind = torch.as_tensor(np.asarray(obs.wind[0]), dtype=torch.float64)
    with torch.no_grad():
        pts = np.stack(
            [truth_model.gaussians_at(j, wind.float()).means.double().numpy() for j in range(n)]
        )
    labels, K = prior.part_labels.cpu().numpy(), int(prior.K)
    parent = prior.part_parent.cpu().numpy() if getattr(prior, "chain", False) else None
    axis = truth_model.swing_axis.double().numpy()
    free = rigid_part_angles(pts, labels, K, axis, parent)
    b = prior.bounds  # a grid inset from the bounds (omega, zeta are sigmoids of raw values)
    om = np.exp(np.linspace(np.log(b.omega_lo), np.log(b.omega_hi), 62)[1:-1])
    ze = np.linspace(b.zeta_lo, b.zeta_hi, 14)[1:-1]
    om, ze = np.repeat(om, len(ze)), np.tile(ze, len(om))
    r = unit_responses(
        om, ze, wind, condition_vbar(prior.vbar_ratio, wind), prior.dt, prior.substeps
    )
    r = r[:, lead : lead + n] - r[:, lead : lead + 1]
    om, ze, *_ = oscillator_angles(free.theta, r, om, ze)
    vbar = condition_vbar(prior.vbar_ratio, wind)

    def response(w, z):  # one oscillator's unit response over the window, from frame 0
        x = unit_responses([w], [z], wind, vbar, prior.dt, prior.substeps)[0]
        return x[lead : lead + n] - x[lead]

    bounds = ((b.omega_lo, b.omega_hi), (b.zeta_lo, b.zeta_hi))
    *_, osc = refine_oscillators(free.theta, om, ze, response, bounds)
    uv = obs.train_camera.project(pts.reshape(-1, 3))[0].reshape(n, -1, 2)
    moved = np.linalg.norm(uv - uv[:1], axis=-1).mean()
    out = []
    for how, theta in (("free", free.theta), ("osc", osc)):
        shift = None
        if parent is not None:  # a chain: each part's total turn and the shift it carries
            theta, shift = chain_turns(theta, free.pivot, parent, axis)
        at = turned(pts[0], labels, axis, free.pivot, theta, shift)
        err = np.linalg.norm(
            obs.train_camera.project(at.reshape(-1, 3))[0].reshape(n, -1, 2) - uv, axis=-1
        )
        name = f"{prior_id}_{how}"
        print(f"# {name}: image error {err.mean():.2f} px against a true motion of {moved:.2f} px")
        m = PartsAtAngles(
            prior.ctx, truth_job["settings"]["canonical"], labels, axis, free.pivot, theta, shift
        )
        out.append((name, m, float(err.mean())))
    return out


if __name__ == "__main__":
    main()
