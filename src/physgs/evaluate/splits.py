"""Evaluation splits (the protocol, section 4): view, time, transfer, plus per-frame curves.

The evaluation never sees a model class: it calls a render callback
``render_fn(frame_idx, condition, camera) -> (rgb [H, W, 3] float in [0, 1], alpha [H, W])``
where ``frame_idx`` is the 0-based recorded frame (t = frame_idx / fps seconds) and
``condition`` indexes ``observed.conditions`` (0 = training wind).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Callable

import numpy as np

from physgs.atomic import save_npz
from physgs.evaluate.metrics import centroid_error, psnr, to_float_image
from physgs.intermediate import read_npz
from physgs.models.undefined import NotDefined


RenderFn = Callable[[int, int, object], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class EvalResult:
    """Per-frame scores of one model on one tree. PSNR in dB, centroid errors in pixels.

    camera_psnr [C, F]: training camera, every condition, all F = n_train + n_tail frames.
    centroid_err [C, F]: canopy-centroid error at the training camera, same frames.
    view_psnr [A, M]: held-out azimuths x held-out frames (training wind, inside the window).
    """

    camera_psnr: np.ndarray  # [C, F]
    centroid_err: np.ndarray  # [C, F]
    view_psnr: np.ndarray  # [A, M]
    conditions: np.ndarray  # [C] mean-speed multipliers, 0 = training wind
    heldout_azimuths_deg: np.ndarray  # [A]
    heldout_frame_idx: np.ndarray  # [M]
    n_train: int
    n_tail: int

    # --- derived per-frame splits -------------------------------------------------------
    @property
    def temporal_psnr(self) -> np.ndarray:
        """[F] per-frame PSNR at the training camera and wind (fig_temporal)."""
        return self.camera_psnr[0]

    @property
    def time_psnr(self) -> np.ndarray:
        """[n_tail] the time split: tail frames, training camera and wind."""
        return self.camera_psnr[0, self.n_train :]

    @property
    def train_timestamps_psnr(self) -> np.ndarray:
        """[C, n_train] training camera, frames 1-300 of each condition (0 = in-sample fit)."""
        return self.camera_psnr[:, : self.n_train]

    @property
    def beyond_window_psnr(self) -> np.ndarray:
        """[C, n_tail] training camera, frames 301-350 of each condition."""
        return self.camera_psnr[:, self.n_train :]

    # --- split means (what the tables show) ---------------------------------------------
    def summary(self) -> dict[str, float]:
        """Mean PSNR per split (dB): view, time, and train/beyond for every condition c as
        ``train_c{c}`` / ``beyond_c{c}``; mean centroid errors as ``centroid_c{c}`` (px).

        Returns:
            Split name -> mean.
        """
        out = {"view": float(self.view_psnr.mean()), "time": float(self.time_psnr.mean())}
        for c in range(len(self.conditions)):
            out[f"train_c{c}"] = float(self.train_timestamps_psnr[c].mean())
            out[f"beyond_c{c}"] = float(self.beyond_window_psnr[c].mean())
            out[f"centroid_c{c}"] = float(self.centroid_err[c].mean())
        return out

    def save(self, path) -> None:
        """Write as .npz atomically.

        Args:
            path (str | Path): the ``.npz`` to write.
        """
        save_npz(path, **{f.name: np.asarray(getattr(self, f.name)) for f in fields(self)})


def load_eval(path) -> EvalResult:
    """Read the scores that ``EvalResult.save`` wrote.

    Args:
        path (str | os.PathLike): the ``.npz`` file.

    Returns:
        The [`EvalResult`][physgs.evaluate.splits.EvalResult].

    Raises:
        IntermediateFileError: the file is missing or not an evaluation (rule ``evaluate``).
    """
    d = read_npz(path, [f.name for f in fields(EvalResult)], rule="evaluate")
    d["n_train"], d["n_tail"] = int(d["n_train"]), int(d["n_tail"])
    return EvalResult(**d)


def _render(render_fn: RenderFn, frame: int, cond: int, camera, shape: tuple[int, int]):
    rgb, alpha = render_fn(int(frame), int(cond), camera)
    rgb, alpha = np.asarray(rgb), np.asarray(alpha, dtype=np.float64)
    if rgb.shape != (*shape, 3) or alpha.shape != shape:
        raise ValueError(
            f"render_fn returned rgb {rgb.shape}, alpha {alpha.shape} for frame {frame}, "
            f"condition {cond}; expected {(*shape, 3)} and {shape} (the camera's size)"
        )
    return to_float_image(rgb), alpha


def evaluate(
    render_fn: RenderFn, observed, *, progress: Callable[[str], None] | None = None
) -> EvalResult:
    """Score a model through its render callback on every split.

    Renders C x F frames at the training camera (every condition, window and tail) and A x M
    held-out views (training condition). A frame the callback refuses with
    [`NotDefined`][physgs.models.undefined.NotDefined] (a learned forcing beyond its window or under
    another wind) scores NaN: its split means are NaN, "not defined", never a number.

    Args:
        render_fn: ``render_fn(frame, condition, camera) -> (rgb [H, W, 3] uint8 or float in
            [0, 1], alpha [H, W] in [0, 1])`` at recorded frame ``frame`` of ``condition``.
        observed (Observed): the testbed's observed dataset.
        progress: called with a line of progress, or None.

    Returns:
        Per-frame PSNR (dB) and centroid errors (px); means per split come from
            ``EvalResult.summary()``.

    Raises:
        ValueError: the callback returns images of another size than the camera's.
    """
    frames = observed.frames  # [C, F, H, W, 3] uint8
    C, F, H, W, _ = frames.shape
    if F != observed.n_train + observed.n_tail:
        raise ValueError(
            f"observed has {F} frames but n_train + n_tail = "
            f"{observed.n_train + observed.n_tail}; the dataset is inconsistent"
        )
    cam_psnr = np.empty((C, F))
    cen = np.empty((C, F))
    # frame-major order, so a render_fn that caches its last deformed frame deforms each once
    for j in range(F):
        if progress and j % 50 == 0:
            progress(f"training camera, frame {j + 1}/{F}, {C} conditions")
        for c in range(C):
            try:
                rgb, alpha = _render(render_fn, j, c, observed.train_camera, (H, W))
            except NotDefined:  # no prediction there: "not defined", never a score
                cam_psnr[c, j] = cen[c, j] = np.nan
                continue
            cam_psnr[c, j] = psnr(rgb, frames[c, j])
            cen[c, j] = centroid_error(alpha, observed.masks[c, j])
    return EvalResult(
        cam_psnr,
        cen,
        view_psnr(render_fn, observed, progress=progress),
        np.asarray(observed.conditions, dtype=np.float64),
        np.asarray(observed.heldout_azimuths_deg, dtype=np.float64),
        np.asarray(observed.heldout_frame_idx, dtype=np.int64),
        int(observed.n_train),
        int(observed.n_tail),
    )


def view_psnr(
    render_fn: RenderFn, observed, *, progress: Callable[[str], None] | None = None
) -> np.ndarray:
    """The view split: PSNR (dB) [A, M] of the held-out azimuths x held-out frames (training
    condition, inside the window) of ``observed``, through the render callback.

    Args:
        render_fn: the model's render callback.
        observed (Observed): the dataset.
        progress: receives a progress line.

    Returns:
        [A, M] PSNR, dB.

    Raises:
        NotDefined: from the callback, where the model makes no prediction (not caught here).
        ValueError: when a render's size is not the held-out frames'.
    """
    A, M = len(observed.heldout_cameras), len(observed.heldout_frame_idx)
    view = np.empty((A, M))
    if progress:
        progress(f"held-out views: {A} azimuths x {M} frames")
    for m, j in enumerate(observed.heldout_frame_idx):
        for a, cam in enumerate(observed.heldout_cameras):
            rgb, _ = _render(render_fn, j, 0, cam, observed.heldout_frames.shape[2:4])
            view[a, m] = psnr(rgb, observed.heldout_frames[a, m])
    return view
