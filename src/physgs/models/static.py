"""Static pose: the canonical set alone, the floor every model must clear."""

from __future__ import annotations

import torch

from physgs.models.base import BaseModel
from physgs.models.gaussians import GaussianState


class StaticModel(BaseModel):
    """No deformation: every frame shows the canonical Gaussians."""

    name = "static"
    use_wind = False

    def deform(self, frame_idx: int, wind: torch.Tensor) -> GaussianState:
        """The canonical Gaussians, whatever the frame and wind.

        Args:
            frame_idx: recorded frame (not read).
            wind: the observed wind [L+F], m/s (not read).

        Returns:
            The activated canonical Gaussians.
        """
        return self.canonical.state()
