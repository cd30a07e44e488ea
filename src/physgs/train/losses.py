"""Photometric loss of 3DGS: (1 - w) L1 + w (1 - SSIM)."""

from __future__ import annotations

import torch
import torch.nn.functional as F


def _gauss_window(size: int, sigma: float, dtype) -> torch.Tensor:
    x = torch.arange(size, dtype=dtype) - (size - 1) / 2
    g = torch.exp(-(x**2) / (2 * sigma**2))
    g = g / g.sum()
    return g[:, None] * g[None, :]  # [size, size]


def ssim(a: torch.Tensor, b: torch.Tensor, window: int = 11, sigma: float = 1.5) -> torch.Tensor:
    """Mean SSIM of images a, b [H, W, C] in [0, 1] (Gaussian 11x11 window, sigma 1.5, zero
    padding: the 3DGS implementation)."""
    if a.shape != b.shape or a.ndim != 3:
        raise ValueError(
            f"ssim: images must share shape [H, W, C]; got {tuple(a.shape)}, {tuple(b.shape)}"
        )
    c = a.shape[-1]
    x = a.permute(2, 0, 1)[None]  # [1, C, H, W]
    y = b.permute(2, 0, 1)[None]
    w = _gauss_window(window, sigma, a.dtype).expand(c, 1, window, window)
    pad = window // 2

    def blur(z):
        return F.conv2d(z, w, padding=pad, groups=c)

    mx, my = blur(x), blur(y)
    sxx = blur(x * x) - mx * mx
    syy = blur(y * y) - my * my
    sxy = blur(x * y) - mx * my
    c1, c2 = 0.01**2, 0.03**2
    m = ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    return m.mean()


def photometric_loss(render: torch.Tensor, target: torch.Tensor, ssim_weight: float = 0.2):
    """(loss, l1, dssim) for images [H, W, 3] in [0, 1]; loss = (1-w) L1 + w (1 - SSIM)."""
    l1 = (render - target).abs().mean()
    dssim = 1.0 - ssim(render, target)
    return (1.0 - ssim_weight) * l1 + ssim_weight * dssim, l1, dssim
