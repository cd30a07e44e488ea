"""The photometric loss and its gradient in one numba pass (float64), behind one autograd node.

The torch form of [`photometric_loss`][physgs.train.losses.photometric_loss] builds SSIM from five
blurred maps per channel as banded [n, n] matmuls, then backpropagates through some twenty small
ops: ~3.4 ms forward + backward per 128 px RGB frame on one thread, a sixth of an iteration of
ours on the medium tree. Here the 11-tap window runs as a direct separable convolution (22
multiply-adds a pixel per map instead of 2n), and the gradient w.r.t. the render is written out
by hand: SSIM is a per-pixel function of the blurred maps, and the zero-padded blur with a
symmetric window is its own adjoint, so dSSIM/dx = B g_mx + 2 x B g_bxx + y B g_bxy with the
g_* the per-pixel partials. The loss and both gradients come out of the forward; the backward
only scales them. Numbers: float64 throughout, so the loss and gradient match a float64 torch
reference to ~1e-12 whatever the input dtype (the float32 torch form was off by ~1e-7).
"""

from __future__ import annotations

import functools

import numba as nb
import numpy as np
import torch

#: SSIM's stabilising constants (K1 L)^2 and (K2 L)^2 for L = 1 (images in [0, 1]).
SSIM_C1 = 0.01**2
SSIM_C2 = 0.03**2


@functools.lru_cache(maxsize=8)
def gauss_window(size: int, sigma: float) -> np.ndarray:
    """Normalised 1D Gaussian window, the 2D SSIM window's separable factor (cached: every
    training iteration asks for it; read-only).

    Args:
        size: window length, px (odd).
        sigma: standard deviation, px.

    Returns:
        (np.ndarray): [size] float64, sums to 1.
    """
    x = np.arange(size, dtype=np.float64) - (size - 1) / 2
    g = np.exp(-(x**2) / (2 * sigma**2))
    g /= g.sum()
    g.flags.writeable = False
    return g


@nb.njit(cache=True)
def _blur_plane(src, g, tmp, dst):  # pragma: no cover - compiled
    """dst = zero-padded separable blur of src [H, W] by the window g [size] (rows, then
    columns); tmp [H, W + size - 1] is scratch (its first and last size // 2 columns are
    written zero here: the column pass then needs no bounds). Taps run four at a time, so a
    pass reads and writes its output row once per four taps (once per tap left the loop bound
    by its stores, ~2x slower); every inner loop runs along contiguous row views with its
    bounds hoisted, which LLVM vectorises (2D indexing in the loop kept it scalar)."""
    H, W = src.shape
    n = g.shape[0]
    r = n // 2
    if tmp.shape[0] < H or tmp.shape[1] != W + n - 1:  # the loops below do not check bounds
        raise ValueError("_blur_plane: tmp must be [H, W + size - 1]")
    for i in range(H):
        t = tmp[i, r : r + W]
        t[:] = 0.0
        k0 = max(0, r - i)  # the taps whose source row lies inside the image
        k1 = min(n, H + r - i)
        k = k0
        while k + 4 <= k1:
            s0, s1, s2, s3 = (
                src[i + k - r],
                src[i + k + 1 - r],
                src[i + k + 2 - r],
                src[i + k + 3 - r],
            )
            g0, g1, g2, g3 = g[k], g[k + 1], g[k + 2], g[k + 3]
            for j in range(W):
                t[j] += g0 * s0[j] + g1 * s1[j] + g2 * s2[j] + g3 * s3[j]
            k += 4
        while k < k1:
            s0 = src[i + k - r]
            g0 = g[k]
            for j in range(W):
                t[j] += g0 * s0[j]
            k += 1
    for i in range(H):
        tp = tmp[i]
        tp[:r] = 0.0
        tp[r + W :] = 0.0
        d = dst[i]
        d[:] = 0.0
        k = 0
        while k + 4 <= n:
            a0, a1, a2, a3 = (
                tp[k : k + W],
                tp[k + 1 : k + 1 + W],
                tp[k + 2 : k + 2 + W],
                tp[k + 3 : k + 3 + W],
            )
            g0, g1, g2, g3 = g[k], g[k + 1], g[k + 2], g[k + 3]
            for j in range(W):
                d[j] += g0 * a0[j] + g1 * a1[j] + g2 * a2[j] + g3 * a3[j]
            k += 4
        while k < n:
            a0 = tp[k : k + W]
            g0 = g[k]
            for j in range(W):
                d[j] += g0 * a0[j]
            k += 1


