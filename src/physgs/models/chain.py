"""Forward kinematics of chained rigid parts: each part rotates about its own pivot and rides on
its parent (the testbed's own skinning, [`physgs.testbed.kinematics`][], with one axis per part).

Part p's map of canonical space is T_p = T_parent(p) o Rot_p, Rot_p(x) = c_p + R_p (x - c_p)
the rotation by theta_p about axis a_p through its canonical pivot c_p (a_p and c_p are given
in the canonical frame; the ancestors carry them). So a Gaussian of part p moves by the product
of the rotations of p and of every ancestor, each about its own pivot as carried by the
ancestors. Written as displacements, so that zero angles give exactly zero motion:

    T_p(x) = x + u_p + E_p (x - c_p),   E_p = Rw_p - I,   u_p = T_parent(c_p) - c_p,
    E_p = E_q + G_p + E_q G_p,   u_p = u_q + E_q (c_p - c_q),   q = parent(p), G_p = R_p - I,

with E = G and u = 0 at the root. Parts must be numbered parents first (parent[p] < p), as
[`physgs.models.topology`][] numbers them: on the CPU one pass over them in that order
([`physgs.models.chain_kernel`][]), on other devices one vectorised step per tree depth.
"""

from __future__ import annotations

import numpy as np
import torch

from physgs.models.chain_kernel import fused_chain_transforms, parent_of_levels
from physgs.models.gaussians import axis_angle_quat, quat_multiply, rodrigues_minus_identity
from physgs.models.part_transform import transform_parts
from physgs.models.topology import part_depth


def depth_levels(parent) -> list[tuple[np.ndarray, np.ndarray]]:
    """[(parts [M] int64, their parents [M] int64)] per depth 1, 2, ... for parent [K] (root -1,
    parent[p] < p); raises ValueError on any other parent array (so no cycle is accepted).

    Args:
        parent (ArrayLike): [K] each part's parent, -1 for part 0, parent[p] < p.

    Returns:
        One ``(parts, parents)`` pair per depth from 1 down, each [M] int64.

    Raises:
        ValueError: for parents not numbered first.
    """
    parent = np.asarray(parent, dtype=np.int64)
    depth = part_depth(parent)
    out = []
    for d in range(1, int(depth.max()) + 1 if len(depth) else 1):
        idx = np.nonzero(depth == d)[0]
        out.append((idx, parent[idx]))
    return out


