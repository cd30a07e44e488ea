"""Differentiable 3D Gaussian Splatting rasterizer (CPU fast path, PyTorch reference, gsplat).

One entry point, [`rasterization`][physgs.render.rasterization], in the spirit of gsplat's:
Gaussians + camera + background -> RGB, accumulated alpha and expected depth, differentiable w.r.t.
means, quats, scales, opacities and colours.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from physgs.camera import Camera
from physgs.render.fast import rasterize_fast
from physgs.render.gsplat_backend import rasterize_gsplat
from physgs.render.project import project_gaussians
from physgs.render.reference import composite_reference

BACKENDS = ("auto", "fast", "reference", "gsplat")


@dataclass(frozen=True)
class RenderOutput:
    """rgb [H, W, 3] composited colour (background included); alpha [H, W] accumulated opacity
    1 - T_final; depth [H, W] expected camera depth sum_i z_i a_i T_i in world units,
    *unnormalised* (divide by alpha for the depth of the visible surface), or None."""

    rgb: torch.Tensor
    alpha: torch.Tensor
    depth: torch.Tensor | None


def _all(torch_pred, np_pred, x: torch.Tensor) -> bool:
    # numpy on the CPU: a single small torch op can cost milliseconds of OpenMP barrier on a
    # busy 2-core machine.
    if x.device.type == "cpu":
        return bool(np_pred(x.detach().numpy()).all())
    return bool(torch_pred(x.detach()).all())


def _check_inputs(means, quats, scales, opacities, colors, camera, background):
    n = means.shape[0] if means.ndim == 2 else -1
    shapes = {
        "means": (means, (n, 3)),
        "quats": (quats, (n, 4)),
        "scales": (scales, (n, 3)),
        "opacities": (opacities, (n,)),
        "colors": (colors, (n, colors.shape[-1])),
    }
    for name, (x, shape) in shapes.items():
        if not isinstance(x, torch.Tensor):
            raise TypeError(f"rasterization: {name} must be a torch.Tensor, got {type(x).__name__}")
        if tuple(x.shape) != shape or n < 0:
            raise ValueError(
                f"rasterization: {name} has shape {tuple(x.shape)}, expected "
                f"{shape} (N = {n} from means [N, 3]); reshape the input"
            )
        if x.dtype != means.dtype or x.device != means.device:
            raise ValueError(
                f"rasterization: {name} is {x.dtype} on {x.device} but means is "
                f"{means.dtype} on {means.device}; cast all inputs alike"
            )
        if not _all(torch.isfinite, np.isfinite, x):
            raise ValueError(
                f"rasterization: {name} contains NaN or inf; fix the upstream model "
                "(e.g. a diverged training step)"
            )
    if means.dtype not in (torch.float32, torch.float64):
        raise ValueError(f"rasterization: dtype {means.dtype} unsupported; use float32 or float64")
    if not _all(lambda v: v >= 0, lambda v: v >= 0, scales):
        raise ValueError(
            "rasterization: scales must be >= 0 (already activated, e.g. exp of the "
            "log-scale parameter)"
        )
    if not _all(lambda v: (v >= 0) & (v <= 1), lambda v: (v >= 0) & (v <= 1), opacities):
        raise ValueError(
            "rasterization: opacities must lie in [0, 1] (already activated, e.g. "
            "sigmoid of the logit parameter)"
        )
    if not isinstance(camera, Camera):
        raise TypeError(f"rasterization: camera must be physgs.camera.Camera, got {type(camera)}")
    if camera.width <= 0 or camera.height <= 0:
        raise ValueError(
            f"rasterization: image size {camera.width}x{camera.height} is empty; "
            "give the camera a positive width and height"
        )
    if background.shape != (colors.shape[-1],):
        raise ValueError(
            f"rasterization: background has shape {tuple(background.shape)}, "
            f"expected ({colors.shape[-1]},) to match colors"
        )


def _gsplat_available(device: torch.device) -> bool:
    if device.type != "cuda":
        return False
    try:  # here: gsplat is optional (CUDA only), probed and never required
        import gsplat  # noqa: F401
    except ImportError:
        return False
    return True


def auto_backend(device) -> str:
    """The backend ``"auto"`` picks on ``device``: gsplat on CUDA where it is installed, else the
    numba kernels (on CUDA they copy to the host and back: 17 ms forward + backward on the medium
    tree at 128 px on one thread, against 178 ms for the PyTorch reference, whose Python loop
    over tiles is bound by kernel launches there; measured on an H200).

    Args:
        device (torch.device | str): where the Gaussians live.

    Returns:
        ``"fast"``, ``"gsplat"`` or ``"reference"``.
    """
    return "gsplat" if _gsplat_available(torch.device(device)) else "fast"


def rasterization(
    means: torch.Tensor,
    quats: torch.Tensor,
    scales: torch.Tensor,
    opacities: torch.Tensor,
    colors: torch.Tensor,
    camera: Camera,
    background,
    *,
    backend: str = "auto",
    return_depth: bool = True,
) -> RenderOutput:
    """Render N 3D Gaussians into ``camera``.

    Args:
        means: [N, 3] centres, world units.
        quats: [N, 4] orientations (w, x, y, z), need not be unit.
        scales: [N, 3] standard deviations, world units (>= 0, activated).
        opacities: [N] in [0, 1].
        colors: [N, 3] in [0, 1] (any D channels work).
        camera: the camera; the image is camera.height x camera.width px.
        background (torch.Tensor | np.ndarray | list): [3] (tensor, array or list; same channels as
            colors).
        backend: ``"fast"`` (numba CPU kernels with an explicit backward), ``"reference"`` (pure
            PyTorch autograd), ``"gsplat"`` (CUDA, needs gsplat installed) or ``"auto"``
            ([`auto_backend`][physgs.render.auto_backend]: gsplat on CUDA when installed, else
            fast).
        return_depth: whether to compute the expected depth.

    Returns:
        A [`RenderOutput`][physgs.render.RenderOutput] on the device and dtype of ``means``.

    Raises:
        ValueError: an unknown backend, or inputs of the wrong shape, dtype or device, with NaN
            or inf, negative scales or opacities outside [0, 1].
        TypeError: an input other than ``background`` is not a tensor.
        RuntimeError: the gsplat backend is asked for where gsplat is not available.
    """
    if backend not in BACKENDS:
        raise ValueError(f"rasterization: unknown backend {backend!r}; choose one of {BACKENDS}")
    background = torch.as_tensor(
        np.asarray(background) if not isinstance(background, torch.Tensor) else background,
        dtype=means.dtype,
        device=means.device,
    )
    _check_inputs(means, quats, scales, opacities, colors, camera, background)
    if backend == "auto":
        backend = auto_backend(means.device)
    if backend == "gsplat":
        if not _gsplat_available(means.device):
            raise RuntimeError(
                "rasterization: backend 'gsplat' needs CUDA tensors and the gsplat "
                "package; use backend='fast' on the CPU or `pip install gsplat`"
            )
        rgb, alpha, depth = rasterize_gsplat(
            means, quats, scales, opacities, colors, camera, background, return_depth
        )
        return RenderOutput(rgb, alpha, depth)
    if backend == "fast":
        rgb, alpha, depth = rasterize_fast(
            means, quats, scales, opacities, colors, camera, background, return_depth
        )
        return RenderOutput(rgb, alpha, depth)
    proj = project_gaussians(means, quats, scales, camera)
    rgb, alpha, depth = composite_reference(
        proj.means2d,
        proj.conics,
        opacities,
        colors,
        proj.depths,
        proj.valid,
        proj.cov2d,
        background,
        camera.width,
        camera.height,
        return_depth,
    )
    return RenderOutput(rgb, alpha, depth)


def render_state(
    state, camera: Camera, background, *, backend: str = "auto", return_depth: bool = False
) -> RenderOutput:
    """Render a model's Gaussians at one instant: ``rasterization`` on the state's five arrays.

    Training, the held-out window frames, the evaluation and the tests all render a
    [`GaussianState`][physgs.models.gaussians.GaussianState] this way; one call keeps the order
    of its fields in one place.

    Args:
        state (GaussianState): any object with ``means`` [N, 3], ``quats`` [N, 4], ``scales`` [N, 3],
            ``opacities`` [N] and ``colors`` [N, 3] (a ``GaussianState``).
        camera: the camera; the image is camera.height x camera.width px.
        background (torch.Tensor | np.ndarray | list): [3] background colour.
        backend: as for [`rasterization`][physgs.render.rasterization].
        return_depth: whether to compute the expected depth (off: the losses read colour only).

    Returns:
        The [`RenderOutput`][physgs.render.RenderOutput].
    """
    return rasterization(
        state.means,
        state.quats,
        state.scales,
        state.opacities,
        state.colors,
        camera,
        background,
        backend=backend,
        return_depth=return_depth,
    )


__all__ = ["rasterization", "render_state", "auto_backend", "RenderOutput", "BACKENDS"]