@nb.njit(cache=True)
def _blur_product(a, b, g, prod, tmp, dst):  # pragma: no cover - compiled
    """dst = the blur of a * b (all [H, W]); prod [H, W] and tmp (as `_blur_plane`'s) are
    scratch."""
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            prod[i, j] = a[i, j] * b[i, j]
    _blur_plane(prod, g, tmp, dst)


@nb.njit(cache=True)
def loss_terms(render, target, g, w, grad_loss, grad_l1, grad_ssim):  # pragma: no cover
    """L1, mean SSIM and the gradients w.r.t. the render of the L1, SSIM and the loss.

    Args:
        render (np.ndarray): [H, W, C] float32 or float64, the render x.
        target (np.ndarray): [H, W, C] float32 or float64, the target y.
        g (np.ndarray): [size] float64 the window from
            [`gauss_window`][physgs.train.fused_loss.gauss_window].
        w (float): the D-SSIM share of the loss, (1 - w) L1 + w (1 - SSIM).
        grad_loss (np.ndarray): [H, W, C], written: d loss / dx (any float dtype; so below).
        grad_l1 (np.ndarray): [H, W, C], written: d mean|x - y| / dx.
        grad_ssim (np.ndarray): [H, W, C], written: d SSIM / dx.

    Returns:
        (tuple[float, float]): (mean |x - y|, mean SSIM) over channels and pixels, from float64
            arithmetic whatever the arrays' dtypes.
    """
    H, W, C = render.shape
    inv_n = 1.0 / (C * H * W)
    planes = np.empty((12, H, W))  # float64 scratch, one [H, W] plane each
    tmp = np.empty((H, W + g.shape[0] - 1))  # the blur's scratch, padded rows
    xc, yc, prod, mx, my, bxx = (
        planes[0],
        planes[1],
        planes[2],
        planes[3],
        planes[4],
        planes[5],
    )
    byy, bxy, g_mx, g_bxx, g_bxy, gl1 = (
        planes[6],
        planes[7],
        planes[8],
        planes[9],
        planes[10],
        planes[11],
    )
    m_row = np.empty(W)
    l1 = 0.0
    total = 0.0
    for c in range(C):
        for i in range(H):  # one channel as a float64 plane
            for j in range(W):
                xc[i, j] = render[i, j, c]
                yc[i, j] = target[i, j, c]
        _blur_plane(xc, g, tmp, mx)
        _blur_plane(yc, g, tmp, my)
        _blur_product(xc, xc, g, prod, tmp, bxx)
        _blur_product(yc, yc, g, prod, tmp, byy)
        _blur_product(xc, yc, g, prod, tmp, bxy)
        for i in range(H):
            # row views: the loop below has no reduction and vectorises
            a_, b_, xx, yy, xy = mx[i], my[i], bxx[i], byy[i], bxy[i]
            gm, gxx, gxy, mr, xr, yr = g_mx[i], g_bxx[i], g_bxy[i], m_row, xc[i], yc[i]
            gr = gl1[i]
            for j in range(W):
                a = a_[j]
                b = b_[j]
                n1 = 2.0 * a * b + SSIM_C1
                n2 = 2.0 * (xy[j] - a * b) + SSIM_C2
                d1 = a * a + b * b + SSIM_C1
                d2 = (xx[j] - a * a) + (yy[j] - b * b) + SSIM_C2
                inv = 1.0 / (d1 * d2)
                m = n1 * n2 * inv
                mr[j] = m
                # per-pixel partials of m, times d(mean)/dm
                gm[j] = inv_n * (2.0 * b * (n2 - n1) * inv - 2.0 * a * m * (d2 - d1) * inv)
                gxx[j] = -inv_n * m * d1 * inv
                gxy[j] = inv_n * 2.0 * n1 * inv
                diff = xr[j] - yr[j]
                gr[j] = inv_n * ((diff > 0.0) - (diff < 0.0))
            for j in range(W):
                total += mr[j]
                l1 += abs(xr[j] - yr[j])
        # the blur is self-adjoint: pull the partials back through it
        _blur_plane(g_mx, g, tmp, mx)
        _blur_plane(g_bxx, g, tmp, bxx)
        _blur_plane(g_bxy, g, tmp, bxy)
        for i in range(H):
            for j in range(W):
                gs = mx[i, j] + 2.0 * xc[i, j] * bxx[i, j] + yc[i, j] * bxy[i, j]
                grad_ssim[i, j, c] = gs
                grad_l1[i, j, c] = gl1[i, j]
                grad_loss[i, j, c] = (1.0 - w) * gl1[i, j] - w * gs
    return l1 * inv_n, total * inv_n


