"""EWA projection of 3D Gaussians to the image plane (vectorised torch, differentiable by autograd).

Follows 3DGS / gsplat: world -> camera (OpenCV: z forward, y down), 3D covariance
R_q S S^T R_q^T, perspective Jacobian evaluated at x/z, y/z clamped to the image edge plus
0.3 tan(half field of view) (gsplat's ``persp_proj``; 1.3 x the half field of view for a centred
principal point, as 3DGS), so Gaussians far off to the side do not blow up, +0.3 px^2 dilation of
the 2D covariance, conic = its inverse. Culled Gaussians (behind the near plane, degenerate) get a
mask and finite zero outputs, never NaN: every division uses a clamped denominator, so gradients
stay finite too. Thresholds live in [`physgs.render.constants`][physgs.render.constants].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from physgs.camera import Camera
from physgs.render.constants import (
    BOX_SLACK_PX,
    EPS2D,
    FOV_CLAMP_MARGIN,
    INV_ALPHA_MIN,
)
from physgs.rotations import quat_to_rotmat


@dataclass(frozen=True)
class Projected:
    """Per-Gaussian image-plane quantities (N Gaussians).

    means2d [N, 2] pixels (x right, y down; pixel centres at integer + 0.5);
    conics [N, 3] (a, b, c) of the inverse 2D covariance [[a, b], [b, c]] in 1/px^2;
    depths [N] camera z (world units); cov2d [N, 3] (xx, xy, yy) px^2, detached, for binning;
    valid [N] bool: in front of the near plane with a positive-definite 2D covariance.
    Invalid entries hold finite zeros.
    """

    means2d: torch.Tensor
    conics: torch.Tensor
    depths: torch.Tensor
    cov2d: torch.Tensor
    valid: torch.Tensor


def fov_clamp_limits(camera: Camera) -> tuple[float, float, float, float]:
    """Tangent limits (x-, x+, y-, y+) of the Jacobian's evaluation point.

    x/z is clamped to [-x-, x+] and y/z to [-y-, y+]. Each is the tangent of the image edge on that
    side plus FOV_CLAMP_MARGIN x tan(half field of view), tan_fovx = 0.5 W / fx (gsplat's
    ``persp_proj``; 1.3 tan(fov / 2) on every side for a centred principal point, as 3DGS's
    ``computeCov2D``).

    Args:
        camera: the pinhole camera (fx, fy, cx, cy in px; width, height in px).

    Returns:
        (x-, x+, y-, y+), dimensionless tangents, each > 0.
    """
    fx, fy, cx, cy = camera.fx, camera.fy, camera.cx, camera.cy
    W, H = camera.width, camera.height
    tan_fovx = 0.5 * W / fx
    tan_fovy = 0.5 * H / fy
    return (
        cx / fx + FOV_CLAMP_MARGIN * tan_fovx,
        (W - cx) / fx + FOV_CLAMP_MARGIN * tan_fovx,
        cy / fy + FOV_CLAMP_MARGIN * tan_fovy,
        (H - cy) / fy + FOV_CLAMP_MARGIN * tan_fovy,
    )


def camera_tensors(camera: Camera, like: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The camera's world-to-camera rotation and translation as tensors.

    Args:
        camera: the camera.
        like: a tensor whose dtype and device the outputs take.

    Returns:
        (R [3, 3], t [3] in world units), x_cam = R x_world + t.
    """
    R = torch.as_tensor(np.asarray(camera.R), dtype=like.dtype, device=like.device)
    t = torch.as_tensor(np.asarray(camera.t), dtype=like.dtype, device=like.device)
    return R, t


