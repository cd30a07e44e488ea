"""Models: the canonical Gaussian set and its deformations (static, learned fields, ours), and the
true-motion reference (truth_motion, the ceiling).

The package's names load on first use (lazy_loader: planning imports no torch): the workflow imports the registry's
model ids to plan jobs, and a dry run should not pay torch's start-up (seconds per Snakemake call)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "base": ["BaseModel", "ModelContext", "context_from_observed"],
        "gaussians": ["GaussianState"],
        "registry": [
            "MODEL_NAMES",
            "MODELS",
            "REFERENCE_NAMES",
            "REFERENCES",
            "build_model",
            "configs_for",
            "is_reference",
            "model_settings",
            "training_jobs",
        ],
        "checkpoint": ["load_checkpoint", "save_checkpoint"],
        "truth_motion": ["TrueMotion", "TruthMotionModel"],
    },
)
