"""Models: the canonical Gaussian set and its deformations (static, learned fields, ours)."""
from physgs.models.base import BaseModel, ModelContext, context_from_observed
from physgs.models.gaussians import GaussianState
from physgs.models.registry import (
    MODEL_NAMES,
    MODELS,
    build_model,
    configs_for,
    load_checkpoint,
    model_settings,
    save_checkpoint,
    training_jobs,
)

__all__ = [
    "BaseModel", "ModelContext", "context_from_observed", "GaussianState", "MODEL_NAMES",
    "MODELS", "build_model", "configs_for", "load_checkpoint", "model_settings",
    "save_checkpoint", "training_jobs",
]
