"""Is an oscillator prior's in-window fit limited by what it can express, or by finding the
frequencies? A diagnostic that reads the truth (never a recipe input).

    python benchmarks/prior_oracle.py results/testbed/sparse [--models ours,ours_chain] [--bones]
        [--set KEY.PATH=VALUE]

Trains each prior twice on one tree's training window, by the profile's recipe (the same
``physgs.experiments.fit`` as every job): as the pipeline does (every part starts at
``omega_init_hz`` and ``zeta_init``, the swing axis horizontal across the view), and with an
oracle start: each part's omega and zeta set to those of its majority bone (truth.npz; omega
clipped into the prior's bounds) and its swing axis to the testbed's. Everything else (gain,
pivots, Gaussians) starts and trains as usual. Prints fit and held-out PSNR (training camera,
training wind, trained and held-out window frames) and each run's share of the true-motion
ceiling's gain over the static pose. If the oracle start fits far better, the prior can express
the motion and gradient descent from a common start does not find the frequencies; if not, the
prior's structure is what limits it. ``--bones`` adds the chained prior with the testbed's own
parts: one part per bone, its parent the parent bone, its pivot the bone's head, and the oracle
start (so only the gains and the Gaussians are left to learn): what the prior can reach when its
parts are the true ones.
"""

from __future__ import annotations

import argparse
import copy
import functools
from pathlib import Path

import numpy as np
import torch

import physgs.config
import physgs.experiments.recipe as recipe
from physgs.evaluate.run import training_camera_scores
from physgs.experiments import fit, job_spec
from physgs.experiments.recipe import heldout_split
from physgs.testbed.dataset import load_observed, load_truth


def set_physics(model, omega=None, zeta=None) -> None:
    """Set the raw parameters whose omega [K] (rad/s) and zeta [K] are given, each clipped just
    inside the prior's bounds (``OscillatorBounds.omega_raw`` / ``zeta_raw``)."""
    b = model.bounds
    with torch.no_grad():
        if omega is not None:
            om = np.clip(omega, b.omega_lo * 1.001, b.omega_hi * 0.999)
            model.omega_raw.copy_(torch.tensor([b.omega_raw(float(w)) for w in om]))
        if zeta is not None:
            ze = np.clip(zeta, b.zeta_lo * 1.001, b.zeta_hi * 0.999)
            model.zeta_raw.copy_(torch.tensor([b.zeta_raw(float(z)) for z in ze]))


def bone_of_gaussian(truth) -> np.ndarray:
    """[N] the bone of each Gaussian's mesh vertex."""
    return np.asarray(truth.vertex_bone)[np.asarray(truth.gaussian_vertex)]


def oracle_start(model, truth, gain: bool = False) -> None:
    """Set each part's omega, zeta (raw parameters) and swing axis from its majority bone, and
    with ``gain`` its force gain (rad/s^2 per m^2/s^2 in both)."""
    bone = bone_of_gaussian(truth)  # [N]
    lab = model.part_labels.numpy()  # [N]
    major = [np.bincount(bone[lab == p]).argmax() for p in range(model.K)]
    set_physics(model, np.asarray(truth.omega)[major], np.asarray(truth.zeta)[major])
    with torch.no_grad():
        axis = torch.tensor(np.asarray(truth.swing_axis, dtype=np.float32))
        model.axis_raw.copy_(axis.repeat(model.K, 1))
        if gain:
            gain = np.asarray(truth.gain, dtype=np.float32)[major]
            model.gain_raw.copy_(torch.tensor(gain) / model.gain_scale)


