"""One training loop for every model: Adam, L1 + D-SSIM, shared static warm-up and schedule."""
from __future__ import annotations

import csv
import math
import time
from dataclasses import dataclass

import numpy as np
import torch
from tqdm import tqdm

from physgs.atomic import atomic_path
from physgs.models.base import BaseModel
from physgs.render import rasterization
from physgs.train.losses import photometric_loss
from physgs.train.schedule import lr_factor

LOG_FIELDS = ("iteration", "phase", "condition", "frame", "loss", "l1", "dssim", "seconds")


class TrainingError(RuntimeError):
    """Training cannot go on (e.g. the loss turned NaN or inf); no checkpoint is written."""


@dataclass
class TrainResult:
    """The trained model, its statistics (for the checkpoint) and the per-iteration loss log."""

    model: BaseModel
    stats: dict
    log: list[dict]


def condition_indices(spec: str, n_conditions: int) -> list[int]:
    """Wind conditions a configuration trains on: 'train' -> [0], 'all' -> every condition."""
    if spec == "train":
        return [0]
    if spec == "all":
        return list(range(n_conditions))
    raise ValueError(f"unknown conditions {spec!r} in models.configs; use 'train' or 'all'")


def train_model(model: BaseModel, observed, train_cfg: dict, *, conditions: list[int], seed: int,
                name: str | None = None, progress: bool = True, frame_pool=None,
                on_iteration=None) -> TrainResult:
    """Fit ``model`` to the training-camera frames of ``observed``.

    Each iteration draws (seeded) one condition from ``conditions`` and one recorded frame
    j < n_train, renders the model at the training camera and steps Adam on
    (1 - w) L1 + w D-SSIM. The first ``warmup`` iterations render the canonical Gaussians only
    (the shared static warm-up). Raises TrainingError naming the model and iteration if the loss
    turns NaN or inf.

    frame_pool: recorded-frame indices (< n_train) to draw from instead of all of them (K
    selection holds some out). on_iteration(it, model, optimizer) -> dict | None is called
    before each iteration; the dicts it returns are merged into the statistics (freezing).
    """
    name = name or model.name
    iterations, warmup = int(train_cfg["iterations"]), int(train_cfg["warmup"])
    if not 0 <= warmup < iterations:
        raise ValueError(f"train.warmup ({warmup}) must lie in [0, iterations = {iterations})")
    n_cond = np.asarray(observed.wind).shape[0]
    if not conditions or min(conditions) < 0 or max(conditions) >= n_cond:
        raise ValueError(f"conditions {conditions} outside the dataset's {n_cond} conditions")
    if frame_pool is not None:
        frame_pool = np.asarray(frame_pool, dtype=np.int64)
        if frame_pool.size == 0 or frame_pool.min() < 0 or frame_pool.max() >= observed.n_train:
            raise ValueError(f"frame_pool must hold training-frame indices in [0, "
                             f"{observed.n_train}); got {frame_pool.size} frames")
    extra: dict = {}
    rng = np.random.default_rng(seed)
    torch.manual_seed(seed)
    groups = model.param_groups(train_cfg["lr"])
    for g in groups:
        g["base_lr"] = g["lr"]
    opt = torch.optim.Adam(groups, eps=1e-15)
    winds = torch.as_tensor(np.asarray(observed.wind), dtype=torch.float32)  # [C, L+F]
    bg = torch.as_tensor(np.asarray(observed.background), dtype=torch.float32)
    cam = observed.train_camera
    backend = train_cfg.get("backend", "auto")
    w_ssim = float(train_cfg["ssim_weight"])
    final = float(train_cfg["lr_final_ratio"])
    log: list[dict] = []
    model.train()
    t0 = time.perf_counter()
    bar = tqdm(range(iterations), desc=f"train {name}", disable=not progress, mininterval=2.0)
    for it in bar:
        if on_iteration is not None:
            extra.update(on_iteration(it, model, opt) or {})
        c = int(conditions[rng.integers(len(conditions))])
        j = int(rng.integers(observed.n_train) if frame_pool is None
                else frame_pool[rng.integers(frame_pool.size)])
        target = torch.from_numpy(np.array(observed.frames[c, j])).float() / 255.0  # [H, W, 3]
        warm = it < warmup
        s = model.canonical_state() if warm else model.gaussians_at(j, winds[c])
        bad = [k for k in ("means", "quats", "scales", "opacities", "colors")
               if not torch.isfinite(getattr(s, k)).all()]
        if bad:
            raise TrainingError(
                f"model '{name}': Gaussian {', '.join(bad)} became NaN or inf at iteration {it}; "
                "no checkpoint written. Lower the learning rates in config train.lr"
            )
        out = rasterization(s.means, s.quats, s.scales, s.opacities, s.colors, cam, bg,
                            backend=backend, return_depth=False)
        loss, l1, dssim = photometric_loss(out.rgb, target, w_ssim)
        if not math.isfinite(loss.item()):
            raise TrainingError(
                f"model '{name}': loss became {float(loss)} at iteration {it} (condition {c}, "
                f"frame {j}); no checkpoint written. Lower the learning rates in config train.lr "
                "or check the dataset for corrupt frames"
            )
        for g in opt.param_groups:
            g["lr"] = g["base_lr"] * lr_factor(g["name"], it, iterations, warmup, final)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        log.append({"iteration": it, "phase": "warmup" if warm else "deform", "condition": c,
                    "frame": j, "loss": loss.item(), "l1": l1.item(), "dssim": dssim.item(),
                    "seconds": time.perf_counter() - t0})
        if it % 10 == 0:
            bar.set_postfix(loss=f"{loss.item():.4f}")
    wall = time.perf_counter() - t0
    model.eval()
    tail = [r["loss"] for r in log[-max(1, iterations // 10):]]
    stats = {
        "iterations": iterations, "warmup": warmup, "wall_s": wall,
        "s_per_iter": wall / iterations, "final_loss": float(np.mean(tail)),
        "conditions": list(conditions), "seed": int(seed), "backend": backend,
        "n_gaussians": int(model.canonical.n), "wind_mean": float(model.ctx.wind_mean),
        "wind_std": float(model.ctx.wind_std), "torch_threads": torch.get_num_threads(),
        **extra,
    }
    return TrainResult(model, stats, log)


def write_loss_log(path, log: list[dict]) -> None:
    """Write the loss log as CSV atomically (temporary file, then rename)."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=LOG_FIELDS)
        w.writeheader()
        w.writerows(log)
