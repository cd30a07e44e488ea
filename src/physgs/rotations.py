"""Rotations, in one leaf module: quaternions (w, x, y, z, acting on column vectors), their
Hamilton product, axis-angle and Rodrigues rotations and quaternion -> matrix, as torch ops
(differentiable, any device) and as numba scalar twins for the compiled kernels
(``models/part_transform``, ``models/chain_kernel``, ``render/kernels``).

Quaternions need not be unit where a function normalises (``quat_to_rotmat``); the helpers that
build rotations return unit quaternions. Imports nothing of physgs (a leaf).
"""

from __future__ import annotations

import numba as nb
import torch

#: Floor on a quaternion's norm before normalising: a zero quaternion gives the identity
#: rotation instead of NaN (the rasterizer's projection, torch and numba alike).
QUAT_NORM_EPS = 1e-12


# ---- torch ------------------------------------------------------------------------------------
def quat_multiply(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Hamilton product a * b of quaternions [..., 4] (w, x, y, z); rotation b first, then a.

    Args:
        a: [..., 4] quaternions (w, x, y, z).
        b: [..., 4] quaternions, broadcast against ``a``.

    Returns:
        [..., 4] the products (unit when both are unit).
    """
    aw, ax, ay, az = a.unbind(-1)
    bw, bx, by, bz = b.unbind(-1)
    return torch.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        dim=-1,
    )


def axis_angle_quat(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    """Unit quaternions [..., 4] for rotations by ``angle`` [...] rad about unit ``axis`` [..., 3].

    Args:
        axis: [..., 3] unit axes.
        angle: [...] angles, rad.

    Returns:
        [..., 4] quaternions (w, x, y, z).
    """
    half = 0.5 * angle
    return torch.cat([torch.cos(half)[..., None], torch.sin(half)[..., None] * axis], dim=-1)


def rodrigues_minus_identity(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    """R - I [..., 3, 3] for rotations by ``angle`` [...] rad about unit ``axis`` [..., 3].

    Kept apart from I so that a zero angle gives exactly zero (and small angles lose no digits).

    Args:
        axis: [..., 3] unit axes.
        angle: [...] angles, rad.

    Returns:
        [..., 3, 3] R - I.
    """
    x, y, z = axis.unbind(-1)
    zero = torch.zeros_like(x)
    Kx = torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], -1).reshape(axis.shape[:-1] + (3, 3))
    s = torch.sin(angle)[..., None, None]
    c = torch.cos(angle)[..., None, None]
    return s * Kx + (1 - c) * (Kx @ Kx)


def rodrigues(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    """Rotation matrices [..., 3, 3] by ``angle`` [...] rad about unit ``axis`` [..., 3].

    Args:
        axis: [..., 3] unit axes.
        angle: [...] angles, rad.

    Returns:
        [..., 3, 3] rotation matrices.
    """
    return torch.eye(3, dtype=axis.dtype, device=axis.device) + rodrigues_minus_identity(
        axis, angle
    )


def quat_to_rotmat(quats: torch.Tensor) -> torch.Tensor:
    """Rotation matrices of quaternions, normalised here.

    The package's one torch implementation (the numba kernels' scalar twin: ``quat_rotmat``).
    A zero quaternion gives the identity.

    Args:
        quats: [..., 4] quaternions (w, x, y, z), any norm.

    Returns:
        [..., 3, 3] rotation matrices, same dtype and device.
    """
    q = quats / quats.norm(dim=-1, keepdim=True).clamp_min(QUAT_NORM_EPS)
    w, x, y, z = q.unbind(-1)
    return torch.stack(
        [
            1 - 2 * (y * y + z * z),
            2 * (x * y - w * z),
            2 * (x * z + w * y),
            2 * (x * y + w * z),
            1 - 2 * (x * x + z * z),
            2 * (y * z - w * x),
            2 * (x * z - w * y),
            2 * (y * z + w * x),
            1 - 2 * (x * x + y * y),
        ],
        dim=-1,
    ).reshape(q.shape[:-1] + (3, 3))


# ---- numba scalar twins (compiled into the kernels) --------------------------------------------
@nb.njit(cache=True, inline="always")
def hamilton(a, b):  # pragma: no cover - compiled
    """The Hamilton product a * b of two quaternions (rotation b first, then a).

    Args:
        a (tuple[float, float, float, float]): (w, x, y, z).
        b (tuple[float, float, float, float]): (w, x, y, z).

    Returns:
        (tuple[float, float, float, float]): a * b as (w, x, y, z).
    """
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@nb.njit(cache=True, inline="always")
def hamilton_vjp(a, b, h):  # pragma: no cover - compiled
    """The gradients of <h, a * b> w.r.t. a and b: the product is bilinear, so each is its
    matrix in the other factor, transposed, applied to h.

    Args:
        a (tuple[float, float, float, float]): (w, x, y, z), the left factor.
        b (tuple[float, float, float, float]): (w, x, y, z), the right factor.
        h (tuple[float, float, float, float]): (w, x, y, z), the gradient w.r.t. the product.

    Returns:
        (tuple[tuple, tuple]): (gradient w.r.t. a, gradient w.r.t. b), each (w, x, y, z).
    """
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    hw, hx, hy, hz = h
    ga = (
        bw * hw + bx * hx + by * hy + bz * hz,
        -bx * hw + bw * hx - bz * hy + by * hz,
        -by * hw + bz * hx + bw * hy - bx * hz,
        -bz * hw - by * hx + bx * hy + bw * hz,
    )
    gb = (
        aw * hw + ax * hx + ay * hy + az * hz,
        -ax * hw + aw * hx + az * hy - ay * hz,
        -ay * hw - az * hx + aw * hy + ax * hz,
        -az * hw + ay * hx - ax * hy + aw * hz,
    )
    return ga, gb


@nb.njit(cache=True, inline="always")
def quat_rotmat(qw, qx, qy, qz, Rq):  # pragma: no cover - compiled
    """A unit quaternion's rotation matrix, written in place (``quat_to_rotmat``'s scalar twin).

    Args:
        qw (float): w of a unit quaternion.
        qx (float): x.
        qy (float): y.
        qz (float): z.
        Rq (np.ndarray): [3, 3] float64, overwritten with the rotation matrix.
    """
    Rq[0, 0] = 1 - 2 * (qy * qy + qz * qz)
    Rq[0, 1] = 2 * (qx * qy - qw * qz)
    Rq[0, 2] = 2 * (qx * qz + qw * qy)
    Rq[1, 0] = 2 * (qx * qy + qw * qz)
    Rq[1, 1] = 1 - 2 * (qx * qx + qz * qz)
    Rq[1, 2] = 2 * (qy * qz - qw * qx)
    Rq[2, 0] = 2 * (qx * qz - qw * qy)
    Rq[2, 1] = 2 * (qy * qz + qw * qx)
    Rq[2, 2] = 1 - 2 * (qx * qx + qy * qy)
