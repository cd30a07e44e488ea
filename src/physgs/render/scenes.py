"""Synthetic Gaussian scenes for tests and benchmarks (no testbed needed)."""

from __future__ import annotations

import numpy as np
import torch

from physgs.camera import Camera, look_at


def random_scene(
    n: int, width: int, height: int, seed: int, dtype=torch.float32, opacity_range=(0.1, 0.9)
):
    """A canopy-like blob: n Gaussians uniform in a unit ball (world units), seen from 3.5 units.

    Scales follow the mean nearest-neighbour spacing (0.6 x (4/3 pi / n)^(1/3), times a random
    0.5-1.5 anisotropy per axis), random rotations, opacities uniform in ``opacity_range``,
    colours uniform in [0, 1]. Returns (means [n, 3], quats [n, 4], scales [n, 3],
    opacities [n], colors [n, 3], camera, background [3]) as tensors of ``dtype``.
    """
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    means = d * rng.uniform(0, 1, size=(n, 1)) ** (1 / 3)
    spacing = (4.0 / 3.0 * np.pi / max(n, 1)) ** (1 / 3)
    scales = 0.6 * spacing * rng.uniform(0.5, 1.5, size=(n, 3))
    quats = rng.normal(size=(n, 4))
    opac = rng.uniform(*opacity_range, size=n)
    colors = rng.uniform(0, 1, size=(n, 3))
    cam: Camera = look_at([0.0, -3.5, 0.3], [0.0, 0.0, 0.0], fov_deg=40, width=width, height=height)
    bg = np.array([0.9, 0.95, 1.0])
    t = [torch.as_tensor(x, dtype=dtype) for x in (means, quats, scales, opac, colors)]
    return (*t, cam, torch.as_tensor(bg, dtype=dtype))
