"""The canonical Gaussian set every model deforms, its per-frame state, and rotation helpers.

Quaternions are (w, x, y, z) and act on column vectors; they need not be unit (the rasterizer
normalises), but the helpers here that build rotations return unit quaternions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from physgs.models.part_transform import transform_parts

# the rotation maths lives in its leaf module; these names stay importable from here
from physgs.rotations import (  # noqa: F401  (re-exported)
    axis_angle_quat,
    quat_multiply,
    quat_to_rotmat,
    rodrigues,
    rodrigues_minus_identity,
)


@dataclass(frozen=True)
class GaussianState:
    """Gaussians ready for [`physgs.render.rasterization`][].

    means [N, 3] world units; quats [N, 4] (w, x, y, z); scales [N, 3] world units (> 0);
    opacities [N] in (0, 1); colors [N, 3] in (0, 1).
    """

    means: torch.Tensor
    quats: torch.Tensor
    scales: torch.Tensor
    opacities: torch.Tensor
    colors: torch.Tensor


def rotate_about_pivot(
    means: torch.Tensor,
    quats: torch.Tensor,
    axis: torch.Tensor,
    angle: torch.Tensor,
    pivot: torch.Tensor,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Rigidly rotate Gaussians: positions about ``pivot`` and orientations alike.

    Rotating the orientation too keeps an elongated Gaussian aligned with the branch it sits on.

    Args:
        means: [N, 3] positions, world units.
        quats: [N, 4] orientations (w, x, y, z).
        axis: [N, 3] unit rotation axes.
        angle: [N] angles, rad.
        pivot: [N, 3] pivot per Gaussian (e.g. gathered from its part), world units.

    Returns:
        ``(means, quats)``: [N, 3] and [N, 4]; exactly the inputs' means at angle 0.
    """
    RmI = rodrigues_minus_identity(axis, angle)  # [N, 3, 3]
    # x' = p + R (x - p) = x + (R - I)(x - p): exactly x at angle 0.
    new_means = means + (RmI @ (means - pivot)[..., None])[..., 0]
    new_quats = quat_multiply(axis_angle_quat(axis, angle), quats)
    return new_means, new_quats


def rotate_parts(
    means: torch.Tensor,
    quats: torch.Tensor,
    labels: torch.Tensor,
    axis: torch.Tensor,
    angle: torch.Tensor,
    pivot: torch.Tensor,
) -> tuple[torch.Tensor, torch.Tensor]:
    """One rotation per part: [`rotate_about_pivot`][physgs.models.gaussians.rotate_about_pivot].

    The K rotations are built once and applied per Gaussian by
    [`transform_parts`][physgs.models.part_transform.transform_parts] (not built N times, one per
    Gaussian): the result equals ``rotate_about_pivot(means, quats, axis[labels], angle[labels],
    pivot[labels])`` to rounding, at a K/N share of the rotation cost.

    Args:
        means: [N, 3] positions, world units.
        quats: [N, 4] orientations (w, x, y, z).
        labels: [N] part of each Gaussian, in [0, K).
        axis: [K, 3] unit rotation axes.
        angle: [K] angles, rad.
        pivot: [K, 3] pivots, world units.

    Returns:
        ``(means, quats)``: [N, 3] and [N, 4].
    """
    RmI = rodrigues_minus_identity(axis, angle)  # [K, 3, 3]
    q = axis_angle_quat(axis, angle)  # [K, 4]
    return transform_parts(means, quats, labels, RmI, pivot, torch.zeros_like(pivot), q)


