"""Evaluate one trained checkpoint end to end: splits, tip trajectories and qualitative panels.

This is what the Snakemake rule `evaluate` calls; it only joins the pieces of
[`physgs.evaluate`][] (scores through the render callback, never through a model class).
"""

from __future__ import annotations

import numpy as np

from physgs.evaluate.adapter import model_means_fn, model_render_fn
from physgs.atomic import save_npz
from physgs.evaluate.metrics import psnr
from physgs.evaluate.splits import NotDefined, evaluate
from physgs.evaluate.trajectories import tip_trajectories


def panel_choice(observed) -> dict[str, tuple[int, int, int]]:
    """The qualitative panels of fig_results: split -> (frame_idx, condition, camera index).

    Fixed choices so every model shows the same frame: the middle of the tail (unseen time), the
    held-out azimuth nearest +30 degrees in the middle of the window (unseen view), and the
    weakest unseen wind in the middle of the tail (unseen wind, where replay cannot help).

    Args:
        observed (Observed): the dataset.

    Returns:
        ``time``, ``view`` and ``wind`` -> ``(frame_idx, condition, camera)``; camera -1 is the
            training camera, otherwise a held-out azimuth's index.
    """
    mid_tail = int(observed.n_train + observed.n_tail // 2)
    az = np.asarray(observed.heldout_azimuths_deg, dtype=np.float64)
    a = int(np.argmin(np.abs(az - 30.0)))
    m = len(observed.heldout_frame_idx) // 2
    return {
        "time": (mid_tail, 0, -1),
        "view": (int(observed.heldout_frame_idx[m]), 0, a),
        "wind": (mid_tail, len(observed.conditions) - 1, -1),
    }


def render_panels(render_fn, observed) -> dict[str, np.ndarray]:
    """Renders and ground truth of the fig_results panels; arrays keyed '<split>_pred/_gt/_psnr'.

    Args:
        render_fn (RenderFn): the model's render callback.
        observed (Observed): the dataset.

    Returns:
        Per split ``<split>_pred`` and ``<split>_gt`` [H, W, 3] uint8 and ``<split>_psnr`` (dB, a
            0-d array; NaN with a blank render where the model makes no prediction).
    """
    out = {}
    for split, (j, c, a) in panel_choice(observed).items():
        if a < 0:
            cam, gt = observed.train_camera, observed.frames[c, j]
        else:
            m = int(np.flatnonzero(np.asarray(observed.heldout_frame_idx) == j)[0])
            cam, gt = observed.heldout_cameras[a], observed.heldout_frames[a, m]
        try:
            rgb, _ = render_fn(j, c, cam)
        except NotDefined:  # a blank panel and a NaN score: "not defined"
            out[f"{split}_pred"] = np.zeros(np.asarray(gt).shape, np.uint8)
            out[f"{split}_gt"] = np.asarray(gt)
            out[f"{split}_psnr"] = np.asarray(float("nan"))
            continue
        out[f"{split}_pred"] = (np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8)
        out[f"{split}_gt"] = np.asarray(gt)
        out[f"{split}_psnr"] = np.asarray(float(psnr(rgb, gt)))
    return out


def training_camera_scores(
    model, observed, frames, *, condition: int = 0, backend: str = "auto"
) -> tuple[np.ndarray, np.ndarray]:
    """(MSE [M], PSNR dB [M]) of ``model`` at the training camera, per recorded frame in
    ``frames`` [M] of ``condition``, through the same render callback as the evaluation.

    Args:
        model (BaseModel): the trained model.
        observed (Observed): the dataset.
        frames (ArrayLike): [M] recorded-frame indices.
        condition: the wind condition's index.
        backend: the rasterizer backend.

    Returns:
        ``(mse [M], psnr [M])``: MSE of images in [0, 1], PSNR in dB.
    """
    render_fn = model_render_fn(model, observed, backend=backend)
    mse, score = [], []
    for j in np.asarray(frames, dtype=np.int64):
        rgb, _ = render_fn(int(j), condition, observed.train_camera)
        gt = np.asarray(observed.frames[condition, j], dtype=np.float64) / 255.0
        mse.append(float(np.mean((rgb - gt) ** 2)))
        score.append(float(psnr(rgb, observed.frames[condition, j])))
    return np.asarray(mse), np.asarray(score)


def undefined_splits(model, observed) -> set[str]:
    """The summary keys (``EvalResult.summary``) holding a frame the model does not predict
    (``model.defined``): a learned forcing has none beyond its window or under another wind.

    Args:
        model (BaseModel): the trained model.
        observed (Observed): the dataset.

    Returns:
        Keys among ``time``, ``view``, ``train_c{c}``, ``beyond_c{c}``, ``centroid_c{c}``.
    """
    n, C = int(observed.n_train), len(observed.conditions)
    out = set()
    if not model.defined(n, 0):
        out.add("time")
    if not all(model.defined(int(j), 0) for j in observed.heldout_frame_idx):
        out.add("view")
    for c in range(C):
        train = all(model.defined(j, c) for j in (0, n - 1))
        beyond = model.defined(n, c)
        out |= {f"train_c{c}"} if not train else set()
        out |= {f"beyond_c{c}"} if not beyond else set()
        out |= {f"centroid_c{c}"} if not (train and beyond) else set()
    return out


def evaluate_checkpoint(
    model,
    observed,
    truth,
    *,
    eval_path,
    traj_path,
    panels_path,
    backend: str = "auto",
    progress=None,
    device=None,
) -> dict[str, float]:
    """Score ``model`` on every split and write three files atomically.

    Args:
        model (BaseModel): the trained model.
        observed (Observed): the dataset.
        truth (Truth): its ground truth (for the tip trajectories).
        eval_path (str | Path): [`EvalResult`][physgs.evaluate.splits.EvalResult] npz (per-frame
            PSNR in dB, centroid errors in pixels).
        traj_path (str | Path): branch-tip trajectories (pixels) at the training wind.
        panels_path (str | Path): the qualitative renders.
        backend: the rasterizer backend.
        progress (Callable[[str], None] | None): receives progress lines.
        device (str | torch.device | None): where to deform and render (the model is moved
            there); None: where it is.

    Returns:
        The split means ([`EvalResult.summary`][physgs.evaluate.splits.EvalResult.summary]).

    Raises:
        FloatingPointError: when a split the model predicts scores non-finite (a corrupt
            checkpoint); nothing is written then.
    """
    if device is not None:
        model = model.to(device)
    seen: dict = {}  # the evaluation's deformations under the training wind, for the tips
    render_fn = model_render_fn(model, observed, backend=backend, means_seen=seen)
    res = evaluate(render_fn, observed, progress=progress)
    traj = tip_trajectories(model_means_fn(model, observed, seen), truth, observed, condition=0)
    panels = render_panels(render_fn, observed)
    summary = res.summary()
    undefined = undefined_splits(model, observed)  # NaN there is "not defined", not corruption
    bad = [k for k, v in summary.items() if not np.isfinite(v) and k not in undefined]
    if bad:
        raise FloatingPointError(
            f"evaluation produced non-finite scores for {bad}; "
            "the checkpoint is likely corrupt: to retrain it and remake what is made from it, "
            "rerun this command with `--forcerun <the checkpoint's path>` added"
        )
    res.save(eval_path)
    traj.save(traj_path)
    save_npz(panels_path, **panels)
    return summary
