"""What every model shares: the context read off the observed dataset, and the canonical set."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from physgs.models.gaussians import CanonicalGaussians, GaussianState


@dataclass(frozen=True)
class ModelContext:
    """The observed-dataset facts a model is built from (never ground-truth physics).

    canonical_xyz [N, 3] world units (mesh vertices at recorded frame 1); fps frames/s;
    n_train training frames; lead_in_frames L (wind column L = recorded frame 1);
    wind_mean, wind_std m/s of the training condition's observed wind (lead-in included);
    wind_force_std m^2/s^2, std of v^2 - mean(v)^2 of that wind (scales the oscillator gain);
    view_dir [3] unit viewing direction of the training camera (world);
    vbar_ratio: the condition's nominal mean speed over the mean of its observed record (the
    conditions are rescalings of one record, so one ratio serves all; vbar = ratio * mean(wind)).
    """

    canonical_xyz: np.ndarray
    fps: int
    n_train: int
    lead_in_frames: int
    wind_mean: float
    wind_std: float
    wind_force_std: float
    view_dir: np.ndarray
    vbar_ratio: float = 1.0

    def to_dict(self) -> dict:
        """Checkpoint-safe form (tensors and Python scalars only).

        Returns:
            The fields by name: canonical_xyz a float32 tensor [N, 3], view_dir a float64 tensor
                [3], the rest ints and floats.
        """
        return {
            "canonical_xyz": torch.tensor(np.asarray(self.canonical_xyz, dtype=np.float32)),
            "fps": int(self.fps),
            "n_train": int(self.n_train),
            "lead_in_frames": int(self.lead_in_frames),
            "wind_mean": float(self.wind_mean),
            "wind_std": float(self.wind_std),
            "wind_force_std": float(self.wind_force_std),
            "view_dir": torch.tensor(np.asarray(self.view_dir, dtype=np.float64)),
            "vbar_ratio": float(self.vbar_ratio),
        }

    @staticmethod
    def from_dict(d: dict) -> "ModelContext":
        """The context that [to_dict][physgs.models.base.ModelContext.to_dict] wrote.

        Args:
            d: field name -> value; ``vbar_ratio`` defaults to 1.0 when absent (older checkpoints).

        Returns:
            The context.
        """
        return ModelContext(
            np.asarray(d["canonical_xyz"], dtype=np.float32),
            int(d["fps"]),
            int(d["n_train"]),
            int(d["lead_in_frames"]),
            float(d["wind_mean"]),
            float(d["wind_std"]),
            float(d["wind_force_std"]),
            np.asarray(d["view_dir"], dtype=np.float64),
            float(d.get("vbar_ratio", 1.0)),
        )


def context_from_observed(obs, wind: bool = True) -> ModelContext:
    """ModelContext from a [`physgs.testbed.dataset.Observed`][] (training condition = index 0).

    Args:
        obs (Observed): the testbed's [`Observed`][physgs.testbed.dataset.Observed].
        wind: False for a model that never reads the wind (``ModelSpec.wind``): the wind
            statistics are NaN and the observed wind is not looked at (it may be NaN itself).

    Returns:
        The [`ModelContext`][physgs.models.base.ModelContext]: canonical positions, frame counts,
            the training wind's mean and std (m/s) and its forcing's std (m^2/s^2), the training
            camera's viewing direction [3].

    Raises:
        ValueError: when ``wind`` and the training wind is constant or not finite.
    """
    w = np.asarray(obs.wind[0], dtype=np.float64) if wind else np.full(2, np.nan)  # [L+F] m/s
    std = float(w.std())
    if wind and (not np.isfinite(w).all() or std <= 0):
        raise ValueError(
            "the training condition's observed wind is constant or not finite; a wind-driven "
            "model needs varying wind: regenerate the testbed dataset"
        )
    fwd = np.asarray(obs.train_camera.R, dtype=np.float64)[2]  # camera +z in world
    return ModelContext(
        canonical_xyz=np.asarray(obs.canonical_xyz, dtype=np.float32),
        fps=int(obs.fps),
        n_train=int(obs.n_train),
        lead_in_frames=int(obs.lead_in_frames),
        wind_mean=float(w.mean()),
        wind_std=std,
        wind_force_std=float((w**2 - w.mean() ** 2).std()),
        view_dir=fwd,
        vbar_ratio=float(np.asarray(obs.vbar)[0] / w.mean()) if hasattr(obs, "vbar") else 1.0,
    )


class BaseModel(nn.Module):
    """A canonical Gaussian set plus a deformation; subclasses implement ``deform``.

    ``gaussians_at(frame_idx, wind)`` gives the Gaussians at recorded frame ``frame_idx``
    (0-based; t_norm = frame_idx / (n_train - 1)) under the condition whose observed wind
    [L+F] (m/s, lead-in included) is passed.
    """

    name = "base"

    def __init__(self, ctx: ModelContext, canonical_cfg: dict):
        """Build the canonical set from the context.

        Args:
            ctx: the observed-dataset facts (canonical positions [N, 3], fps, wind statistics).
            canonical_cfg: keyword arguments of
                [CanonicalGaussians][physgs.models.gaussians.CanonicalGaussians] (config
                ``models.canonical``).
        """
        super().__init__()
        self.ctx = ctx
        self.fps = ctx.fps
        self.n_train = ctx.n_train
        self.lead_in = ctx.lead_in_frames
        self.canonical = CanonicalGaussians(ctx.canonical_xyz, **canonical_cfg)
        xyz = np.asarray(ctx.canonical_xyz, dtype=np.float64)
        lo, hi = xyz.min(0), xyz.max(0)
        # Scene size in world units: scales position learning rates like 3DGS's spatial_lr_scale.
        self.extent = float(0.5 * np.linalg.norm(hi - lo))

    def t_norm(self, frame_idx: int) -> float:
        """Normalised time: 0 at recorded frame 0, 1 at the last training frame.

        Args:
            frame_idx: recorded frame, 0-based.

        Returns:
            ``frame_idx / (n_train - 1)`` (above 1 beyond the window).
        """
        return frame_idx / (self.n_train - 1)

    def _check(self, frame_idx: int, wind: torch.Tensor) -> None:
        if wind.ndim != 1:
            raise ValueError(
                f"{self.name}: wind must be one condition's series [L+F], got shape "
                f"{tuple(wind.shape)}"
            )
        if not 0 <= frame_idx < wind.shape[0] - self.lead_in:
            raise ValueError(
                f"{self.name}: frame {frame_idx} outside the recording (0 .. "
                f"{wind.shape[0] - self.lead_in - 1} for a wind series of {wind.shape[0]} "
                f"columns with lead-in {self.lead_in})"
            )

    # Whether the deformation reads the wind (a model that does not gives the same Gaussians under
    # every condition, which lets the evaluation deform each frame once).
    use_wind: bool = True

    def defined(self, frame_idx: int, condition: int) -> bool:
        """Whether the model predicts recorded frame ``frame_idx`` under condition ``condition``
        (every model but a prior with a learned forcing predicts everything).

        Args:
            frame_idx: recorded frame, 0-based.
            condition: wind condition index.

        Returns:
            True here; overridden where a model predicts only some frames.
        """
        return True

    def canonical_state(self) -> GaussianState:
        """The undeformed canonical Gaussians (used by the shared static warm-up).

        Returns:
            The canonical set's [`GaussianState`][physgs.models.gaussians.GaussianState].
        """
        return self.canonical.state()

    def gaussians_at(self, frame_idx: int, wind: torch.Tensor) -> GaussianState:
        """Gaussians at recorded frame ``frame_idx`` under the observed wind [L+F] (m/s).

        Args:
            frame_idx: recorded frame, 0-based.
            wind: [L+F] the condition's observed wind, m/s, lead-in included.

        Returns:
            The deformed [`GaussianState`][physgs.models.gaussians.GaussianState].

        Raises:
            ValueError: when the frame or the wind does not fit the model (the model's own check).
        """
        wind = torch.as_tensor(wind, dtype=torch.float32)
        self._check(int(frame_idx), wind)
        return self.deform(int(frame_idx), wind)

    def deform(self, frame_idx: int, wind: torch.Tensor) -> GaussianState:
        """The Gaussians at recorded frame ``frame_idx``; each model implements it.

        Args:
            frame_idx: recorded frame, 0-based (0 .. n_train - 1 in the window, beyond it the tail).
            wind: the condition's observed wind [L+F], m/s, lead-in included.

        Returns:
            The deformed, activated Gaussians (N of them).
        """
        raise NotImplementedError

    def param_groups(self, lr: dict) -> list[dict]:
        """Adam parameter groups; the canonical set uses the same rates in every model.

        Args:
            lr: config ``train.lr`` (means and pivot rates are multiplied by the scene extent).

        Returns:
            The canonical set's groups (means, quats, scales, opacities, colors) followed by
                [`deformation_param_groups`][physgs.models.base.BaseModel.deformation_param_groups].
        """
        c = self.canonical
        groups = [
            {"name": "means", "params": [c.means], "lr": lr["means"] * self.extent},
            {"name": "quats", "params": [c.quats], "lr": lr["quats"]},
            {"name": "scales", "params": [c.log_scales], "lr": lr["scales"]},
            {"name": "opacities", "params": [c.opacity_logits], "lr": lr["opacities"]},
            {"name": "colors", "params": [c.color_logits], "lr": lr["colors"]},
        ]
        return groups + self.deformation_param_groups(lr)

    def deformation_param_groups(self, lr: dict) -> list[dict]:
        """Adam parameter groups of the deformation (`param_groups` adds the canonical set's).

        Args:
            lr: config ``train.lr``.

        Returns:
            The groups (``name``, ``params``, ``lr``); none for a model without deformation.
        """
        return []

    def bounded_positions(self) -> dict[str, np.ndarray]:
        """Where each bounded physical parameter sits between its bounds: name -> [n] in [0, 1]
        (0: the lower bound, 1: the upper). Models without bounded parameters: empty.

        Returns:
            Empty here; a model with bounded parameters overrides it.
        """
        return {}

    def scale_settings(self) -> dict[str, list[tuple[str, float]]]:
        """Config settings besides a group's rate that scale what the group's parameters do now:
        parameter group -> [(dotted config key, value)]; named when that group is suspect.

        Returns:
            Empty here; a model whose groups scale with other settings overrides it.
        """
        return {}
