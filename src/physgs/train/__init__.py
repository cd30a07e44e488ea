"""Training: one loop for every model (Adam, L1 + D-SSIM, shared warm-up and schedule).

The recipe that seeds, builds and trains a job is [`physgs.experiments.recipe`][]."""

from physgs.train.loop import (
    TrainingError,
    TrainResult,
    train_model,
    write_loss_log,
)
from physgs.train.losses import photometric_loss, ssim

__all__ = [
    "TrainingError",
    "TrainResult",
    "train_model",
    "write_loss_log",
    "photometric_loss",
    "ssim",
]
