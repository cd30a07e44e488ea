"""Where a model's motion error lies: across the training camera's image plane, or along its depth.

    python benchmarks/motion_depth.py results --tree sparse --seed 0 [--models ours,ours_chain]

One camera constrains the motion it sees across its image; motion along its viewing direction
only through perspective. For each trained checkpoint (``results/models/<tree>/seed<s>/<model>_
single.pt``) this compares every Gaussian's motion from recorded frame 0 with its vertex's true
motion (truth.npz's bone angles posed by the testbed's skinning), on condition 0
(training wind): where the model puts each Gaussian at recorded frame 0 against its vertex, and
over the training window and the tail its motion from frame 0 against the vertex's (RMS, mm),
each split across the training camera's ray through the true point (what its image shows) and
along it (what it cannot see, the held-out views do). A Gaussian may also slide along its own
branch unseen by any view: placement errors bound what the images show from above. Frame 0's
placement error is also split into the canonical positions' drift from the vertices they start
at and the deformation at frame 0 (the canonical set is frame 0's vertices). An evaluation diagnostic that
reads the truth: it chooses nothing.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import torch

from physgs.models import load_checkpoint
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.kinematics import pose_vertices


def split_on_rays(vec: np.ndarray, at: np.ndarray, centre: np.ndarray):
    """(across [..., 3], along [...]) of vectors ``vec`` [..., 3] (m) at world points ``at``
    [..., 3]: the part across the training camera's ray through each point (what its image
    shows) and the signed length along it (what it cannot see)."""
    d = at - centre
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    along = np.sum(vec * d, axis=-1)
    return vec - along[..., None] * d, along


def positions(model, obs, truth, frames) -> tuple[np.ndarray, np.ndarray]:
    """(true, predicted) world positions [F, N, 3] (m) of every Gaussian, in Gaussian order, at
    recorded ``frames`` [F] of condition 0 (the training wind)."""
    wind = torch.as_tensor(np.asarray(obs.wind[0]), dtype=torch.float32)
    order = np.asarray(truth.gaussian_vertex)  # [N] the vertex of each Gaussian
    theta = np.asarray(truth.theta)[0]  # [L+F, B]
    lead = int(obs.lead_in_frames)
    gt = np.stack([pose_vertices(truth, theta[lead + j])[order] for j in frames])  # [F, N, 3]
    with torch.no_grad():
        pred = np.stack([model.gaussians_at(int(j), wind).means.numpy() for j in frames])
    return gt, pred


def _rms(a) -> float:
    """Root mean square of ``a`` (metres) in millimetres."""
    return 1000 * float(np.sqrt(np.mean(np.asarray(a) ** 2)))


def main(argv: list[str] | None = None) -> None:
    """Run with ``argv`` (default: the command line)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("results", type=Path, help="the pipeline's results folder")
    ap.add_argument("--tree", default="sparse")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--models", default="ours,ours_topo,ours_chain")
    args = ap.parse_args(argv)
    ds = args.results / "testbed" / args.tree
    obs, truth = load_observed(ds / "observed.npz"), load_truth(ds / "truth.npz")
    n, F = int(obs.n_train), int(obs.n_train + obs.n_tail)
    spans = {"window": np.arange(0, n, 3), "tail": np.arange(n, F, 3)}
    c = obs.train_camera.center
    print(f"# {args.tree} seed {args.seed}: RMS, mm; across / along the training camera's rays")
    print(
        f"{'model':12s} {'frame 0 across':>14s} {'along':>6s}   {'span':6s} {'motion across':>13s} "
        f"{'along':>6s} {'error across':>12s} {'along':>6s}"
    )
    for m in args.models.split(","):
        path = args.results / "models" / args.tree / f"seed{args.seed}" / f"{m}_single.pt"
        model = load_checkpoint(path)
        gt0, p0 = positions(model, obs, truth, np.array([0]))
        off_x, off_a = split_on_rays(p0 - gt0, gt0, c)  # where frame 0 puts each Gaussian
        # frame 0's error = the canonical positions' drift from the vertices they start at
        # (frame 0's) + the deformation at frame 0
        canon = model.canonical.means.detach().double().numpy()  # [N, 3]
        dr_x, dr_a = split_on_rays(canon - np.asarray(obs.canonical_xyz), gt0[0], c)
        de_x, de_a = split_on_rays(p0[0] - canon, gt0[0], c)
        print(
            f"{m:12s} frame 0 = drift {_rms(dr_x):.1f} / {_rms(dr_a):.1f} + deformation "
            f"{_rms(de_x):.1f} / {_rms(de_a):.1f} (across / along)"
        )
        for span, frames in spans.items():
            gt, pred = positions(model, obs, truth, frames)
            # motion from frame 0, true and predicted: the placement's offset cancels
            mv_x, mv_a = split_on_rays(gt - gt0, gt, c)
            er_x, er_a = split_on_rays((pred - p0) - (gt - gt0), gt, c)
            print(
                f"{m:12s} {_rms(off_x):14.1f} {_rms(off_a):6.1f}   {span:6s} {_rms(mv_x):13.1f} "
                f"{_rms(mv_a):6.1f} {_rms(er_x):12.1f} {_rms(er_a):6.1f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
