"""Evaluation of a reconstruction through a render callback (SPEC section 4).

Modules: ``metrics`` (PSNR, silhouette centroids), ``splits`` (view / time / transfer splits,
``evaluate``), ``trajectories`` (branch-tip paths in pixels), ``adapter`` (render/means callbacks
from a model via the shared interfaces); safe writes live in ``physgs.atomic``.
"""
from physgs.evaluate.adapter import model_means_fn, model_render_fn
from physgs.evaluate.metrics import centroid_error, psnr, silhouette_centroid
from physgs.evaluate.splits import EvalResult, evaluate, load_eval
from physgs.evaluate.trajectories import Trajectories, load_trajectories, tip_trajectories

__all__ = ["psnr", "silhouette_centroid", "centroid_error", "EvalResult", "evaluate", "load_eval",
           "Trajectories", "tip_trajectories", "load_trajectories", "model_render_fn", "model_means_fn"]
