"""Model names, construction from the config, and checkpoints.

A checkpoint (torch.save of plain dicts and tensors, loadable with weights_only=True) holds:
format, model name, training configuration name, seed, the ``models`` config section, the
``train`` config section, the ModelContext (canonical positions, fps, frame counts, frozen wind
statistics), the state dict and the training statistics.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from physgs.atomic import atomic_path
from physgs.models.base import BaseModel, ModelContext, context_from_observed
from physgs.models.fields import FieldModel
from physgs.models.ours import OscillatorPrior
from physgs.models.static import StaticModel

MODEL_NAMES = ("static", "mlp", "mlp_wind", "d3dgs", "d3dgs_wind", "ours")
CONFIG_NAMES = ("single", "joint32", "joint96")
FORMAT = "physgs-model-v1"
#: Ours with K chosen from the data (physgs.models.kselect). Kept out of CONFIG_NAMES so the
#: fixed-K rules and tables do not iterate over it; its K is written into models.configs.auto
#: by ``kselect.auto_config`` before training, and so travels in the checkpoint.
AUTO_CONFIG = "auto"


def configs_for(model: str) -> tuple[str, ...]:
    """Training configurations a model is run in: every model `single`, ours also joint ones."""
    if model not in MODEL_NAMES:
        raise ValueError(f"unknown model {model!r}; choose one of {MODEL_NAMES}")
    return CONFIG_NAMES if model == "ours" else ("single",)


def training_jobs() -> list[tuple[str, str]]:
    """All (model, configuration) pairs that are trained per tree."""
    return [(m, c) for m in MODEL_NAMES for c in configs_for(m)]


def build_model(name: str, observed, cfg: dict, *, config: str = "single", seed: int = 0,
                labels: np.ndarray | None = None) -> BaseModel:
    """A freshly initialised model.

    name: one of MODEL_NAMES; observed: a testbed ``Observed`` or a ModelContext;
    cfg: the resolved config's ``models`` section; config: training configuration (sets K);
    seed: k-means seed (ours); labels: precomputed part labels [N] (used when loading).
    """
    if config == AUTO_CONFIG and name == "ours":
        if not isinstance(cfg["configs"].get(AUTO_CONFIG, {}).get("K"), int):
            raise ValueError("configuration 'auto' has no chosen K yet: run the kselect rule "
                             "(physgs.models.kselect.select_k, then auto_config) first")
    elif config not in configs_for(name):
        raise ValueError(f"model {name!r} is not trained in configuration {config!r}; valid: "
                         f"{configs_for(name)}" + (" or 'auto'" if name == "ours" else ""))
    ctx = observed if isinstance(observed, ModelContext) else context_from_observed(observed)
    canon = dict(cfg["canonical"])
    if name == "static":
        return StaticModel(ctx, canon)
    if name in ("mlp", "mlp_wind", "d3dgs", "d3dgs_wind"):
        arch = name.split("_")[0]
        a = cfg[arch]
        ww = cfg["wind_window"]
        return FieldModel(ctx, canon, arch=arch, pos_bands=a["pos_bands"],
                          time_bands=a["time_bands"], depth=a["depth"], width=a["width"],
                          skip=a.get("skip"), wind=name.endswith("_wind"),
                          window_seconds=ww["seconds"], window_values=ww["values"], name=name)
    o = cfg["ours"]
    return OscillatorPrior(ctx, canon, K=int(cfg["configs"][config]["K"]), omega_hz=o["omega_hz"],
                           zeta=o["zeta"], omega_init_hz=o["omega_init_hz"],
                           zeta_init=o["zeta_init"], substeps=o["substeps"],
                           rk4_guard=o["rk4_guard"], kmeans_n_init=o["kmeans_n_init"], seed=seed,
                           labels=labels)


def save_checkpoint(path, model: BaseModel, *, name: str, config: str, seed: int,
                    models_cfg: dict, train_cfg: dict, stats: dict) -> None:
    """Write the checkpoint atomically (temporary file in the same folder, then rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    blob = {
        "format": FORMAT, "model": name, "config": config, "seed": int(seed),
        "models_cfg": models_cfg, "train_cfg": train_cfg, "context": model.ctx.to_dict(),
        "state_dict": model.state_dict(), "stats": stats,
    }
    with atomic_path(path) as tmp:
        torch.save(blob, tmp)


def read_checkpoint(path) -> dict:
    """The raw checkpoint dict; clear errors for a missing or corrupt file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"no checkpoint at {path}; train it first (snakemake --cores 2 {path})")
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # noqa: BLE001 - any unpickling failure means a corrupt file
        raise ValueError(f"checkpoint {path} is corrupt or not a physgs checkpoint ({e}); delete "
                         "it and retrain") from None
    if not isinstance(blob, dict) or blob.get("format") != FORMAT:
        raise ValueError(f"{path} is not a {FORMAT} checkpoint; delete it and retrain")
    return blob


def load_checkpoint(path) -> BaseModel:
    """Rebuild the trained model (eval mode) from a checkpoint written by save_checkpoint.

    The returned model also carries ``checkpoint_info`` (name, config, seed, stats, cfgs).
    """
    blob = read_checkpoint(path)
    sd = blob["state_dict"]
    labels = sd["part_labels"].numpy() if "part_labels" in sd else None
    model = build_model(blob["model"], ModelContext.from_dict(blob["context"]), blob["models_cfg"],
                        config=blob["config"], seed=blob["seed"], labels=labels)
    model.load_state_dict(sd, strict=True)
    model.eval()
    model.checkpoint_info = {k: blob[k] for k in ("model", "config", "seed", "stats",
                                                  "models_cfg", "train_cfg")}
    return model
