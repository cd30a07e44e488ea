"""A tree's geometry without its frames: what per-iteration costs and rasterizer checks need.

The cost of a training iteration does not depend on the target image's content, so the speed
benchmarks train on an observed-like stand-in that has the tree's real canonical set, wind and
training camera (the testbed's own framing) but flat grey frames, and skip the Embree renders.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from physgs.testbed import scene
from physgs.testbed.dataset import simulate_tree, swept_points


def geometry_stand_in(cfg: dict, tree: str, resolution: int | None = None) -> SimpleNamespace:
    """An observed-like dataset of ``tree`` with flat frames.

    Args:
        cfg: the resolved config (``testbed``, ``presets``, ``seed``).
        tree: the tree's name.
        resolution: the image side, px; None: ``testbed.resolution``.

    Returns:
        The fields a model and the training loop read from an
            [`Observed`][physgs.testbed.dataset.Observed]: fps, n_train, n_tail,
            lead_in_frames, conditions, wind [C, L+F] m/s, frames [C, F, R, R, 3] uint8 (all 128,
            a read-only broadcast), train_camera, background [3], canonical_xyz [N, 3] float32 m.
    """
    tb = cfg["testbed"]
    R = int(tb["resolution"] if resolution is None else resolution)
    sim = simulate_tree(dict(tb, resolution=R), cfg["presets"][tree], seed=cfg["seed"], tree=tree)
    # the testbed's own framing (swept extent of every frame and condition)
    cam = scene.frame_cameras(
        swept_points(sim.truth),
        [0.0],
        fov_deg=tb["fov_deg"],
        resolution=R,
        fill_height=tb["fill_height"],
    )[0]
    F = tb["n_train"] + tb["n_tail"]
    frames = np.broadcast_to(np.full((R, R, 3), 128, np.uint8), (sim.wind.shape[0], F, R, R, 3))
    return SimpleNamespace(
        fps=tb["fps"],
        n_train=tb["n_train"],
        n_tail=tb["n_tail"],
        lead_in_frames=sim.truth.lead_in_frames,
        conditions=sim.conditions,
        wind=sim.wind,
        frames=frames,
        train_camera=cam,
        background=np.asarray(tb["background"]),
        canonical_xyz=sim.truth.rest_vertices.astype(np.float32),
    )
