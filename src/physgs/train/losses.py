"""Photometric loss of 3DGS: (1 - w) L1 + w (1 - SSIM)."""

from __future__ import annotations

import functools

import torch
import torch.nn.functional as F

from physgs.train.fused_loss import SSIM_C1, SSIM_C2, fused_photometric_loss, gauss_window

#: Image side (pixels) from which SSIM's blur runs in block-Toeplitz tiles rather than as one
#: banded [n, n] matmul per side: the banded matmul does O(n) work per output pixel, the tiles
#: O(TILE + window). Measured (benchmarks/passes.py blur) forward + backward of the 15 blurred maps,
#: one thread (banded / tiles of 32): 128 px 4.1 / 5.8 ms, 256 px 25 / 23 ms, 384 px 80 / 54 ms,
#: 512 px 180 / 106 ms. Below this side the banded matmul is kept. (The torch path's blur: a
#: training on the CPU takes the fused pass of physgs.train.fused_loss, 30 ms at 512 px.)
TILED_BLUR_MIN_SIDE = 320
#: Output rows per tile of the tiled blur.
BLUR_TILE = 32


def _gauss_1d(size: int, sigma: float, dtype) -> torch.Tensor:
    """Normalised 1D Gaussian window [size] (sums to 1); the 2D window is its outer product (the
    fused pass's window, one definition)."""
    return torch.tensor(gauss_window(size, sigma), dtype=dtype)  # a copy: the window is read-only


@functools.lru_cache(maxsize=16)
def _blur_matrix(n: int, size: int, sigma: float, dtype, device) -> torch.Tensor:
    """[n, n] banded matrix B with (B z)[i] = sum_k g[k] z[i + k - size // 2], z zero outside
    [0, n): a zero-padded 1D Gaussian blur as a matrix (cached per size, dtype and device).

    The 2D window is separable, so blurring an image [H, W] is B_H z B_W^T: the same sums as
    the zero-padded 2D convolution, reassociated. Two small matmuls run ~15x faster on the CPU
    than a grouped 11x11 conv2d (which dominated a training iteration), and no less accurately.
    """
    g = _gauss_1d(size, sigma, torch.float64)
    i = torch.arange(n)
    off = i[None, :] - i[:, None] + size // 2  # column j of row i takes g[j - i + size // 2]
    inside = (off >= 0) & (off < size)
    B = torch.where(inside, g[off.clamp(0, size - 1)], torch.zeros((), dtype=torch.float64))
    return B.to(dtype=dtype, device=device)


@functools.lru_cache(maxsize=16)
def _tile_matrix(tile: int, size: int, sigma: float, dtype, device) -> torch.Tensor:
    """[tile, tile + size - 1] Toeplitz block T with T[i, j] = g[j - i]: output row i of a tile
    from the tile's rows padded by size // 2 on each side (cached per size, dtype, device)."""
    g = _gauss_1d(size, sigma, torch.float64)
    off = torch.arange(tile + size - 1)[None, :] - torch.arange(tile)[:, None]
    inside = (off >= 0) & (off < size)
    T = torch.where(inside, g[off.clamp(0, size - 1)], torch.zeros((), dtype=torch.float64))
    return T.to(dtype=dtype, device=device)


