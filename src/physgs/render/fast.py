"""Fast CPU rasterizer: fused numba projection + tile compositing behind one torch.autograd.Function
with an explicit backward (kernels in [`physgs.render.kernels`][physgs.render.kernels]).

Everything between the input tensors and the output images runs in numba or vectorised numpy:
no Python loop over Gaussians and no small torch ops (whose OpenMP barriers cost more than the
arithmetic on a busy 2-core machine).
"""

from __future__ import annotations

import numpy as np
import torch

from physgs.camera import Camera
from physgs.numpy_bridge import float64_array, tensor_like
from physgs.render import kernels
from physgs.render.constants import EPS2D, TILE
from physgs.render.project import fov_clamp_limits


def camera_arrays(camera: Camera):
    """The camera as the kernels read it, float64 numpy.

    Args:
        camera: the pinhole camera.

    Returns:
        (tuple[np.ndarray, ...]): (Rc, tc, intr, lims), float64: Rc [3, 3] and tc [3] (world
            units) the world-to-camera rotation and translation; intr [4] (fx, fy, cx, cy) px;
            lims [4] gsplat's tangent clamps (x-, x+, y-, y+) of the projection Jacobian from
            [`fov_clamp_limits`][physgs.render.project.fov_clamp_limits] (the reference path uses
            the same).
    """
    intr = np.array([camera.fx, camera.fy, camera.cx, camera.cy], dtype=np.float64)
    lims = np.array(fov_clamp_limits(camera), dtype=np.float64)
    return (
        np.ascontiguousarray(camera.R, dtype=np.float64),
        np.ascontiguousarray(camera.t, dtype=np.float64),
        intr,
        lims,
    )


def _forward(means, quats, scales, opacities, colors, background, camera, with_depth=True):
    """Project, bin and composite: ((rgb [H, W, D], alpha [H, W], depth [H, W]) float64 numpy,
    state) where state holds what the backward needs (float64 inputs, projection, tile lists,
    per-pixel totals); a forward-only caller drops it. Without depth the depth image is zeros
    and the backward takes no depth gradient."""
    m, q, s, o, col, bg = (
        float64_array(x) for x in (means, quats, scales, opacities, colors, background)
    )
    n, D = col.shape
    W, H = camera.width, camera.height
    cam = camera_arrays(camera)
    m2 = np.empty((n, 2))
    con = np.empty((n, 3))
    dep = np.empty(n)
    cov = np.empty((n, 3))
    valid = np.empty(n, np.bool_)
    kernels.project_forward(m, q, s, *cam, camera.near, EPS2D, m2, con, dep, cov, valid)
    boxes = np.empty((n, 4), np.int64)
    kernels.pixel_boxes(m2, cov, o, valid, W, H, boxes)
    touches = boxes[:, 0] <= boxes[:, 1]
    order = np.argsort(np.where(touches, dep, np.inf), kind="stable")[: int(touches.sum())]
    tiles_x = (W + TILE - 1) // TILE
    tiles_y = (H + TILE - 1) // TILE
    tile_start, pair_gid, row_start = kernels.bin_tiles(
        boxes, order.astype(np.int64), TILE, tiles_x, tiles_y
    )
    rgb = np.empty((H, W, D))
    alpha = np.empty((H, W))
    depth = np.empty((H, W))
    acc_c = np.empty((H, W, D))
    acc_d = np.empty((H, W))
    t_final = np.empty((H, W))
    n_contrib = np.empty((H, W), np.int64)
    # the rows each (tile, Gaussian) pair composited, for the backward (bin_tiles' capacity)
    rows = (
        np.empty((row_start[-1], 3), np.int32),
        np.empty((row_start[-1], 2)),
        np.zeros(pair_gid.shape[0], np.int64),
    )
    comp = (
        *(m2, con, o, col, dep, bg, boxes, tile_start, pair_gid, row_start),
        *(TILE, tiles_x, W, H, bool(with_depth)),
    )
    kernels.forward(*comp, rgb, alpha, depth, acc_c, acc_d, t_final, n_contrib, *rows)
    return (rgb, alpha, depth), (
        m,
        q,
        s,
        cam,
        camera.near,
        valid,
        comp,
        acc_c,
        acc_d,
        t_final,
        rows,
        n_contrib,
    )


