"""Training: one loop for every model (Adam, L1 + D-SSIM, shared warm-up and schedule)."""
from physgs.train.loop import TrainingError, TrainResult, condition_indices, train_model, write_loss_log
from physgs.train.losses import photometric_loss, ssim
from physgs.train.run import run_training

__all__ = ["TrainingError", "TrainResult", "condition_indices", "train_model", "write_loss_log",
           "photometric_loss", "ssim", "run_training"]