def project_gaussians(
    means: torch.Tensor,
    quats: torch.Tensor,
    scales: torch.Tensor,
    camera: Camera,
    eps2d: float = EPS2D,
) -> Projected:
    """Project 3D Gaussians to the image plane (EWA splatting, module docstring).

    Differentiable w.r.t. means, quats and scales; culled Gaussians get finite zeros.

    Args:
        means: [N, 3] centres, world units.
        quats: [N, 4] orientations (w, x, y, z), any norm.
        scales: [N, 3] standard deviations along the Gaussian's axes, world units.
        camera: the pinhole camera.
        eps2d: dilation added to the 2D covariance's diagonal, px^2.

    Returns:
        A [`Projected`][physgs.render.project.Projected]: means2d [N, 2] px, conics [N, 3]
            1/px^2, depths [N] world units, cov2d [N, 3] px^2 (detached), valid [N] bool.
    """
    R, t = camera_tensors(camera, means)
    xyz = means @ R.T + t  # [N, 3] camera coordinates
    x, y, z = xyz.unbind(-1)
    in_front = z > camera.near
    # Clamp before dividing so culled Gaussians (z <= near) never produce inf/NaN, even in grads.
    zs = torch.where(in_front, z, torch.ones_like(z))

    Rq = quat_to_rotmat(quats)  # [N, 3, 3]
    M = R @ (Rq * scales[:, None, :])  # [N, 3, 3] camera-frame square root of the covariance

    fx, fy, cx, cy = camera.fx, camera.fy, camera.cx, camera.cy
    # gsplat's field-of-view clamp of the Jacobian's evaluation point.
    lim_x_neg, lim_x_pos, lim_y_neg, lim_y_pos = fov_clamp_limits(camera)
    tx = zs * torch.clamp(x / zs, -lim_x_neg, lim_x_pos)
    ty = zs * torch.clamp(y / zs, -lim_y_neg, lim_y_pos)
    zero = torch.zeros_like(zs)
    J = torch.stack(
        [fx / zs, zero, -fx * tx / (zs * zs), zero, fy / zs, -fy * ty / (zs * zs)], dim=-1
    ).reshape(-1, 2, 3)  # [N, 2, 3]
    JM = J @ M  # [N, 2, 3]
    cov = JM @ JM.transpose(1, 2)  # [N, 2, 2]
    a = cov[:, 0, 0] + eps2d
    b = cov[:, 0, 1]
    c = cov[:, 1, 1] + eps2d
    det = a * c - b * b
    valid = in_front & (det > 0) & torch.isfinite(det)
    dets = torch.where(valid, det, torch.ones_like(det))
    conics = torch.stack([c / dets, -b / dets, a / dets], dim=-1)
    means2d = torch.stack([fx * x / zs + cx, fy * y / zs + cy], dim=-1)
    v = valid[:, None]
    conics = torch.where(v, conics, torch.zeros_like(conics))
    means2d = torch.where(v, means2d, torch.zeros_like(means2d))
    depths = torch.where(valid, z, torch.zeros_like(z))
    cov2d = torch.stack([a, b, c], dim=-1).detach()
    cov2d = torch.where(v, cov2d, torch.zeros_like(cov2d))
    return Projected(means2d, conics, depths, cov2d, valid)


def pixel_bounds(
    means2d: np.ndarray,
    cov2d: np.ndarray,
    opacities: np.ndarray,
    valid: np.ndarray,
    width: int,
    height: int,
) -> np.ndarray:
    """Conservative pixel boxes outside which a Gaussian's alpha is below ALPHA_MIN.

    alpha >= 1/255 needs d^T conic d <= 2 ln(255 o); that ellipse's bounding box has half-widths
    sqrt(2 ln(255 o) cov_xx), sqrt(2 ln(255 o) cov_yy), widened by BOX_SLACK_PX on each side.

    Args:
        means2d: [N, 2] centres, px.
        cov2d: [N, 3] 2D covariances (xx, xy, yy), px^2.
        opacities: [N] in [0, 1].
        valid: [N] bool, the projection's mask.
        width: image width, px.
        height: image height, px.

    Returns:
        int64 [N, 4] (x0, x1, y0, y1) inclusive pixel index ranges clipped to the image; x0 > x1
            marks a Gaussian that touches no pixel (invalid, too faint, or off the image).
    """
    n = means2d.shape[0]
    out = np.empty((n, 4), dtype=np.int64)
    out[:, 0], out[:, 1], out[:, 2], out[:, 3] = 1, 0, 1, 0
    o = opacities.astype(np.float64)
    keep = valid & (o * INV_ALPHA_MIN > 1.0) & np.isfinite(means2d).all(1)
    if not keep.any():
        return out
    thr = 2.0 * np.log(INV_ALPHA_MIN * o[keep])
    m = means2d[keep].astype(np.float64)
    cv = cov2d[keep].astype(np.float64)
    rx = np.sqrt(thr * np.maximum(cv[:, 0], 0.0))
    ry = np.sqrt(thr * np.maximum(cv[:, 2], 0.0))
    # pixel j has centre j + 0.5; BOX_SLACK_PX of slack on each side absorbs rounding (the clip,
    # just outside the image, only keeps huge extents finite before the int cast).
    s, lo = BOX_SLACK_PX, -(BOX_SLACK_PX + 1.0)
    x0 = np.floor(np.clip(m[:, 0] - rx - 0.5, lo, width - lo)) - s
    x1 = np.ceil(np.clip(m[:, 0] + rx - 0.5, lo, width - lo)) + s
    y0 = np.floor(np.clip(m[:, 1] - ry - 0.5, lo, height - lo)) - s
    y1 = np.ceil(np.clip(m[:, 1] + ry - 0.5, lo, height - lo)) + s
    box = np.stack(
        [
            np.maximum(x0, 0),
            np.minimum(x1, width - 1),
            np.maximum(y0, 0),
            np.minimum(y1, height - 1),
        ],
        axis=1,
    ).astype(np.int64)
    bad = ~np.isfinite(rx) | ~np.isfinite(ry)  # NaN extents cannot be bounded: cover the image
    box[bad] = [0, width - 1, 0, height - 1]
    out[keep] = box
    return out
