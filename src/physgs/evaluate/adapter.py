"""Callbacks that let the evaluation score any model through the shared interfaces only
(``model.gaussians_at`` and [`physgs.render.rasterization`][]), never a model class."""

from __future__ import annotations

import numpy as np
import torch

from physgs.evaluate.splits import NotDefined


def model_render_fn(model, observed, *, backend: str = "auto", means_seen: dict | None = None):
    """render_fn(frame_idx, condition, camera) -> (rgb [H, W, 3] in [0, 1], alpha [H, W]) numpy.

    Runs without autograd; the last deformed frame is kept, so one deformation serves every camera
    (and, for a model blind to the wind, every condition).

    Args:
        model (BaseModel): any module with ``gaussians_at(frame_idx, wind [L+F])`` and
            ``defined(frame_idx, condition)``.
        observed (Observed): the dataset (its wind per condition and background colour).
        backend: the rasterizer backend (see [`rasterization`][physgs.render.rasterization]).
        means_seen: if given, filled with ``(frame_idx, 0) -> means [N, 3]`` numpy (world
            units) of every deformation made under the training wind (condition 0, what the tip
            trajectories read; one condition keeps it to F x N x 3 floats), for
            [`model_means_fn`][physgs.evaluate.adapter.model_means_fn] to reuse.

    Returns:
        (Callable): The callback, float64 arrays; it raises
            [`NotDefined`][physgs.evaluate.splits.NotDefined] where the model makes no prediction.
    """
    # here: the rasterizer loads numba, which the evaluate job should load only once
    # physgs.jobs.job has set the rule's threads (its pool then starts at that size)
    from physgs.render import render_state

    dev = _device_of(model)
    winds = [torch.as_tensor(w, dtype=torch.float32).to(dev) for w in observed.wind]  # C x [L+F]
    bg = torch.as_tensor(np.asarray(observed.background), dtype=torch.float32).to(dev)  # [3]
    reads_wind = bool(getattr(model, "use_wind", True))
    last: dict = {}  # the last deformed frame: one deformation serves every camera and, for
    # models blind to the wind, every condition (the evaluation visits frames in that order)

    def render_fn(frame_idx: int, condition: int, camera):
        if not model.defined(int(frame_idx), int(condition)):
            raise NotDefined(
                f"{model.name}: no prediction at frame {frame_idx}, condition {condition}"
            )
        key = (int(frame_idx), int(condition) if reads_wind else 0)
        with torch.no_grad():
            if last.get("key") != key:
                last["key"], last["g"] = key, model.gaussians_at(int(frame_idx), winds[condition])
                if means_seen is not None and key[1] == 0:  # the training wind's, or any for
                    # a model blind to the wind (the same deformation)
                    means_seen[(int(frame_idx), 0)] = last["g"].means.cpu().numpy()
            g = last["g"]
            out = render_state(g, camera, bg, backend=backend)
        return (
            out.rgb.clamp(0, 1).cpu().numpy().astype(np.float64),
            out.alpha.cpu().numpy().astype(np.float64),
        )

    return render_fn


def model_means_fn(model, observed, seen: dict | None = None):
    """means_fn(frame_idx, condition) -> Gaussian means [N, 3] numpy (world units).

    Args:
        model (BaseModel): the trained model.
        observed (Observed): the dataset (its wind per condition).
        seen: ``(frame_idx, condition) -> means`` already computed (a render_fn's
            ``means_seen``), returned as they are instead of deforming again.

    Returns:
        (Callable): ``means_fn``; NaN means [N, 3] where the model makes no prediction.
    """
    dev = _device_of(model)
    winds = [torch.as_tensor(w, dtype=torch.float32).to(dev) for w in observed.wind]  # m/s

    def means_fn(frame_idx: int, condition: int) -> np.ndarray:
        if seen is not None and (int(frame_idx), int(condition)) in seen:
            return seen[(int(frame_idx), int(condition))]
        if not model.defined(int(frame_idx), int(condition)):  # no prediction: NaN, not a path
            return np.full((model.canonical_state().means.shape[0], 3), np.nan, np.float32)
        with torch.no_grad():
            return model.gaussians_at(int(frame_idx), winds[condition]).means.cpu().numpy()

    return means_fn


def _device_of(model) -> torch.device:
    """Where the model's parameters live: the renders and winds go there too."""
    p = next(model.parameters(), None)
    return torch.device("cpu") if p is None else p.device
