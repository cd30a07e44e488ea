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
from physgs.render import render_state
from physgs.train.adam import FusedAdam
from physgs.train.divergence import SUSPECT_GROWN, Divergence, DivergenceGuard, pinned
from physgs.train.holdout import HoldoutEval
from physgs.train.losses import photometric_loss
from physgs.train.schedule import lr_factor
from physgs.train.stopping import STOP_CAP, STOP_PLATEAU, Plateau, StopRule

#: The loss log's columns. phase: warmup | deform | anneal (the final decay after the stopping
#: rule triggered: a log whose last phase is anneal stopped on a plateau); holdout: the held-out
#: window frames' mean loss, evaluated before that iteration (empty between evaluations).
LOG_FIELDS = (
    "iteration",
    "phase",
    "condition",
    "frame",
    "loss",
    "l1",
    "dssim",
    "holdout",
    "seconds",
)


class TrainingError(RuntimeError):
    """Training cannot go on (the loss turned NaN or inf, the fit diverged, or the model's
    forward pass failed); no checkpoint is written."""


#: Canonical-set field of a GaussianState -> the parameter group (train.lr key) that trains it.
_STATE_GROUP = {
    "means": "means",
    "quats": "quats",
    "scales": "scales",
    "opacities": "opacities",
    "colors": "colors",
}


@dataclass
class TrainResult:
    """The trained model, its statistics (for the checkpoint) and the per-iteration loss log."""

    model: BaseModel
    stats: dict
    log: list[dict]


def condition_indices(spec: str, n_conditions: int) -> list[int]:
    """Wind conditions a configuration trains on: 'train' -> [0], 'all' -> every condition.

    Args:
        spec: ``'train'`` or ``'all'`` (a configuration's ``conditions``).
        n_conditions: the dataset's condition count.

    Returns:
        The condition indices.

    Raises:
        ValueError: for any other ``spec``.
    """
    if spec == "train":
        return [0]
    if spec == "all":
        return list(range(n_conditions))
    raise ValueError(f"unknown conditions {spec!r} in models.configs; use 'train' or 'all'")


