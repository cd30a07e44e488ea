"""Cost of the evaluation and recovery steps on the real testbed trees (physics only) and of
one evaluation render. Prints a table. Usage:
    python benchmarks/bench_evaluate.py [--profile default] [--renders 20]
"""

import argparse
import time
from types import SimpleNamespace

import numpy as np
import torch

import physgs.config
from physgs.camera import orbit_camera
from physgs.evaluate import model_render_fn
from physgs.models import ModelContext, build_model
from physgs.recovery.matcher import match_parts
from physgs.recovery.record import bone_window, run_null
from physgs.testbed.dataset import simulate_tree


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--profile", default="default")
    ap.add_argument("--renders", type=int, default=20)
    a = ap.parse_args()
    cfg = physgs.config.load("config/trees.yaml", a.profile)
    tb, oc = cfg["testbed"], cfg["models"]["ours"]
    F = tb["n_train"] + tb["n_tail"]
    n_eval = len(tb["conditions"]) * F + len(tb["heldout_azimuths_deg"]) * (
        tb["n_train"] // tb["heldout_every"]
    )
    rows = []
    for tree in cfg["trees"]:
        sim = simulate_tree(tb, cfg["presets"][tree], seed=cfg["seed"], tree=tree)
        tr = sim.truth
        obs = SimpleNamespace(
            wind=sim.wind,
            lead_in_frames=int(tr.lead_in_frames),
            n_train=tb["n_train"],
            fps=int(tr.fps),
            background=np.asarray(tb["background"], float),
        )
        bw = bone_window(tr, obs.lead_in_frames, obs.n_train)
        for K in (32, 96):
            run_null(
                tr,
                obs,
                n_parts=K,
                zeta_init=oc["zeta_init"],
                substeps=oc["substeps"],
                seed=0,
                n_draws=1,
            )
            t0 = time.perf_counter()
            nl = run_null(
                tr, obs, n_parts=K, zeta_init=oc["zeta_init"], substeps=oc["substeps"], seed=0
            )
            t_null = time.perf_counter() - t0
            t0 = time.perf_counter()
            match_parts(
                bw[:K] if K <= len(bw) else bw[np.arange(K) % len(bw)],
                bw,
                tr.omega[np.arange(K) % len(tr.omega)],
                tr.omega,
            )
            t_match = time.perf_counter() - t0
            rows.append(
                (
                    tree,
                    len(tr.omega),
                    K,
                    t_null,
                    t_match,
                    100 * nl.median_median_rel_err,
                    100 * nl.nearest_bone_gap,
                )
            )
        # one evaluation render of the static model at the profile's resolution
        xyz = tr.rest_vertices.astype(np.float32)
        w = sim.wind[0]
        ctx = ModelContext(
            xyz,
            obs.fps,
            obs.n_train,
            obs.lead_in_frames,
            float(w.mean()),
            float(w.std()),
            float((w**2 - w.mean() ** 2).std()),
            np.array([0.0, 1.0, 0.0]),
        )
        model = build_model("static", ctx, cfg["models"])
        lo, hi = xyz.min(0), xyz.max(0)
        cam = orbit_camera(
            0,
            radius=2.5 * float(np.ptp(xyz[:, 2])),
            height=float(hi[2] + lo[2]) / 2,
            target=(hi + lo) / 2,
            fov_deg=tb["fov_deg"],
            width=tb["resolution"],
            height_px=tb["resolution"],
        )
        fn = model_render_fn(model, obs)
        fn(0, 0, cam)
        t0 = time.perf_counter()
        for j in range(a.renders):
            fn(j, 0, cam)
        per = (time.perf_counter() - t0) / a.renders
        rows.append((tree, len(xyz), "render", per, per * n_eval, float("nan"), float("nan")))
    print(
        f"profile={a.profile}  torch threads={torch.get_num_threads()}  evaluate() renders/model={n_eval}"
    )
    print(
        f"{'tree':8s} {'bones|N':>8s} {'K':>7s} {'null 8 draws s':>15s} {'match s':>9s} {'null err %':>10s} {'gap %':>7s}"
    )
    for r in rows:
        if r[2] == "render":
            print(
                f"{r[0]:8s} {r[1]:8d} {'render':>7s} {'%.4f s/frame' % r[3]:>15s} {'evaluate() ~%.0f s/model' % r[4]:>30s}"
            )
        else:
            print(
                f"{r[0]:8s} {r[1]:8d} {r[2]:7d} {r[3]:15.3f} {r[4]:9.4f} {r[5]:10.2f} {r[6]:7.2f}"
            )


if __name__ == "__main__":
    main()
