# Shared imports and input functions of the rule files.
import os

import physgs.models.registry as _models
from physgs.report import build as _build

# Torch's OpenMP threads spin-wait by default, which starves the other job on a 2-core machine
# (measured: 20x slower projection); jobs inherit this environment.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

TRAIN_JOBS = _models.training_jobs()  # 5 baselines x single + ours x (single, joint32, joint96)


def train_input(wildcards):
    """The observed dataset of the tree; refuses (model, config) pairs that are never trained."""
    if wildcards.config not in _models.configs_for(wildcards.model):
        raise ValueError(
            f"model '{wildcards.model}' is not trained in configuration '{wildcards.config}'; "
            f"valid: {_models.configs_for(wildcards.model)} (joint configurations are ours only)"
        )
    return f"results/testbed/{wildcards.tree}/observed.npz"