def _blur_rows_tiled(z: torch.Tensor, size: int, sigma: float) -> torch.Tensor:
    """Zero-padded 1D Gaussian blur of z [..., H, W] along H, BLUR_TILE output rows at a time:
    the same sums as the banded matrix of ``_blur_matrix``, without its zeros."""
    H, r = z.shape[-2], size // 2
    n_tiles = -(-H // BLUR_TILE)
    zp = F.pad(z, (0, 0, r, n_tiles * BLUR_TILE - H + r))  # [..., tiles*TILE + size-1, W]
    win = zp.unfold(-2, BLUR_TILE + size - 1, BLUR_TILE)  # [..., tiles, W, TILE + size-1]
    T = _tile_matrix(BLUR_TILE, size, sigma, z.dtype, z.device)
    out = (win @ T.T).transpose(-1, -2)  # [..., tiles, TILE, W]
    return out.reshape(*z.shape[:-2], n_tiles * BLUR_TILE, z.shape[-1])[..., :H, :]


def blur(z: torch.Tensor, size: int = 11, sigma: float = 1.5, tiled: bool | None = None):
    """Zero-padded separable Gaussian blur, as SSIM's window.

    Runs as banded matmuls, or as block-Toeplitz tiles from ``TILED_BLUR_MIN_SIDE`` pixels.

    Args:
        z: [..., H, W] maps.
        size: window side, px.
        sigma: the Gaussian's standard deviation, px.
        tiled: force the tiled (True) or the matmul (False) path; None: by size.

    Returns:
        (torch.Tensor): [..., H, W] the blurred maps.
    """
    H, W = z.shape[-2:]
    if tiled is None:
        tiled = min(H, W) >= TILED_BLUR_MIN_SIDE
    if tiled:
        rows = _blur_rows_tiled(z, size, sigma)
        return _blur_rows_tiled(rows.transpose(-1, -2), size, sigma).transpose(-1, -2)
    Bh = _blur_matrix(H, size, sigma, z.dtype, z.device)
    Bw = _blur_matrix(W, size, sigma, z.dtype, z.device)
    return Bh @ z @ Bw.T


def ssim(a: torch.Tensor, b: torch.Tensor, window: int = 11, sigma: float = 1.5) -> torch.Tensor:
    """Mean SSIM of two images (the 3DGS implementation: Gaussian window, zero padding).

    Differentiable w.r.t. both; the window's separable blur runs as two banded matmuls, or in tiles
    on large images ([`blur`][physgs.train.losses.blur]).

    Args:
        a: [H, W, C] image in [0, 1].
        b: [H, W, C] image in [0, 1].
        window: window side, px.
        sigma: the window's standard deviation, px.

    Returns:
        0-d tensor, the mean SSIM over pixels and channels.

    Raises:
        ValueError: the images are not [H, W, C] of one shape.
    """
    if a.shape != b.shape or a.ndim != 3:
        raise ValueError(
            f"ssim: images must share shape [H, W, C]; got {tuple(a.shape)}, {tuple(b.shape)}"
        )
    x = a.permute(2, 0, 1)  # [C, H, W]
    y = b.permute(2, 0, 1)
    # The blurred maps, batched. b's own two (my, byy) go apart under no_grad when b needs no
    # gradient (a training target): autograd would otherwise carry them through the backward.
    if b.requires_grad:
        mx, my, bxx, byy, bxy = blur(
            torch.stack([x, y, x * x, y * y, x * y]), window, sigma
        ).unbind(0)
    else:
        mx, bxx, bxy = blur(torch.stack([x, x * x, x * y]), window, sigma).unbind(0)
        with torch.no_grad():
            my, byy = blur(torch.stack([y, y * y]), window, sigma).unbind(0)
    sxx = bxx - mx * mx
    syy = byy - my * my
    sxy = bxy - mx * my
    c1, c2 = SSIM_C1, SSIM_C2
    m = ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    return m.mean()


def photometric_loss(render: torch.Tensor, target: torch.Tensor, ssim_weight: float = 0.2):
    """(loss, l1, dssim) for images [H, W, 3] in [0, 1]; loss = (1-w) L1 + w (1 - SSIM).

    On the CPU with a target that needs no gradient (training), the loss and its gradient come
    from one numba pass in float64
    ([`fused_photometric_loss`][physgs.train.fused_loss.fused_photometric_loss], half the time
    of the torch ops); otherwise from the torch ops below (differentiable w.r.t. both images,
    on any device, in the images' dtype). The two agree to float64 rounding on float64 images.

    Args:
        render: [H, W, 3] the rendered image, in [0, 1].
        target: [H, W, 3] the recorded image, in [0, 1].
        ssim_weight: w, the D-SSIM share.

    Returns:
        (tuple[torch.Tensor, torch.Tensor, torch.Tensor]): ``(loss, l1, dssim)``, scalar tensors.
    """
    if render.device.type == "cpu" and target.device.type == "cpu" and not target.requires_grad:
        return fused_photometric_loss(render, target, ssim_weight)
    return _photometric_loss_torch(render, target, ssim_weight)


def _photometric_loss_torch(render: torch.Tensor, target: torch.Tensor, ssim_weight: float = 0.2):
    """[`photometric_loss`][physgs.train.losses.photometric_loss] as torch ops: differentiable
    w.r.t. both images, on any device (the fused pass's reference in the tests)."""
    l1 = (render - target).abs().mean()
    dssim = 1.0 - ssim(render, target)
    return (1.0 - ssim_weight) * l1 + ssim_weight * dssim, l1, dssim