def tracks_start(model, fit_npz: Path, tracks_npz: Path, camera, radius_px: float = 2.0):
    """Set each part's omega from the 2D-track control's fit (observed data only: the training
    video's tracks, ``physgs.tracks``): the median omega (rad/s) of the fitted clusters of the
    tracks whose seed position (px; ``tracks_npz``, the track rule's c<condition>.npz) lies
    within ``radius_px`` of one of the part's projected canonical Gaussians. Parts without such a
    track keep their start. Returns [K] the number of tracks each part drew on."""
    from scipy.spatial import cKDTree

    from physgs.tracks.store import load_fit, load_tracks

    fit, _, _ = load_fit(fit_npz)
    tracks, _ = load_tracks(tracks_npz)
    lab = fit.labels[0]  # [M] cluster of each track of the first condition (-1: not fitted)
    keep = (lab >= 0) & fit.estimated[np.clip(lab, 0, None)]
    lab, seed_xy = lab[keep], tracks.first_xy()[keep]  # [M'], [M', 2] px
    uv, _ = camera.project(np.asarray(model.ctx.canonical_xyz, dtype=np.float64))  # [N, 2]
    dist, idx = cKDTree(uv).query(seed_xy)  # nearest projected Gaussian of each track
    part = np.where(dist <= radius_px, model.part_labels.numpy()[idx], -1)  # [M']
    om = model.bounds.omega(model.omega_raw.detach()).numpy().astype(np.float64)  # [K]
    n = np.bincount(part[part >= 0], minlength=model.K)  # [K]
    for p in np.nonzero(n)[0]:
        om[p] = np.median(fit.omega[lab[part == p]])
    set_physics(model, om)
    return n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path, help="folder with observed.npz and truth.npz")
    ap.add_argument("--models", default="ours,ours_chain")
    ap.add_argument("--profile", default="default")
    ap.add_argument("--set", action="append", default=[], help="KEY.PATH=VALUE override")
    ap.add_argument(
        "--bones", action="store_true", help="also the chained prior with one part per bone"
    )
    ap.add_argument(
        "--relative",
        action="store_true",
        help="every run's angles relative to the canonical frame's: theta(t) - theta(t_0)",
    )
    ap.add_argument("--gain", action="store_true", help="the oracle start sets the gains too")
    ap.add_argument(
        "--tracks",
        type=Path,
        help="also a start from the 2D-track control's fit (its fit_<config>.npz): observed data only",
    )
    ap.add_argument("--no-oracle", action="store_true", help="skip the oracle-start runs")
    ap.add_argument("--no-pipeline", action="store_true", help="skip the pipeline-start runs")
    args = ap.parse_args()
    start = functools.partial(oracle_start, gain=args.gain)
    cfg = physgs.config.apply_overrides(
        physgs.config.load("config/trees.yaml", args.profile), args.set
    )
    obs = load_observed(args.dataset / "observed.npz")
    if args.relative:  # the canonical Gaussians are the pose at recorded frame 0, not at rest
        from physgs.models.ours import OscillatorPrior

        L = int(obs.lead_in_frames)
        own = OscillatorPrior._integrate_theta
        OscillatorPrior._integrate_theta = lambda self, w: (lambda th: th - th[:, L : L + 1])(
            own(self, w)
        )
    truth = load_truth(args.dataset / "truth.npz")
    trained, held = heldout_split(int(obs.n_train), int(cfg["train"]["holdout_every"]))

    def scores(m, start=None, bones=False):
        build = recipe.build_model
        if start is not None:  # the oracle start, after the model is built and seeded

            def built(*a, **k):
                if bones:  # one part per bone, its parent bone's part as parent
                    k = {**k, "K": len(truth.omega), "labels": bone_of_gaussian(truth)}
                    k["parent"] = np.asarray(truth.bone_parent)
                model = build(*a, **k)
                start(model, truth)
                if bones:  # each pivot at its bone's head, the joint with the parent
                    with torch.no_grad():
                        model.pivot.copy_(torch.tensor(np.asarray(truth.bone_head)))
                return model

            recipe.build_model = built
        try:
            job = job_spec(copy.deepcopy(cfg), m, "single")
            r = fit(obs, job, truth=truth if m == "truth_motion" else None, progress=False)
        finally:
            recipe.build_model = build
        f = float(np.mean(training_camera_scores(r.model, obs, trained[::3])[1]))
        h = float(np.mean(training_camera_scores(r.model, obs, held)[1]))
        return f, h

    base = {m: scores(m) for m in ("static", "truth_motion")}
    (s_f, s_h), (c_f, c_h) = base["static"], base["truth_motion"]
    print(
        f"# {args.dataset} overrides={args.set}: static {s_f:.2f} / {s_h:.2f} dB, ceiling "
        f"{c_f:.2f} / {c_h:.2f} dB (fit / held-out)"
    )
    print(
        f"{'model':12s} {'start':8s} {'fit dB':>7s} {'held dB':>7s} {'of gain (fit / held)':>22s}"
    )
    starts = ([] if args.no_pipeline else [("pipeline", None)]) + (
        [] if args.no_oracle else [("oracle", start)]
    )
    if args.tracks is not None:
        starts.append(
            (
                "tracks",
                lambda model, _truth: tracks_start(
                    model, args.tracks, args.tracks.parent.parent / "c0.npz", obs.train_camera
                ),
            )
        )
    runs = [
        (m, name, st, False) for m in filter(None, args.models.split(",")) for name, st in starts
    ]
    if args.bones:
        runs.append(("ours_chain", "bones", start, True))
    for m, name, start, bones in runs:
        f, h = scores(m, start, bones)
        print(
            f"{m:12s} {name:8s} {f:7.2f} {h:7.2f} "
            f"{100 * (f - s_f) / (c_f - s_f):10.0f}% / {100 * (h - s_h) / (c_h - s_h):.0f}%",
            flush=True,
        )


if __name__ == "__main__":
    main()