def chain_transforms(
    axis: torch.Tensor, theta: torch.Tensor, pivot: torch.Tensor, levels
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """World transforms of chained parts at one instant.

    Differentiable in axis, theta and pivot: one numba pass each way on the CPU
    ([`fused_chain_transforms`][physgs.models.chain_kernel.fused_chain_transforms], float64
    inside), the same sums as torch ops, one depth at a time, on other devices.

    Args:
        axis: [K, 3] unit swing axes.
        theta: [K] own angles, rad.
        pivot: [K, 3] canonical pivots, world units.
        levels (list[tuple[np.ndarray, np.ndarray]]):
            [`depth_levels`][physgs.models.chain.depth_levels] of the parents.

    Returns:
        ``(E, u, q)``: E [K, 3, 3] = world rotation - I, u [K, 3] displacement of each part's
            pivot by its ancestors (world units), q [K, 4] world rotation quaternions (w, x, y, z).
    """
    if axis.device.type == "cpu":
        return fused_chain_transforms(axis, theta, pivot, parent_of_levels(levels, axis.shape[0]))
    return _chain_transforms_torch(axis, theta, pivot, levels)


def _chain_transforms_torch(axis, theta, pivot, levels):
    """[`chain_transforms`][physgs.models.chain.chain_transforms] as torch ops with autograd
    through each (other devices; the fused pass's reference in the tests)."""
    G = rodrigues_minus_identity(axis, theta)  # [K, 3, 3] own rotation - I
    qo = axis_angle_quat(axis, theta)  # [K, 4] own rotation
    E, u, q = G, torch.zeros_like(pivot), qo
    for idx_np, par_np in levels:
        idx = torch.as_tensor(idx_np, device=axis.device)
        par = torch.as_tensor(par_np, device=axis.device)
        Eq, Gp = E[par], G[idx]  # [M, 3, 3]
        # out-of-place index_copy: autograd sees every level's write
        E = E.index_copy(0, idx, Eq + Gp + Eq @ Gp)
        u = u.index_copy(0, idx, u[par] + (Eq @ (pivot[idx] - pivot[par])[..., None])[..., 0])
        q = q.index_copy(0, idx, quat_multiply(q[par], qo[idx]))
    return E, u, q


def chain_deform(
    means: torch.Tensor,
    quats: torch.Tensor,
    labels: torch.Tensor,
    axis: torch.Tensor,
    theta: torch.Tensor,
    pivot: torch.Tensor,
    levels,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Move Gaussians by their parts' chained transforms.

    Args:
        means: [N, 3] positions, world units.
        quats: [N, 4] orientations (w, x, y, z).
        labels: [N] part of each Gaussian.
        axis: [K, 3] unit swing axes.
        theta: [K] own angles, rad.
        pivot: [K, 3] pivots, world units.
        levels (list[tuple[np.ndarray, np.ndarray]]):
            [`depth_levels`][physgs.models.chain.depth_levels] of the parents.

    Returns:
        ``(means [N, 3], quats [N, 4])``; exactly the input at theta = 0.
    """
    E, u, q = chain_transforms(axis, theta, pivot, levels)
    return transform_parts(means, quats, labels, E, pivot, u, q)


def chain_deform_from(
    means: torch.Tensor,
    quats: torch.Tensor,
    labels: torch.Tensor,
    axis: torch.Tensor,
    theta: torch.Tensor,
    theta0: torch.Tensor,
    pivot: torch.Tensor,
    levels,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Move Gaussians posed at angles ``theta0`` to angles ``theta``: T(theta) o T(theta0)^-1.

    For a canonical set that is the pose at angles theta0 (the recorded frame 0), not the rest
    pose: frame 0's chained transform is undone (its rest pose is T_p(theta0)^-1 of it), then
    the transform at theta applied. With T_p(x) = c_p + u_p + Rw_p (x - c_p)
    ([`chain_transforms`][physgs.models.chain.chain_transforms]):

        T_p(theta) T_p(theta0)^-1 (x) = x + (u_p - u0_p) + (Rw_p Rw0_p^T - I)(x - c_p - u0_p).

    Differentiable in axis, both angles and pivot.

    Args:
        means: [N, 3] positions posed at theta0, world units.
        quats: [N, 4] orientations (w, x, y, z).
        labels: [N] part of each Gaussian.
        axis: [K, 3] unit swing axes.
        theta: [K] target own angles, rad.
        theta0: [K] own angles the input is posed at, rad.
        pivot: [K, 3] rest-pose pivots, world units.
        levels (list[tuple[np.ndarray, np.ndarray]]):
            [`depth_levels`][physgs.models.chain.depth_levels] of the parents.

    Returns:
        ``(means [N, 3], quats [N, 4])``; the input (to rounding) at theta = theta0.
    """
    E, u, q = chain_transforms(axis, theta, pivot, levels)  # [K, 3, 3], [K, 3], [K, 4]
    E0, u0, q0 = chain_transforms(axis, theta0, pivot, levels)
    # Rw Rw0^T - I = E + E0^T + E E0^T, kept apart from I as chain_transforms keeps E
    M = E + E0.transpose(-1, -2) + E @ E0.transpose(-1, -2)  # [K, 3, 3]
    q0_inv = q0 * torch.tensor([1.0, -1.0, -1.0, -1.0], dtype=q0.dtype, device=q0.device)
    return transform_parts(means, quats, labels, M, pivot + u0, u - u0, quat_multiply(q, q0_inv))
