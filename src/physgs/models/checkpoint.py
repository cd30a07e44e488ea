"""Checkpoints: write a trained model, read one back, rebuild it.

A checkpoint (torch.save of plain dicts and tensors, loadable with weights_only=True) holds:
format, model name, training configuration name, seed, the ``models`` settings it was built from,
the ``train`` config section, the ModelContext (canonical positions, fps, frame counts, frozen
wind statistics), the state dict and the training statistics. A model is rebuilt by
[`build_model`][physgs.models.registry.build_model] from what the checkpoint stores.

torch loads inside the functions: the workflow's planning imports the models package.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from physgs.atomic import atomic_path
from physgs.intermediate import remake_hint
from physgs.models.registry import build_model, is_reference

if TYPE_CHECKING:  # the model classes load torch (module docstring)
    from physgs.models.base import BaseModel

FORMAT = "physgs-model-v2"


def save_checkpoint(
    path,
    model: BaseModel,
    *,
    name: str,
    config: str,
    seed: int,
    models_cfg: dict,
    train_cfg: dict,
    stats: dict,
) -> None:
    """Write the checkpoint atomically (temporary file in the same folder, then rename).

    Args:
        path (str | Path): the ``.pt`` file.
        model: the trained model.
        name: its model id.
        config: its training configuration name.
        seed: its training seed.
        models_cfg: the settings the model was built from
            ([`model_settings`][physgs.models.registry.model_settings] or the whole ``models``
            section); ours' K is read off the model, so any configuration name reloads.
        train_cfg: the ``train`` config section it was trained with.
        stats: the training statistics.
    """
    import torch  # here: the workflow plans with this module (module docstring)

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    blob = {
        "format": FORMAT,
        "model": name,
        "config": config,
        "seed": int(seed),
        "K": int(model.K) if hasattr(model, "K") else None,
        "models_cfg": models_cfg,
        "train_cfg": train_cfg,
        "context": model.ctx.to_dict(),
        "state_dict": _device_free(model.state_dict()),
        "stats": stats,
    }
    with atomic_path(path) as tmp:
        torch.save(blob, tmp)


def _device_free(sd):
    """``sd`` with its tensors on the CPU, so a model trained on a GPU reloads on any machine
    (``read_checkpoint`` maps to the CPU); a CPU model's state is returned as it is, so its file
    stays byte for byte what it was."""
    if all(v.device.type == "cpu" for v in sd.values()):
        return sd
    out = type(sd)((k, v.cpu()) for k, v in sd.items())
    out._metadata = getattr(sd, "_metadata", None)  # the modules' versions load_state_dict reads
    return out


def read_checkpoint(path) -> dict:
    """The raw checkpoint dict; clear errors for a missing or corrupt file.

    Args:
        path (str | Path): the ``.pt`` file.

    Returns:
        The checkpoint's dict (loaded on the CPU, ``weights_only``).

    Raises:
        FileNotFoundError: when there is no file.
        ValueError: when it does not unpickle or is not a checkpoint of this format.
    """
    import torch  # here: the workflow plans with this module (module docstring)

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"no checkpoint at {path}; train it first (snakemake --cores 2 {path})"
        )
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # noqa: BLE001 - any unpickling failure means a corrupt file
        raise ValueError(
            f"checkpoint {path} is corrupt or not a physgs checkpoint ({e}); to retrain it "
            f"{remake_hint(path).removeprefix('to remake it ')}"
        ) from None
    if not isinstance(blob, dict) or blob.get("format") != FORMAT:
        raise ValueError(
            f"{path} is not a {FORMAT} checkpoint; to retrain it "
            f"{remake_hint(path).removeprefix('to remake it ')}"
        )
    return blob


def load_checkpoint(path) -> BaseModel:
    """Rebuild the trained model (eval mode) from a checkpoint written by save_checkpoint.

    The returned model also carries ``checkpoint_info`` (name, config, seed, stats, cfgs).

    Args:
        path (str | Path): the ``.pt`` file.

    Returns:
        The model in eval mode, its state loaded strictly.

    Raises:
        FileNotFoundError: when there is no file.
        ValueError: for a corrupt checkpoint.
    """
    # here: torch, as in build_model
    from physgs.models.base import ModelContext
    from physgs.models.truth_motion import TrueMotion

    blob = read_checkpoint(path)
    sd = blob["state_dict"]
    labels = sd["part_labels"].numpy() if "part_labels" in sd else None
    parent = sd["part_parent"].numpy() if "part_parent" in sd else None
    # a reference's motion is in its own buffers: no truth.npz needed to reload it
    motion = TrueMotion.from_state_dict(sd) if is_reference(blob["model"]) else None
    # the checkpoint's state replaces the starting scales: no neighbour search (nor scipy)
    cfg = {**blob["models_cfg"], "canonical": {**blob["models_cfg"]["canonical"], "knn": None}}
    model = build_model(
        blob["model"],
        ModelContext.from_dict(blob["context"]),
        cfg,
        config=blob["config"],
        K=blob["K"],
        seed=blob["seed"],
        labels=labels,
        parent=parent,
        truth=motion,
    )
    model.load_state_dict(sd, strict=True)
    model.eval()
    model.checkpoint_info = {
        k: blob[k] for k in ("model", "config", "seed", "stats", "models_cfg", "train_cfg")
    }
    return model
