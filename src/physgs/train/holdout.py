"""The held-out window frames' loss during training: what the stopping rule reads.

The frames are the ones ``train.holdout_every`` keeps out of the training window (of the trained
winds only): never the held-out views, the tail beyond the window or another wind.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from physgs.evaluate.metrics import psnr
from physgs.render import render_state
from physgs.train.losses import photometric_loss


@dataclass(frozen=True)
class HoldoutEval:
    """Renders the held-out window frames at the training camera and scores them.

    pairs: ``(condition, frame)`` of each held-out frame [M]; targets: their images in [0, 1]
    ``[M, H, W, 3]``; winds: ``[C, L+F]`` m/s; the rest as in the training loop.
    """

    pairs: tuple[tuple[int, int], ...]
    targets: torch.Tensor  # [M, H, W, 3]
    winds: torch.Tensor  # [C, L+F]
    camera: object
    background: torch.Tensor  # [3]
    backend: str
    ssim_weight: float

    @staticmethod
    def build(observed, frames, conditions, train_cfg: dict, device=None) -> "HoldoutEval":
        """The evaluator of ``frames`` (held-out recorded-frame indices) under each trained wind.

        Args:
            observed (Observed): the dataset.
            frames (ArrayLike): [M] held-out frame indices (< n_train).
            conditions (list[int]): the trained conditions.
            train_cfg: the ``train`` section (backend, ssim_weight).
            device (str | torch.device | None): where the targets, winds and background live
                (the training's device); None: the CPU.

        Returns:
            The evaluator.

        Raises:
            ValueError: no frames, or a frame outside the training window.
        """
        frames = np.asarray(frames, dtype=np.int64)
        if frames.size == 0 or frames.min() < 0 or frames.max() >= observed.n_train:
            raise ValueError(
                f"held-out frames must be training-window indices in [0, {observed.n_train}); "
                f"got {frames.size} frames (train.holdout_every = 0 holds none out)"
            )
        dev = torch.device("cpu" if device is None else device)
        pairs = tuple((int(c), int(j)) for c in conditions for j in frames)
        imgs = np.stack([np.asarray(observed.frames[c, j]) for c, j in pairs])
        return HoldoutEval(
            pairs=pairs,
            targets=torch.from_numpy(imgs).to(dev).float() / 255.0,
            winds=torch.as_tensor(np.asarray(observed.wind), dtype=torch.float32).to(dev),
            camera=observed.train_camera,
            background=torch.as_tensor(np.asarray(observed.background), dtype=torch.float32).to(
                dev
            ),
            backend=str(train_cfg.get("backend", "auto")),
            ssim_weight=float(train_cfg["ssim_weight"]),
        )

    def evaluate(self, model, warm: bool = False) -> tuple[float, float]:
        """Mean training loss ((1 - w) L1 + w D-SSIM) and mean PSNR (dB) over the held-out frames.

        Args:
            model (BaseModel): the model being trained (left in its mode; no gradients).
            warm: render the canonical Gaussians (the static warm-up) instead of the motion.

        Returns:
            ``(loss, psnr)``.
        """
        losses, psnrs = [], []
        with torch.no_grad():
            canon = model.canonical_state() if warm else None
            for (c, j), target in zip(self.pairs, self.targets):
                s = canon if warm else model.gaussians_at(j, self.winds[c])
                out = render_state(s, self.camera, self.background, backend=self.backend)
                loss, _, _ = photometric_loss(out.rgb, target, self.ssim_weight)
                losses.append(float(loss))
                rgb = out.rgb.clamp(0, 1).float().cpu().numpy()
                psnrs.append(float(psnr(rgb, target.cpu().numpy())))
        return float(np.mean(losses)), float(np.mean(psnrs))