def nearest_neighbour_scale(xyz: np.ndarray, k: int = 3) -> np.ndarray:
    """Isotropic scale [N] (world units): mean distance to the k nearest other points.

    Coincident points (distance 0) get the smallest positive spacing in the set, so every
    Gaussian has a drawable size.

    Args:
        xyz: [N, 3] positions, world units, N >= 2.
        k: neighbours averaged (at most N - 1).

    Returns:
        [N] scales, world units, all positive.

    Raises:
        ValueError: for positions that are not [N >= 2, 3], not finite, or all coincident.
    """
    xyz = np.asarray(xyz, dtype=np.float64)
    if xyz.ndim != 2 or xyz.shape[1] != 3 or xyz.shape[0] < 2:
        raise ValueError(f"canonical positions must be [N >= 2, 3]; got shape {xyz.shape}")
    if not np.isfinite(xyz).all():
        raise ValueError("canonical positions contain NaN or inf; regenerate the testbed dataset")
    k = min(k, xyz.shape[0] - 1)
    # here: ~0.25 CPU-s of start-up that the jobs loading a trained model never need
    from scipy.spatial import cKDTree

    d, _ = cKDTree(xyz).query(xyz, k=k + 1)
    s = d[:, 1:].mean(axis=1)
    if not (s > 0).any():
        raise ValueError("all canonical positions coincide; the mesh is degenerate")
    return np.where(s > 0, s, s[s > 0].min())


def _logit(p: float) -> float:
    return float(np.log(p / (1 - p)))


class CanonicalGaussians(nn.Module):
    """Trainable canonical set: one Gaussian per mesh vertex (positions only from the mesh).

    Init: means = xyz [N, 3]; identity rotation; isotropic scale = scale_factor x mean
    distance to the ``knn`` nearest vertices; opacity ``opacity``; grey colour ``color``.
    Parameters are stored unactivated (log-scale, opacity and colour logits).
    """

    def __init__(
        self,
        xyz: np.ndarray,
        *,
        opacity: float = 0.1,
        color: float = 0.5,
        knn: int | None = 3,
        scale_factor: float = 1.0,
    ):
        """One Gaussian per vertex of ``xyz``.

        Args:
            xyz: [N, 3] mesh vertices, world units.
            opacity: starting opacity, in (0, 1).
            color: starting grey level, in (0, 1).
            knn: neighbours whose mean distance sets the starting scale; None: no starting
                scale (every scale 1), for a set whose state a checkpoint then replaces
                ([`load_checkpoint`][physgs.models.checkpoint.load_checkpoint]), which so needs no
                neighbour search.
            scale_factor: factor on that distance.

        Raises:
            ValueError: opacity or colour outside (0, 1).
        """
        super().__init__()
        if not (0 < opacity < 1 and 0 < color < 1):
            raise ValueError(
                f"canonical opacity and color must lie in (0, 1); got {opacity}, "
                f"{color} (config models.canonical)"
            )
        xyz = np.asarray(xyz, dtype=np.float64)
        s = (  # [N]
            np.ones(xyz.shape[0])
            if knn is None
            else nearest_neighbour_scale(xyz, knn) * scale_factor
        )
        n = xyz.shape[0]
        self.means = nn.Parameter(torch.tensor(xyz, dtype=torch.float32))
        q = torch.zeros(n, 4)
        q[:, 0] = 1.0
        self.quats = nn.Parameter(q)
        self.log_scales = nn.Parameter(
            torch.tensor(np.log(s), dtype=torch.float32)[:, None].repeat(1, 3)
        )
        self.opacity_logits = nn.Parameter(torch.full((n,), _logit(opacity)))
        self.color_logits = nn.Parameter(torch.full((n, 3), _logit(color)))

    @property
    def n(self) -> int:
        """The number of Gaussians, N."""
        return self.means.shape[0]

    def state(self) -> GaussianState:
        """Activated canonical Gaussians.

        Returns:
            The [`GaussianState`][physgs.models.gaussians.GaussianState]: means and quats as stored,
                scales exp(log_scales), opacities and colours through a sigmoid.
        """
        return GaussianState(
            self.means,
            self.quats,
            torch.exp(self.log_scales),
            torch.sigmoid(self.opacity_logits),
            torch.sigmoid(self.color_logits),
        )