class _FastRasterize(torch.autograd.Function):
    @staticmethod
    def forward(ctx, means, quats, scales, opacities, colors, background, camera, with_depth):
        images, ctx.saved = _forward(
            means, quats, scales, opacities, colors, background, camera, with_depth
        )
        ctx.like = torch.empty(0, dtype=means.dtype, device=means.device)
        return tuple(tensor_like(x, means) for x in images)

    @staticmethod
    def backward(ctx, g_rgb, g_alpha, g_depth):
        m, q, s, cam, near, valid, comp, acc_c, acc_d, t_final, rows, _ = ctx.saved
        H, W = t_final.shape
        D = comp[3].shape[1]
        n = m.shape[0]

        def up(g, shape):  # upstream gradient as float64 numpy; None means zero
            if g is None:
                return np.zeros(shape)
            return np.ascontiguousarray(g.detach().cpu().numpy(), dtype=np.float64)

        g_rgb = up(g_rgb, (H, W, D))
        g_alpha = up(g_alpha, (H, W))
        g_depth = up(g_depth, (H, W))
        pair_gid = comp[8]
        pair_grad = np.zeros((pair_gid.shape[0], kernels.N_GRAD + D))
        kernels.backward(*comp, acc_c, acc_d, t_final, *rows, g_rgb, g_alpha, g_depth, pair_grad)
        G = kernels.reduce_pairs(pair_gid, pair_grad, n)  # [N, 7 + D]
        v_means = np.empty((n, 3))
        v_quats = np.empty((n, 4))
        v_scales = np.empty((n, 3))
        kernels.project_backward(
            m,
            q,
            s,
            *cam,
            near,
            EPS2D,
            valid,
            np.ascontiguousarray(G[:, 0:2]),
            np.ascontiguousarray(G[:, 2:5]),
            np.ascontiguousarray(G[:, 6]),
            v_means,
            v_quats,
            v_scales,
        )
        g_bg = np.einsum("hwd,hw->d", g_rgb, t_final)
        out = (v_means, v_quats, v_scales, G[:, 5], G[:, kernels.N_GRAD :], g_bg)
        return tuple(tensor_like(x, ctx.like) for x in out) + (None, None)


def work_count(means, quats, scales, opacities, colors, camera, background) -> dict[str, int]:
    """How much compositing one forward + backward of the fast rasterizer does.

    Runs one forward of [`rasterize_fast`][physgs.render.fast.rasterize_fast] (no gradient) and
    counts what it did.

    Args:
        means (torch.Tensor): [N, 3] world units.
        quats (torch.Tensor): [N, 4] (w, x, y, z).
        scales (torch.Tensor): [N, 3] world units.
        opacities (torch.Tensor): [N] in [0, 1].
        colors (torch.Tensor): [N, D] in [0, 1].
        camera (Camera): the camera.
        background (torch.Tensor): [D] in [0, 1].

    Returns:
        The counts by name, ints. ``pairs``, pixel-Gaussian pairs composited before transmittance
            saturates (each costs ``kernels.FLOPS_PER_PAIR`` flops, forward + backward);
            ``footprint_pixels``, pixels inside the 1/255 contours of the tile pairs reached (pairs
            plus the ones skipped after saturation); ``rows``, pixel rows of those footprints (the
            forward finds each one's span and two exps); ``tile_pairs``, (tile, Gaussian) pairs
            binned; ``gaussians``, N.
    """
    with torch.no_grad():
        _, state = _forward(means, quats, scales, opacities, colors, background, camera)
    row_start = state[6][9]  # [P + 1] each pair's row capacity; its first n_rows are written
    row_pix, _, n_rows = state[10]
    slot = np.arange(row_pix.shape[0])
    pair = np.searchsorted(row_start, slot, side="right") - 1
    used = slot - row_start[pair] < n_rows[pair]
    n_contrib = state[11]
    return {
        "pairs": int(n_contrib.sum()),
        "footprint_pixels": int((row_pix[used, 2] - row_pix[used, 1] + 1).sum()),
        "rows": int(n_rows.sum()),
        "tile_pairs": int(n_rows.shape[0]),
        "gaussians": int(means.shape[0]),
    }


def rasterize_fast(
    means: torch.Tensor,
    quats: torch.Tensor,
    scales: torch.Tensor,
    opacities: torch.Tensor,
    colors: torch.Tensor,
    camera: Camera,
    background: torch.Tensor,
    return_depth: bool = True,
):
    """Fast CPU backend of [`rasterization`][physgs.render.rasterization] (same shapes and units).

    Tensors on another device are copied to the CPU and back. Arithmetic is float64 inside the
    kernels for any input dtype. Forward only (no autograd node, no state kept for a backward) when
    autograd is off (torch.no_grad, inference_mode) or no input requires a gradient, as in
    evaluation.

    Args:
        means: [N, 3] centres, world units.
        quats: [N, 4] (w, x, y, z), any norm.
        scales: [N, 3] world units, activated.
        opacities: [N] in [0, 1].
        colors: [N, D] in [0, 1].
        camera: the camera (the image is camera.height x camera.width px).
        background: [D] in [0, 1].
        return_depth: whether to return the expected depth.

    Returns:
        (tuple[torch.Tensor, ...]): (rgb [H, W, D], alpha [H, W], depth [H, W] world units or
            None), on the device and dtype of ``means``.
    """
    inputs = (means, quats, scales, opacities, colors, background)
    if torch.is_grad_enabled() and any(x.requires_grad for x in inputs):
        # without depth, its terms are skipped (the same numbers: its gradient would be zero)
        rgb, alpha, depth = _FastRasterize.apply(*inputs, camera, return_depth)
    else:
        images, _ = _forward(*inputs, camera, return_depth)
        rgb, alpha, depth = (tensor_like(x, means) for x in images)
    return rgb, alpha, (depth if return_depth else None)
