"""Evaluation of a reconstruction through a render callback (the protocol, section 4).

Modules: ``metrics`` (PSNR, silhouette centroids), ``splits`` (view / time / transfer splits,
``evaluate``), ``trajectories`` (branch-tip paths in pixels), ``adapter`` (render/means callbacks
from a model via the shared interfaces); safe writes live in [`physgs.atomic`][].

The names load on first use (lazy_loader): the report jobs read evaluation records with
``splits.load_eval`` and should not pay torch's start-up for it.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "metrics": ["psnr", "silhouette_centroid", "centroid_error"],
        "splits": ["EvalResult", "evaluate", "load_eval"],
        "trajectories": ["Trajectories", "tip_trajectories", "load_trajectories"],
        "adapter": ["model_render_fn", "model_means_fn"],
    },
)
