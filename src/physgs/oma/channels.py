"""Channels for output-only modal analysis: dense optical flow of the training video over cells.

The sparse tree's point tracks are short (on the default testbed 2 of 858 last the whole training
window), and SSI-cov needs every channel over the whole record. So the channels are OpenCV's
Farneback dense flow from the window's first frame to every frame (the first frame as the
reference, like the tracker's seed-frame template: the swings are a few degrees, the image
changes little), averaged over the foreground pixels of square cells of the first frame: two
channels (x and y displacement, px) per cell whose foreground share reaches ``min_fg``.
Nothing but the frames and the background colour is read.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physgs.tracks.track import foreground, to_gray


@dataclass(frozen=True)
class FlowSettings:
    """cell_px: cell side (px); min_fg: the fewest foreground share of a cell's pixels in the
    first frame for it to be a channel; fg_tol, fg_dilate_px: the tracker's foreground test
    ([`physgs.tracks.track.foreground`][]); levels, winsize, iterations, poly_n, poly_sigma:
    OpenCV's Farneback settings (pyramid levels, averaging window px, iterations per level,
    polynomial neighbourhood px and its Gaussian sigma). Values and their reasons: docs/blind.md.
    """

    cell_px: int = 8
    min_fg: float = 0.25
    fg_tol: int = 12
    fg_dilate_px: int = 1
    levels: int = 2
    winsize: int = 9
    iterations: int = 3
    poly_n: int = 5
    poly_sigma: float = 1.1


@dataclass(frozen=True)
class Channels:
    """y [T, C] px displacement since the first frame (C = 2 N: x then y of each cell);
    cell_xy [N, 2] px, the cells' centres (OpenCV x, y); channel_cell [C] the cell of each channel.
    """

    y: np.ndarray
    cell_xy: np.ndarray
    channel_cell: np.ndarray

    @property
    def n_cells(self) -> int:
        """The number of cells, N (the channels are 2 N)."""
        return int(self.cell_xy.shape[0])


def flow_channels(
    frames: np.ndarray, background: np.ndarray, s: FlowSettings, reference: np.ndarray | None = None
) -> Channels:
    """Dense-flow channels of one video.

    Args:
        frames: [T, H, W, 3] uint8, the training window of one condition's training camera.
        background: [3] background colour in [0, 1].
        s: the settings.
        reference: a [H, W, 3] uint8 frame whose foreground picks the cells (default
            this video's first frame): the other winds' videos take the training video's, so
            every record has the same channels in the same order.

    Returns:
        ``Channels`` over the cells whose foreground share in frame 0 reaches ``s.min_fg``.
    """
    import cv2  # here: the OMA recovery jobs import this module and never read a video

    gray = to_gray(frames)  # [T, H, W]
    T, H, W = gray.shape
    ref = frames[:1] if reference is None else np.asarray(reference)[None]
    fg0 = foreground(ref, background, s.fg_tol, s.fg_dilate_px)[0]  # [H, W]
    ny, nx = H // s.cell_px, W // s.cell_px
    cells = fg0[: ny * s.cell_px, : nx * s.cell_px].reshape(ny, s.cell_px, nx, s.cell_px)
    share = cells.mean(axis=(1, 3))  # [ny, nx]
    iy, ix = np.nonzero(share >= s.min_fg)
    if iy.size == 0:
        raise ValueError(f"oma/flow/min_fg = {s.min_fg}: no cell of the first frame qualifies")
    y = np.zeros((T, 2 * iy.size), np.float64)
    for t in range(1, T):
        flow = cv2.calcOpticalFlowFarneback(
            gray[0],
            gray[t],
            None,
            0.5,
            s.levels,
            s.winsize,
            s.iterations,
            s.poly_n,
            s.poly_sigma,
            0,
        )  # [H, W, 2] px
        f = np.where(fg0[..., None], flow, 0.0)[: ny * s.cell_px, : nx * s.cell_px]
        f = f.reshape(ny, s.cell_px, nx, s.cell_px, 2).sum(axis=(1, 3))  # [ny, nx, 2]
        n = cells.sum(axis=(1, 3))[iy, ix]  # [N] foreground pixels per cell
        y[t] = (f[iy, ix] / n[:, None]).T.reshape(-1)  # x of every cell, then y
    xy = np.stack([(ix + 0.5) * s.cell_px, (iy + 0.5) * s.cell_px], axis=1).astype(np.float64)
    return Channels(y, xy, np.tile(np.arange(iy.size), 2))


def principal_channels(y: np.ndarray, n_components: int) -> tuple[np.ndarray, np.ndarray]:
    """The record's leading principal components, the channels SSI-cov reads.

    Neighbouring cells move together and the flow of thin branches is noisy, so the C cell
    channels carry few independent motions (on the default sparse testbed the first 12
    components hold 98% of the variance): SSI on the components is faster and steadier, and a
    mode's shape over the cells is its component shape mapped back through the loadings.

    Args:
        y: [T, C] channels.
        n_components: how many to keep (at most min(T, C)).

    Returns:
        (z [T, n] component series, loadings [n, C]; a shape phi over the components is
            ``phi @ loadings`` over the cells' channels).
    """
    y = np.asarray(y, np.float64)
    if not 1 <= n_components <= min(y.shape):
        raise ValueError(
            f"oma/flow/components = {n_components} must be in [1, min(T, C) = {min(y.shape)}]"
        )
    yc = y - y.mean(axis=0)
    _, _, vt = np.linalg.svd(yc, full_matrices=False)
    load = vt[:n_components]  # [n, C]
    return yc @ load.T, load
