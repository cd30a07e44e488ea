"""Evaluation of a reconstruction through a render callback (SPEC section 4).

Modules: ``metrics`` (PSNR, silhouette centroids), ``splits`` (view / time / transfer splits,
``evaluate``), ``trajectories`` (branch-tip paths in pixels), ``adapter`` (render/means callbacks
from a model via the shared interfaces); safe writes live in ``physgs.atomic``.

The names load on first use (PEP 562): the report jobs read evaluation records with
``splits.load_eval`` and should not pay torch's start-up for it.
"""
import importlib

#: public name -> the submodule that defines it
_WHERE = {
    "psnr": "metrics", "silhouette_centroid": "metrics", "centroid_error": "metrics",
    "EvalResult": "splits", "evaluate": "splits", "load_eval": "splits",
    "Trajectories": "trajectories", "tip_trajectories": "trajectories",
    "load_trajectories": "trajectories",
    "model_render_fn": "adapter", "model_means_fn": "adapter",
}
__all__ = list(_WHERE)


def __getattr__(name: str):
    if name not in _WHERE:
        raise AttributeError(f"module 'physgs.evaluate' has no attribute {name!r}")
    return getattr(importlib.import_module(f"physgs.evaluate.{_WHERE[name]}"), name)


def __dir__():
    return sorted(set(globals()) | set(__all__))
