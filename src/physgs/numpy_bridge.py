"""Tensors to numpy and back around the numba kernels (renderer, part transform): float64 in,
the caller's dtype and device out."""

from __future__ import annotations

import numpy as np
import torch


def float64_array(x: torch.Tensor) -> np.ndarray:
    """A tensor as a C-contiguous float64 array on the CPU (a view when it already is one).

    Args:
        x: any tensor (detached here).

    Returns:
        (np.ndarray): x's values, float64, x's shape. The kernels compute in float64 and so
            compile once whatever the callers' dtype.
    """
    return np.ascontiguousarray(x.detach().cpu().numpy(), dtype=np.float64)


def tensor_like(x: np.ndarray, like: torch.Tensor) -> torch.Tensor:
    """An array as a tensor of ``like``'s dtype and device.

    Args:
        x: the values, any float dtype.
        like: the tensor whose dtype and device the result takes.

    Returns:
        (torch.Tensor): x's values, x's shape.
    """
    if like.dtype in (torch.float32, torch.float64):
        # cast in numpy (single-threaded) rather than torch: no OpenMP barrier for a tiny copy
        np_dtype = np.float32 if like.dtype == torch.float32 else np.float64
        return torch.from_numpy(np.ascontiguousarray(x, dtype=np_dtype)).to(like.device)
    return torch.from_numpy(np.ascontiguousarray(x)).to(like.device, like.dtype)
