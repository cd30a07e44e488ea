"""Models: the canonical Gaussian set and its deformations (static, learned fields, ours), and the
true-motion reference (truth_motion, the ceiling)."""
from physgs.models.base import BaseModel, ModelContext, context_from_observed
from physgs.models.gaussians import GaussianState
from physgs.models.registry import (
    MODEL_NAMES,
    MODELS,
    REFERENCE_NAMES,
    REFERENCES,
    build_model,
    configs_for,
    is_reference,
    load_checkpoint,
    model_settings,
    save_checkpoint,
    training_jobs,
)
from physgs.models.truth_motion import TrueMotion, TruthMotionModel

__all__ = [
    "BaseModel", "ModelContext", "context_from_observed", "GaussianState", "MODEL_NAMES",
    "MODELS", "REFERENCE_NAMES", "REFERENCES", "TrueMotion", "TruthMotionModel", "build_model",
    "configs_for", "is_reference", "load_checkpoint", "model_settings", "save_checkpoint",
    "training_jobs",
]
