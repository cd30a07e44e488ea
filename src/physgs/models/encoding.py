"""Fourier (NeRF-style) positional encoding."""

from __future__ import annotations

import math

import torch


def fourier_dim(d: int, bands: int) -> int:
    """Width of ``fourier(x [.., d], bands)``: the input plus a sine and cosine per band.

    Args:
        d: the input's width.
        bands: frequency bands.

    Returns:
        d * (1 + 2 bands).
    """
    return d * (1 + 2 * bands)


def fourier(x: torch.Tensor, bands: int) -> torch.Tensor:
    """[x, sin(2^k pi x), cos(2^k pi x) for k < bands] of x [..., d] -> [..., d * (1 + 2 bands)].

    Args:
        x: [..., d] inputs, expected in roughly [-1, 1] (normalised position) or [0, 1+]
            (normalised time).
        bands: frequency bands (0: x itself).

    Returns:
        [..., d * (1 + 2 bands)]: x, then per band k its d sines and d cosines.

    Raises:
        ValueError: for negative ``bands``.
    """
    if bands < 0:
        raise ValueError(f"fourier: bands must be >= 0, got {bands}")
    if bands == 0:
        return x
    freqs = (2.0 ** torch.arange(bands, dtype=x.dtype, device=x.device)) * math.pi  # [bands]
    xb = x[..., None, :] * freqs[:, None]  # [..., bands, d]
    enc = torch.cat([torch.sin(xb), torch.cos(xb)], dim=-1).flatten(-2)  # [..., bands * 2d]
    return torch.cat([x, enc], dim=-1)
