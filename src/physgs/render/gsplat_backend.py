"""Dispatch to gsplat's CUDA ``rasterization()`` with this package's conventions.

Only imported when the tensors are on CUDA and gsplat is installed. Same maths as the CPU paths:
eps2d = 0.3 px^2 dilation, near plane from the camera, pixel centres at integer + 0.5, the
unnormalised expected depth sum z a T from render_mode "RGB+D", background composited.
gsplat bounds each Gaussian by 3 sigma where the CPU paths use the exact 1/255 footprint, so faint
far tails can differ slightly.
"""

from __future__ import annotations

import torch

from physgs.camera import Camera
from physgs.render.constants import EPS2D


def rasterize_gsplat(
    means: torch.Tensor,
    quats: torch.Tensor,
    scales: torch.Tensor,
    opacities: torch.Tensor,
    colors: torch.Tensor,
    camera: Camera,
    background: torch.Tensor,
    return_depth: bool = True,
):
    """gsplat backend of [`rasterization`][physgs.render.rasterization] (same shapes and units).

    Args:
        means: [N, 3] centres, world units.
        quats: [N, 4] orientations (w, x, y, z).
        scales: [N, 3] standard deviations, world units.
        opacities: [N] in [0, 1].
        colors: [N, D] in [0, 1].
        camera: the camera; the image is camera.height x camera.width px.
        background: [D] background colour.
        return_depth: whether to compute the expected depth.

    Returns:
        (tuple[torch.Tensor, torch.Tensor, torch.Tensor | None]): ``(rgb [H, W, D], alpha [H, W],
            depth [H, W] or None)`` on the CUDA device, in the dtype of ``means`` (gsplat computes
            in float32).
    """
    import gsplat  # here: an optional package (CUDA only); the module loads without it

    dev, dt = means.device, means.dtype
    viewmat = torch.as_tensor(camera.viewmat, dtype=torch.float32, device=dev)[None]
    K = torch.as_tensor(camera.K, dtype=torch.float32, device=dev)[None]
    cast = [x.float() for x in (means, quats, scales, opacities, colors, background)]
    m, q, s, o, c, bg = cast
    # "RGB+D": depth rides along as an extra channel (sum z a T); gsplat pads its background
    # with 0 itself.
    mode = "RGB+D" if return_depth else "RGB"
    img, alpha, _ = gsplat.rasterization(
        m,
        q,
        s,
        o,
        c,
        viewmat,
        K,
        camera.width,
        camera.height,
        near_plane=camera.near,
        eps2d=EPS2D,
        backgrounds=bg[None],
        render_mode=mode,
        packed=False,
        rasterize_mode="classic",
    )
    img = img[0].to(dt)
    alpha = alpha[0, ..., 0].to(dt)
    D = colors.shape[1]
    rgb = img[..., :D]
    depth = img[..., D] if return_depth else None
    return rgb, alpha, depth


__all__ = ["rasterize_gsplat"]
