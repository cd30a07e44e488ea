"""Branch-tip trajectories in pixels at the training camera, through the window and the tail."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Callable

import numpy as np

from physgs.atomic import save_npz
from physgs.intermediate import read_npz
from physgs.testbed.kinematics import pose_vertices

MeansFn = Callable[[int, int], np.ndarray]  # (frame_idx, condition) -> Gaussian means [N, 3]


@dataclass(frozen=True)
class Trajectories:
    """Tip paths projected by the training camera, pixels (x right, y down).

    gt_px, pred_px: [P, F, 2] for the tip vertices ``tips`` [P] (mesh vertex indices) over
    recorded frames 0..F-1 of ``condition``; frames < n_train lie in the training window, the rest
    in the tail. The prediction is the model's Gaussian of each tip vertex
    (``truth.vertex_gaussian[tips]``: the observed Gaussians are stored in a random order).
    """

    gt_px: np.ndarray  # [P, F, 2]
    pred_px: np.ndarray  # [P, F, 2]
    tips: np.ndarray  # [P] mesh vertex indices
    condition: int
    n_train: int

    def error_px(self) -> np.ndarray:
        """[P, F] pixel distance between predicted and ground-truth tips.

        Returns:
            [P, F] distances, px.
        """
        return np.linalg.norm(self.pred_px - self.gt_px, axis=-1)

    def save(self, path) -> None:
        """Write the trajectories to a ``.npz`` atomically (read back by `load_trajectories`).

        Args:
            path (str | os.PathLike): the ``.npz`` file to write.
        """
        save_npz(path, **{f.name: np.asarray(getattr(self, f.name)) for f in fields(self)})


def load_trajectories(path) -> Trajectories:
    """Read the trajectories that [save][physgs.evaluate.trajectories.Trajectories.save] wrote.

    Args:
        path (str | os.PathLike): the ``.npz`` file.

    Returns:
        The trajectories (``gt_px``, ``pred_px`` [P, F, 2] px, ``tips`` [P]).

    Raises:
        IntermediateFileError: the file is missing or not a trajectories file (rule ``evaluate``).
    """
    d = read_npz(path, [f.name for f in fields(Trajectories)], rule="evaluate")
    d["condition"], d["n_train"] = int(d["condition"]), int(d["n_train"])
    return Trajectories(**d)


def gt_tip_positions(
    truth,
    tips: np.ndarray,
    condition: int,
    lead_in_frames: int,
    n_frames: int,
    pose_fn: Callable | None = None,
) -> np.ndarray:
    """Ground-truth world positions [P, F, 3] of vertices ``tips`` at recorded frames 0..F-1.

    Recorded frame j uses bone angles ``truth.theta[condition, lead_in_frames + j]`` (rad) posed
    by forward kinematics.

    Args:
        truth (Truth): the dataset's ground truth.
        tips: [P] mesh vertex indices.
        condition: the wind condition's index.
        lead_in_frames: lead-in frames L.
        n_frames: F, the recorded frames.
        pose_fn: ``pose_fn(truth, theta_b [B]) -> [N, 3]`` (default
            [`pose_vertices`][physgs.testbed.kinematics.pose_vertices]).

    Returns:
        [P, F, 3] positions, m.

    Raises:
        ValueError: when the truth holds fewer than L + F samples.
    """
    if pose_fn is None:
        pose_fn = pose_vertices
    theta = np.asarray(truth.theta)[condition]  # [L+F, B]
    if lead_in_frames + n_frames > theta.shape[0]:
        raise ValueError(
            f"truth has {theta.shape[0]} samples, fewer than lead-in {lead_in_frames} "
            f"+ {n_frames} frames; dataset and truth files disagree"
        )
    out = np.empty((len(tips), n_frames, 3))
    for j in range(n_frames):
        out[:, j] = np.asarray(pose_fn(truth, theta[lead_in_frames + j]))[tips]
    return out


def tip_trajectories(
    means_fn: MeansFn,
    truth,
    observed,
    *,
    condition: int = 0,
    tips: np.ndarray | None = None,
    pose_fn: Callable | None = None,
) -> Trajectories:
    """Ground-truth and predicted branch-tip paths in pixels at the training camera.

    The Gaussian of vertex v is ``truth.vertex_gaussian[v]`` (one Gaussian per mesh vertex, in the
    seeded random order of ``canonical_xyz``). Covers all F = n_train + n_tail recorded frames.

    Args:
        means_fn: ``means_fn(frame_idx, condition) -> [N, 3]`` numpy Gaussian means of the
            model, in Gaussian order.
        truth (Truth): the dataset's ground truth.
        observed (Observed): the dataset (training camera, frame counts).
        condition: the wind condition's index.
        tips: [P] mesh vertex indices (default ``truth.tip_vertices``).
        pose_fn: forward kinematics for the ground truth (see
            [`gt_tip_positions`][physgs.evaluate.trajectories.gt_tip_positions]).

    Returns:
        The [`Trajectories`][physgs.evaluate.trajectories.Trajectories], px.
    """
    tips = np.asarray(truth.tip_vertices if tips is None else tips, dtype=np.int64)
    gauss = np.asarray(truth.vertex_gaussian, dtype=np.int64)[tips]  # the tips' Gaussians
    F = int(observed.n_train + observed.n_tail)
    cam = observed.train_camera
    gt = gt_tip_positions(truth, tips, condition, int(observed.lead_in_frames), F, pose_fn)
    pred = np.stack(
        [np.asarray(means_fn(j, condition))[gauss] for j in range(F)], axis=1
    )  # [P, F, 3]
    P = len(tips)
    gt_px, _ = cam.project(gt.reshape(-1, 3))
    pred_px, _ = cam.project(pred.reshape(-1, 3).astype(np.float64))
    return Trajectories(
        gt_px.reshape(P, F, 2),
        pred_px.reshape(P, F, 2),
        tips,
        int(condition),
        int(observed.n_train),
    )