def train_model(
    model: BaseModel,
    observed,
    train_cfg: dict,
    *,
    conditions: list[int],
    seed: int,
    name: str | None = None,
    progress: bool = True,
    frame_pool=None,
    on_iteration=None,
    holdout: HoldoutEval | None = None,
    earliest_stop: int = 0,
    device=None,
) -> TrainResult:
    """Fit ``model`` to the training-camera frames of ``observed``.

    Each iteration draws (seeded) one condition from ``conditions`` and one recorded frame
    j < n_train, renders the model at the training camera and steps Adam on
    (1 - w) L1 + w D-SSIM. The first ``warmup`` iterations render the canonical Gaussians only
    (the shared static warm-up).

    With ``holdout`` and ``train.stopping.every`` > 0, the held-out window frames are scored
    every ``every`` iterations (logged in the loss log's ``holdout`` column); with
    ``train.stopping.enabled``, a plateau of that loss ([`physgs.train.stopping`][]) starts the
    schedule's final anneal and the training ends after it, before ``train.iterations``. Without
    ``holdout`` the loop trains ``train.iterations`` (the recipe,
    [`fit`][physgs.experiments.recipe.fit], passes it whenever the rule is on).

    Args:
        model: the model to train (in place).
        observed (Observed): the testbed's observed dataset.
        train_cfg: config ``train`` (iterations, warmup, lr, loss weights, ...).
        conditions: condition indices to draw from.
        seed: seeds the draws of conditions and frames.
        name: the name progress and errors use; None: the model's.
        progress: show a progress bar.
        frame_pool (np.ndarray | None): recorded-frame indices (< n_train) to draw from instead of
            all of them (K selection holds some out).
        on_iteration (Callable | list | None): a hook ``on_iteration(it, model, optimizer) -> dict |
            None``, or a list of them called in order, before each iteration; the dicts they return
            are merged into the statistics (freezing, the search over omega).
        holdout: the held-out window frames' evaluator (None: no scores, no early stop).
        earliest_stop: the stopping rule counts no evaluation before this iteration (the
            recipe's last change to the model: freezing, the end of the search over omega).
        device (str | torch.device | None): where to train: the model (moved there before its
            optimiser is built), its optimiser state, the targets, winds and background; None:
            where the model's parameters are ([`resolve_device`][physgs.device.resolve_device]
            turns ``train.device`` into one). ``holdout`` must be built for the same device.

    Returns:
        The [`TrainResult`][physgs.train.loop.TrainResult]: the model in eval mode, its statistics
            and the per-iteration loss log.

    Raises:
        ValueError: warmup outside [0, iterations), conditions or frame_pool out of range, or
            a stopping rule that cannot run (``train.stopping``).
        TrainingError: the loss turns NaN or inf, the fit diverges (non-finite or exploding
            parameters, Gaussians far outside the scene, a loss far above its warm-up level:
            [`physgs.train.divergence`][]), or the model's forward pass raises (chained); it names
            the model, the iteration and the likely ``train.lr`` setting.
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
            raise ValueError(
                f"frame_pool must hold training-frame indices in [0, "
                f"{observed.n_train}); got {frame_pool.size} frames"
            )
    rule = StopRule.from_config(train_cfg)
    rule.check()
    evaluate = holdout is not None and rule.every > 0
    plateau = Plateau(rule.patience, rule.tol, earliest=max(earliest_stop, warmup, 1))
    anneal_from, end, eval_s = None, iterations, 0.0
    extra: dict = {}
    if on_iteration is None:
        hooks = []
    elif callable(on_iteration):
        hooks = [on_iteration]
    else:
        hooks = list(on_iteration)
    dev = torch.device(device) if device is not None else next(model.parameters()).device
    if dev.type != "cpu":  # the CPU path stays exactly as it was (no copies, same tensors)
        model.to(dev)
    if holdout is not None and holdout.targets.device != dev:
        raise ValueError(
            f"the held-out evaluator's targets are on {holdout.targets.device}, the training on "
            f"{dev}: build it with HoldoutEval.build(..., device={str(dev)!r})"
        )
    rng = np.random.default_rng(seed)
    torch.manual_seed(seed)
    groups = model.param_groups(train_cfg["lr"])
    for g in groups:
        g["base_lr"] = g["lr"]
    # torch's fused Adam kernel (one call per group: about half the per-op step's time), without
    # building a torch.optim optimiser (which imports torch._dynamo: ~1 CPU-s of every job)
    opt = FusedAdam(groups, eps=1e-15)
    lr_cfg = train_cfg["lr"]
    group_of = {id(p): g["name"] for g in groups for p in g["params"]}
    named = [(n, p) for n, p in model.named_parameters() if id(p) in group_of]
    guard = DivergenceGuard.build(
        model.ctx.canonical_xyz, _abs_maxes(named), {n: group_of[id(p)] for n, p in named}, warmup
    )

    # what Adam's rates alone could have moved each group by so far (it moves a parameter by
    # about its rate per step at most): a group grown past that was moved by something else
    moved = {g["name"]: 0.0 for g in groups}

    def likely(suspects) -> str:
        reach = {g: 1.0 + m for g, m in moved.items()}
        return _likely(suspects, lr_cfg, guard.growth(), model.scale_settings(), reach)

    def diverged(it: int, d: Divergence, when: str = "at") -> TrainingError:
        return TrainingError(
            f"model '{name}': training diverged {when} iteration {it}: {d.what}; "
            f"{likely(d.groups)}; "
            "no checkpoint written"
        )

    winds = torch.as_tensor(np.asarray(observed.wind), dtype=torch.float32).to(dev)  # [C, L+F]
    bg = torch.as_tensor(np.asarray(observed.background), dtype=torch.float32).to(dev)  # [3]
    # off the CPU each recorded frame crosses the bus once, as uint8, then stays on the device
    on_device: dict[tuple[int, int], torch.Tensor] = {}
    cam = observed.train_camera
    backend = train_cfg.get("backend", "auto")
    w_ssim = float(train_cfg["ssim_weight"])
    final = float(train_cfg["lr_final_ratio"])
    log: list[dict] = []
    model.train()
    t0 = time.perf_counter()
    bar = tqdm(range(iterations), desc=f"train {name}", disable=not progress, mininterval=2.0)
    for it in bar:
        if it >= end:
            break
        for hook in hooks:
            extra.update(hook(it, model, opt) or {})
        held = None
        # no score before the recipe's last change (the rule would not count it) or where a
        # trigger could no longer stop the run early
        if evaluate and anneal_from is None and rule.scores_at(it, iterations, plateau.earliest):
            te = time.perf_counter()
            held, _ = holdout.evaluate(model)
            eval_s += time.perf_counter() - te
            if plateau.update(it, held) and rule.enabled:
                anneal_from, end = it, it + rule.anneal
        c = int(conditions[rng.integers(len(conditions))])
        j = int(
            rng.integers(observed.n_train)
            if frame_pool is None
            else frame_pool[rng.integers(frame_pool.size)]
        )
        if dev.type == "cpu":
            target = torch.from_numpy(np.array(observed.frames[c, j])).float() / 255.0  # [H, W, 3]
        else:
            if (c, j) not in on_device:
                on_device[c, j] = torch.from_numpy(np.array(observed.frames[c, j])).to(dev)
            target = on_device[c, j].float() / 255.0  # [H, W, 3]
        warm = it < warmup
        # the groups that shape this iteration's Gaussians, most grown first
        shaping = guard.suspects(_STATE_GROUP.values()) if warm else guard.deformation_suspects()
        try:
            s = model.canonical_state() if warm else model.gaussians_at(j, winds[c])
        except Exception as e:  # e.g. integrate: omega ... got min nan
            grown = max(guard.growth().values(), default=1.0)
            note = (
                ""
                if grown > SUSPECT_GROWN
                else f" (no parameter has grown past "
                f"{grown:.2g}x its initial scale: if the rate is not the cause, the error "
                "itself is)"
            )
            raise TrainingError(
                f"model '{name}': its {'canonical state' if warm else 'deformation'} failed at "
                f"iteration {it} (condition {c}, frame {j}) with {type(e).__name__}: {e}; "
                f"{likely(shaping)}{note}; "
                "no checkpoint written"
            ) from e
        bad = [k for k in _STATE_GROUP if not _finite(getattr(s, k))]
        if bad:
            raise diverged(
                it,
                Divergence(
                    f"Gaussian {', '.join(bad)} became NaN or inf",
                    guard.suspects(
                        [_STATE_GROUP[k] for k in bad]
                        if warm
                        else [*shaping, *(_STATE_GROUP[k] for k in bad)]
                    ),
                ),
            )
        d = guard.check_means(s.means.detach().cpu().numpy())
        if d is not None:
            raise diverged(it, d)
        out = render_state(s, cam, bg, backend=backend)
        loss, l1, dssim = photometric_loss(out.rgb, target, w_ssim)
        if not math.isfinite(loss.item()):
            raise diverged(
                it,
                Divergence(
                    f"the loss became {float(loss)} (condition {c}, frame {j}; if no setting below "
                    "explains it, check the dataset for corrupt frames)",
                    shaping,
                ),
            )
        d = guard.check_loss(it, loss.item())
        if d is not None:
            raise diverged(it, d)
        for g in opt.param_groups:
            g["lr"] = g["base_lr"] * lr_factor(
                g["name"], it, iterations, warmup, final, anneal_from, end
            )
            moved[g["name"]] += g["lr"]
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        d = guard.check_params(_abs_maxes(named))
        if d is not None:
            raise diverged(it, d, "in the update of")
        log.append(
            {
                "iteration": it,
                "phase": "warmup" if warm else "deform" if anneal_from is None else "anneal",
                "condition": c,
                "frame": j,
                "loss": loss.item(),
                "l1": l1.item(),
                "dssim": dssim.item(),
                "holdout": "" if held is None else held,
                "seconds": time.perf_counter() - t0,
            }
        )
        if it % 10 == 0:
            bar.set_postfix(loss=f"{loss.item():.4f}")
    wall = time.perf_counter() - t0
    used = len(log)
    d = pinned(model.bounded_positions())
    if d is not None:  # a saturated fit is a failed fit, not a checkpoint to score
        raise TrainingError(
            f"model '{name}': after {used} iterations {d.what}; "
            f"{likely(d.groups)}; "
            "no checkpoint written"
        )
    model.eval()
    tail = [r["loss"] for r in log[-max(1, used // 10) :]]
    stats = {
        "iterations": used,
        "budget": iterations,
        "stopped": STOP_PLATEAU if anneal_from is not None else STOP_CAP,
        "stop_trigger": -1 if anneal_from is None else int(anneal_from),
        "holdout_evals": len(plateau.history),
        "holdout_s": eval_s,
        "warmup": warmup,
        "wall_s": wall,
        "s_per_iter": wall / used,
        "final_loss": float(np.mean(tail)),
        "conditions": list(conditions),
        "seed": int(seed),
        "backend": backend,
        "device": str(dev),
        "n_gaussians": int(model.canonical.n),
        "wind_mean": float(model.ctx.wind_mean),
        "wind_std": float(model.ctx.wind_std),
        "torch_threads": torch.get_num_threads(),
        **extra,
    }
    return TrainResult(model, stats, log)


def _finite(x: torch.Tensor) -> bool:
    # numpy on the CPU: a small torch op can cost milliseconds of OpenMP barrier on a busy machine
    x = x.detach()
    return (
        bool(np.isfinite(x.numpy()).all())
        if x.device.type == "cpu"
        else bool(torch.isfinite(x).all())
    )


def _abs_maxes(named) -> dict[str, float]:
    """Parameter name -> largest |value| (NaN or inf when it holds one)."""
    out = {}
    for n, p in named:
        x = p.detach()
        if x.numel() == 0:
            out[n] = 0.0
        elif x.device.type == "cpu":
            out[n] = float(np.max(np.abs(x.numpy())))
        else:
            out[n] = float(x.abs().max())
    return out


#: A group grown past this multiple of what its rate could reach was moved by something else.
BEYOND_RATE = 2.0


def _likely(groups, lr_cfg: dict, growth=None, scales=None, reach=None) -> str:
    """'likely setting: train.lr.physics (now 1e+06) or train.lr.pivot (now 0.00016); lower it'
    for parameter groups (= train.lr keys), most likely first.

    growth: group -> growth of its parameters (``DivergenceGuard.growth``); scales: group -> the
    other settings that scale what it does (``BaseModel.scale_settings``); reach: group -> the
    growth its rates alone could reach (1 + the sum of its rates so far). The rate is named
    first only when it explains the growth: a group that barely grew (<= SUSPECT_GROWN: a step
    of normal size did the damage) or grew past BEYOND_RATE x its reach (something else set it,
    as the search's hand-over sets the gains from the bank) names its scaling settings first."""
    if not groups:
        return "likely setting: the learning rates in train.lr; lower them"
    growth, scales, reach = growth or {}, scales or {}, reach or {}
    parts = []
    for g in groups:
        rate = f"train.lr.{g}" + (
            f" (now {lr_cfg[g]:g})" if isinstance(lr_cfg.get(g), (int, float)) else ""
        )
        other = [f"{k} (now {v:g})" for k, v in scales.get(g, [])]
        grew = growth.get(g, 0.0)
        by_rate = SUSPECT_GROWN < grew <= BEYOND_RATE * reach.get(g, float("inf"))
        parts += [rate, *other] if by_rate else [*other, rate]
    return "likely setting: " + " or ".join(dict.fromkeys(parts)) + "; lower it"


def write_loss_log(path, log: list[dict]) -> None:
    """Write the loss log as CSV atomically (temporary file, then rename).

    Args:
        path (str | Path): the CSV to write.
        log: one dict per logged iteration, keyed by ``LOG_FIELDS``.
    """
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=LOG_FIELDS)
        w.writeheader()
        w.writerows(log)
