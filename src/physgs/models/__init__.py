"""Models: the canonical Gaussian set and its deformations (static, learned fields, ours), and the
true-motion reference (truth_motion, the ceiling).

The package's names load on first use (PEP 562): the workflow imports the registry's model ids
to plan jobs, and a dry run should not pay torch's start-up (seconds per Snakemake call)."""
import importlib

#: public name -> the submodule that defines it
_WHERE = {
    "BaseModel": "base", "ModelContext": "base", "context_from_observed": "base",
    "GaussianState": "gaussians",
    "MODEL_NAMES": "registry", "MODELS": "registry", "REFERENCE_NAMES": "registry",
    "REFERENCES": "registry", "build_model": "registry", "configs_for": "registry",
    "is_reference": "registry", "load_checkpoint": "registry", "model_settings": "registry",
    "save_checkpoint": "registry", "training_jobs": "registry",
    "TrueMotion": "truth_motion", "TruthMotionModel": "truth_motion",
}
__all__ = list(_WHERE)


def __getattr__(name: str):
    if name not in _WHERE:
        raise AttributeError(f"module 'physgs.models' has no attribute {name!r}")
    return getattr(importlib.import_module(f"physgs.models.{_WHERE[name]}"), name)


def __dir__():
    return sorted(set(globals()) | set(__all__))
