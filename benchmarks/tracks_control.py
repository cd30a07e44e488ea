"""The 2D-track control on the built testbeds, outside the pipeline (the pipeline's
rules: workflow/rules/tracks.smk, docs/tracks.md).

    python benchmarks/tracks_control.py [--trees sparse,medium,dense] [--K 32] [--seed 0]
                                        [--conditions train|all] [--threads 1]

Per tree: tracks of the training camera's training window (``physgs.tracks.track``, observed only),
the tracker scored against truth-projected vertices, ours' oscillators fitted to the tracks
(``physgs.tracks.fit``), their recovery through ours' matcher beside the untrained null (same K,
same seed), and the predicted tracks' pixel errors beyond the window (frames n_train..F-1) and
under the unseen winds (conditions 1 and 2, window frames), beside a motionless prediction.
Reads results/testbed/<tree>/{observed,truth}.npz and config/trees.yaml (``models.ours``).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
import torch
import yaml

from physgs.recovery.record import run_null
from physgs.testbed.dataset import load_observed, load_truth
from physgs.tracks.fit import FitSettings, Oscillators, fit_tracks, predict_tracks
from physgs.tracks.recover import recover_tracks
from physgs.tracks.score import motion_errors, score_tracker
from physgs.tracks.track import TrackSettings, track_video


def main(argv=None) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--trees", default="sparse,medium,dense")
    ap.add_argument("--K", type=int, default=32)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--conditions", choices=("train", "all"), default="train")
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args(argv)
    torch.set_num_threads(a.threads)
    cfg = yaml.safe_load(open("config/trees.yaml"))
    ours = cfg["models"]["ours"]
    lr = float(cfg["train"]["lr"]["physics"])
    for tree in a.trees.split(","):
        o = load_observed(f"results/testbed/{tree}/observed.npz")
        tr = load_truth(f"results/testbed/{tree}/truth.npz")
        T, F = o.n_train, o.n_train + o.n_tail
        conds = [0] if a.conditions == "train" else list(range(len(o.conditions)))
        t0 = time.perf_counter()
        tracks = [track_video(o.frames[c, :T], o.background, TrackSettings()) for c in conds]
        t_track = time.perf_counter() - t0
        out = {"tree": tree, "K": a.K, "seed": a.seed, "conditions": conds}
        out["tracker"] = score_tracker(tracks[0], tr, o.train_camera, 0).to_dict()
        out["track_seconds"] = round(t_track, 2)
        osc = Oscillators.from_config(ours, o)
        try:
            fit = fit_tracks(tracks, conds, o.wind, osc, FitSettings(K=a.K, lr=lr, seed=a.seed))
        except ValueError as e:  # a finding, not hidden: too few tracks for K parts
            out["fit_error"] = str(e)
            print(json.dumps(out))
            continue
        out["fit_seconds"] = round(fit.seconds, 2)
        out["fit_loop_seconds"] = round(fit.loop_seconds, 2)
        out["fit_rms_px"] = round(fit.rms_px, 3)
        out["tracks_per_part"] = fit.n_tracks.tolist()
        out["recovery"] = recover_tracks(fit, osc, o, tr).to_dict()
        null = run_null(
            tr,
            o,
            n_parts=a.K,
            zeta_init=float(ours["zeta_init"]),
            substeps=osc.substeps,
            seed=a.seed,
        )
        out["null"] = {
            "median_n_trusted": null.median_n_trusted,
            "median_median_rel_err": null.median_median_rel_err,
            "median_loglog_r2": null.median_loglog_r2,
        }
        cases = [("window", 0, np.arange(T)), ("tail", 0, np.arange(T, F))]
        cases += [(f"wind{c}", c, np.arange(T)) for c in range(1, len(o.conditions))]
        for name, c, frames in cases:
            pred = predict_tracks(fit, osc, 0, o.wind[c], frames)
            e = motion_errors(pred, tracks[0], tr, o.train_camera, c, frames, conds[0])
            out[name] = {k: round(v, 3) if isinstance(v, float) else v for k, v in e.items()}
        print(json.dumps(out))


if __name__ == "__main__":
    main()
