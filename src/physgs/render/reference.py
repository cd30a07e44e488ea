"""Reference compositing: pure PyTorch under autograd, float32 or float64.

Simple on purpose (tests and fallback): for each 16x16 tile, every Gaussian whose conservative
pixel box touches the tile is evaluated at every pixel of the tile as a dense [P, n] matrix, sorted
front to back by depth, and composited with cumulative products. Python loops run over tiles only.
"""

from __future__ import annotations

import numpy as np
import torch

from physgs.render.constants import ALPHA_MAX, ALPHA_MIN, T_MIN, TILE
from physgs.render.project import pixel_bounds


def composite_reference(
    means2d: torch.Tensor,
    conics: torch.Tensor,
    opacities: torch.Tensor,
    colors: torch.Tensor,
    depths: torch.Tensor,
    valid: torch.Tensor,
    cov2d: torch.Tensor,
    background: torch.Tensor,
    width: int,
    height: int,
    return_depth: bool = True,
):
    """Alpha-composite projected Gaussians front to back, tile by tile, under autograd.

    Differentiable w.r.t. means2d, conics, opacities, colors, depths and background.

    Args:
        means2d: [N, 2] centres, px (pixel centres at integer + 0.5).
        conics: [N, 3] (a, b, c) of the inverse 2D covariance, 1/px^2.
        opacities: [N] in [0, 1].
        colors: [N, D] in [0, 1].
        depths: [N] camera z, world units.
        valid: [N] bool, the projection's mask.
        cov2d: [N, 3] 2D covariances (xx, xy, yy), px^2 (binning only).
        background: [D] in [0, 1].
        width: image width W, px.
        height: image height H, px.
        return_depth: whether to compute the expected depth.

    Returns:
        (tuple[torch.Tensor, ...]): (rgb [H, W, D], alpha [H, W], depth [H, W] world units or
            None), the inputs' dtype.
    """
    D = colors.shape[1]
    boxes = pixel_bounds(
        means2d.detach().cpu().numpy(),
        cov2d.cpu().numpy(),
        opacities.detach().cpu().numpy(),
        valid.cpu().numpy(),
        width,
        height,
    )
    touches = boxes[:, 0] <= boxes[:, 1]
    dep = depths.detach().cpu().numpy()
    order = np.argsort(np.where(touches, dep, np.inf), kind="stable")[: int(touches.sum())]
    b = boxes[order]
    rgb_parts, a_parts, d_parts, pix_parts = [], [], [], []
    for ty0 in range(0, height, TILE):
        for tx0 in range(0, width, TILE):
            ty1, tx1 = min(ty0 + TILE, height) - 1, min(tx0 + TILE, width) - 1
            hit = (b[:, 0] <= tx1) & (b[:, 1] >= tx0) & (b[:, 2] <= ty1) & (b[:, 3] >= ty0)
            idx = torch.as_tensor(order[hit], device=means2d.device)  # depth-sorted candidates
            yy, xx = torch.meshgrid(
                torch.arange(ty0, ty1 + 1), torch.arange(tx0, tx1 + 1), indexing="ij"
            )
            pix_parts.append((yy * width + xx).reshape(-1))
            px = torch.stack([xx, yy], -1).reshape(-1, 2).to(means2d) + 0.5  # [P, 2] centres
            d = px[:, None, :] - means2d[idx][None, :, :]  # [P, n, 2]
            cn = conics[idx]
            sigma = (
                cn[:, 0] * d[..., 0] ** 2
                + 2 * cn[:, 1] * d[..., 0] * d[..., 1]
                + cn[:, 2] * d[..., 1] ** 2
            )  # [P, n]
            alpha = torch.clamp(opacities[idx] * torch.exp(-0.5 * sigma), max=ALPHA_MAX)
            alpha = torch.where(alpha >= ALPHA_MIN, alpha, torch.zeros_like(alpha))
            # Stop before the Gaussian that would take transmittance below T_MIN (and after it).
            keep = torch.cumprod(1 - alpha.detach(), dim=1) >= T_MIN
            alpha = alpha * keep
            trans = torch.cumprod(1 - alpha, dim=1)  # [P, n] transmittance after each Gaussian
            t_final = trans[:, -1] if trans.shape[1] else torch.ones_like(px[:, 0])
            T = torch.cat([torch.ones_like(px[:, :1]), trans[:, :-1]], dim=1)  # before each
            w = alpha * T  # [P, n]
            rgb_parts.append(w @ colors[idx] + t_final[:, None] * background)
            a_parts.append(1 - t_final)
            if return_depth:
                d_parts.append(w @ depths[idx])
    pix = torch.cat(pix_parts).to(means2d.device)
    n_pix = height * width
    rgb = (
        torch.zeros(n_pix, D, dtype=colors.dtype, device=colors.device)
        .index_copy(0, pix, torch.cat(rgb_parts))
        .reshape(height, width, D)
    )
    alpha = (
        torch.zeros(n_pix, dtype=colors.dtype, device=colors.device)
        .index_copy(0, pix, torch.cat(a_parts))
        .reshape(height, width)
    )
    depth = None
    if return_depth:
        depth = (
            torch.zeros(n_pix, dtype=colors.dtype, device=colors.device)
            .index_copy(0, pix, torch.cat(d_parts))
            .reshape(height, width)
        )
    return rgb, alpha, depth