class _FusedPhotometricLoss(torch.autograd.Function):
    @staticmethod
    def forward(ctx, render, target, ssim_weight, window, sigma):
        x = render.detach().cpu().numpy()
        y = target.detach().cpu().numpy()
        w = float(ssim_weight)
        grads = tuple(np.empty_like(x) for _ in range(3))  # loss, l1, ssim: [H, W, C] each
        l1, s = loss_terms(x, y, gauss_window(window, sigma), w, *grads)
        ctx.grads = tuple(torch.from_numpy(v).to(render.device) for v in grads)
        ctx.set_materialize_grads(False)
        vals = ((1.0 - w) * l1 + w * (1.0 - s), l1, 1.0 - s)
        return tuple(torch.tensor(v, dtype=render.dtype, device=render.device) for v in vals)

    @staticmethod
    def backward(ctx, g_loss, g_l1, g_dssim):
        grad_loss, grad_l1, grad_ssim = ctx.grads
        out = None
        # the training loop backpropagates the loss alone; l1 and dssim are for its log
        for g, d in ((g_loss, grad_loss), (g_l1, grad_l1), (g_dssim, -grad_ssim)):
            if g is not None:
                out = g * d if out is None else out + g * d
        return out, None, None, None, None


def fused_photometric_loss(
    render: torch.Tensor,
    target: torch.Tensor,
    ssim_weight: float = 0.2,
    window: int = 11,
    sigma: float = 1.5,
):
    """(loss, l1, dssim) as [`photometric_loss`][physgs.train.losses.photometric_loss], in one
    numba pass, differentiable w.r.t. ``render`` only.

    Args:
        render: [H, W, C] the rendered image, in [0, 1].
        target: [H, W, C] the recorded image, in [0, 1]; no gradient flows to it.
        ssim_weight: w, the D-SSIM share of the loss.
        window: SSIM window side, px.
        sigma: the window's standard deviation, px.

    Returns:
        (tuple[torch.Tensor, torch.Tensor, torch.Tensor]): ``(loss, l1, dssim)``, 0-d tensors of
            ``render``'s dtype and device.

    Raises:
        ValueError: the images are not [H, W, C] of one shape, or ``target`` requires a gradient.
    """
    if render.shape != target.shape or render.ndim != 3:
        raise ValueError(
            "fused_photometric_loss: images must share shape [H, W, C]; got "
            f"{tuple(render.shape)}, {tuple(target.shape)}"
        )
    if target.requires_grad:
        raise ValueError(
            "fused_photometric_loss: the target must not require a gradient "
            "(use physgs.train.losses.photometric_loss for a differentiable target)"
        )
    return _FusedPhotometricLoss.apply(render, target, ssim_weight, window, sigma)
