"""Train one (tree, model, configuration) job from the observed dataset and the resolved config."""
from __future__ import annotations

from physgs.models.registry import build_model, save_checkpoint
from physgs.models.visibility import freeze_callback
from physgs.train.loop import condition_indices, train_model, write_loss_log


def run_training(observed, cfg: dict, *, model: str, config: str, checkpoint_path, loss_path,
                 progress: bool = True):
    """Build, train and save one model; returns the TrainResult.

    observed: a testbed Observed; cfg: the resolved config (reads ``seed``, ``models``,
    ``train``). Nothing is written unless training finishes with a finite loss: the loss log and
    the checkpoint are each written atomically, the checkpoint last.
    """
    mcfg, tcfg = cfg["models"], cfg["train"]
    seed = int(cfg["seed"])
    m = build_model(model, observed, mcfg, config=config, seed=seed)
    conds = condition_indices(mcfg["configs"][config]["conditions"], len(observed.conditions))
    # ours freezes parts whose swing never reaches a pixel (models.ours.freeze_below_px)
    hook = freeze_callback(observed, mcfg, tcfg) if model == "ours" else None
    result = train_model(m, observed, tcfg, conditions=conds, seed=seed, name=f"{model}_{config}",
                         progress=progress, on_iteration=hook)
    if model == "ours":
        result.stats["frozen_parts"] = int(result.model.frozen.sum())
    write_loss_log(loss_path, result.log)
    save_checkpoint(checkpoint_path, result.model, name=model, config=config, seed=seed,
                    models_cfg=mcfg, train_cfg=tcfg, stats=result.stats)
    return result
