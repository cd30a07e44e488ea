"""Gaussian scenes for tests and benchmarks: a synthetic blob (no testbed needed) and a testbed
tree's initial canonical set seen from its training camera."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from physgs.camera import Camera, look_at
from physgs.models.gaussians import CanonicalGaussians
from physgs.testbed.dataset import load_observed


def random_scene(
    n: int, width: int, height: int, seed: int, dtype=torch.float32, opacity_range=(0.1, 0.9)
):
    """A canopy-like blob: n Gaussians uniform in a unit ball (world units), seen from 3.5 units.

    Scales follow the mean nearest-neighbour spacing (0.6 x (4/3 pi / n)^(1/3), times a random
    0.5-1.5 anisotropy per axis), random rotations, opacities uniform in ``opacity_range``,
    colours uniform in [0, 1].

    Args:
        n: number of Gaussians.
        width: image width, px.
        height: image height, px.
        seed: the generator's seed.
        dtype (torch.dtype): the tensors' dtype.
        opacity_range (tuple[float, float]): ``(lo, hi)`` of the opacities.

    Returns:
        (tuple): ``(means [n, 3], quats [n, 4], scales [n, 3], opacities [n], colors [n, 3],
            camera, background [3])``, tensors of ``dtype`` and a
            [`Camera`][physgs.camera.Camera].
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


def tree_scene(dataset_dir, canonical_cfg: dict | None = None, dtype=torch.float32):
    """A testbed tree's canonical Gaussians at initialisation, seen from its training camera.

    Built exactly as every model builds its canonical set
    ([`CanonicalGaussians`][physgs.models.gaussians.CanonicalGaussians] on
    ``Observed.canonical_xyz``), so the scene is what the first training iteration renders.

    Args:
        dataset_dir (str | Path): a testbed folder holding ``observed.npz``
            (results/testbed/<tree>).
        canonical_cfg: ``models.canonical`` of the config (opacity, color, knn, scale_factor; the
            class defaults when None).
        dtype (torch.dtype): the tensors' dtype.

    Returns:
        (tuple): The tuple of [`random_scene`][physgs.render.scenes.random_scene]: ``(means
            [N, 3], quats [N, 4], scales [N, 3], opacities [N], colors [N, 3], camera, background
            [3])``, the image the camera's size (pixels).
    """
    obs = load_observed(Path(dataset_dir) / "observed.npz")
    with torch.no_grad():
        st = CanonicalGaussians(obs.canonical_xyz, **(canonical_cfg or {})).state()
        t = [
            x.detach().to(dtype).clone()
            for x in (st.means, st.quats, st.scales, st.opacities, st.colors)
        ]
    return (*t, obs.train_camera, torch.as_tensor(np.asarray(obs.background), dtype=dtype))
