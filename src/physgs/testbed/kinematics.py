"""Forward kinematics of the bone tree: each bone rotates by its angle theta_b about the tree's
swing axis through its own head; a child moves rigidly with its parent.

All rotations share one world axis, so a bone's world rotation is a rotation by the sum of the
angles along its chain; its head is carried by the parent's transform.
"""

from __future__ import annotations

import numpy as np


def swing_axis(direction_deg: float) -> np.ndarray:
    """Unit horizontal axis perpendicular to the mean wind.

    The wind blows along w = (sin d, cos d, 0), d measured from the training camera's viewing axis
    (+y, camera at azimuth 0). The axis is z x w, so a positive angle tilts a bone downwind.

    Args:
        direction_deg: d, the mean wind's direction, degrees.

    Returns:
        [3] the unit axis (world).
    """
    d = np.deg2rad(direction_deg)
    w = np.array([np.sin(d), np.cos(d), 0.0])
    return np.cross([0.0, 0.0, 1.0], w)


def rotate(v: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotate vectors v [..., 3] about unit axis [3] by angle [...] (rad), Rodrigues.

    Args:
        v: [..., 3] vectors.
        axis: [3] unit rotation axis.
        angle: [...] angles, rad (broadcast against v's leading axes).

    Returns:
        [..., 3] the rotated vectors.
    """
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return v * c + (v @ K.T) * s + axis * (v @ axis)[..., None] * (1.0 - c)  # v @ K.T = axis x v


def bone_depth(parent: np.ndarray) -> np.ndarray:
    """Depth [B] of each bone in its tree (root = 0); raises on a cycle or a bad parent index.

    Args:
        parent: [B] each bone's parent index, -1 for a root.

    Returns:
        [B] int depths.

    Raises:
        ValueError: when ``parent`` is not a forest (a cycle or an index out of range).
    """
    B = len(parent)
    depth = np.full(B, -1)
    for b in range(B):
        chain, p = [], b
        while p != -1 and depth[p] < 0:
            chain.append(p)
            if len(chain) > B or not -1 <= parent[p] < B:
                raise ValueError("bone_parent is not a tree (cycle or index out of range)")
            p = parent[p]
        d = -1 if p == -1 else depth[p]
        for q in reversed(chain):
            d += 1
            depth[q] = d
    return depth


def cumulative_angle(parent: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """World rotation angle of each bone, the sum of theta along its chain: [..., B] (rad).

    Args:
        parent: [B] each bone's parent index, -1 for a root.
        theta: [..., B] each bone's own angle, rad.

    Returns:
        [..., B] cumulative angles, rad (a new array).

    Raises:
        ValueError: when ``parent`` is not a forest.
    """
    depth = bone_depth(parent)
    Theta = np.array(theta, dtype=np.float64)
    for d in range(1, depth.max() + 1):
        idx = np.nonzero(depth == d)[0]
        Theta[..., idx] += Theta[..., parent[idx]]
    return Theta


def pose_bones(
    head: np.ndarray, tail: np.ndarray, parent: np.ndarray, axis: np.ndarray, theta: np.ndarray
):
    """Posed bones for angles theta [..., B] (rad).

    Args:
        head: [B, 3] rest bone heads, m.
        tail: [B, 3] rest bone tails, m.
        parent: [B] each bone's parent index, -1 for a root.
        axis: [3] the unit swing axis every bone rotates about.
        theta: [..., B] each bone's own angle, rad.

    Returns:
        (tuple[np.ndarray, np.ndarray, np.ndarray]): ``(Theta, heads, tails)``: Theta [..., B]
            cumulative angle (rad), heads [..., B, 3] and tails [..., B, 3] in metres.

    Raises:
        ValueError: when ``parent`` is not a forest.
    """
    theta = np.asarray(theta, dtype=np.float64)
    depth = bone_depth(parent)
    Theta = np.zeros_like(theta)
    H = np.broadcast_to(head, theta.shape + (3,)).copy()
    for d in range(depth.max() + 1):
        idx = np.nonzero(depth == d)[0]
        p = parent[idx]
        if d == 0:
            Theta[..., idx] = theta[..., idx]
            continue
        Theta[..., idx] = theta[..., idx] + Theta[..., p]
        H[..., idx, :] = H[..., p, :] + rotate(head[idx] - head[p], axis, Theta[..., p])
    T = H + rotate(tail - head, axis, Theta)
    return Theta, H, T


def pose_points(
    points: np.ndarray,
    point_bone: np.ndarray,
    head: np.ndarray,
    tail: np.ndarray,
    parent: np.ndarray,
    axis: np.ndarray,
    theta: np.ndarray,
) -> np.ndarray:
    """Rigidly skinned points [N, 3] (rest pose, m) posed by theta [..., B] -> [..., N, 3].

    Args:
        points: [N, 3] rest positions, m.
        point_bone: [N] each point's bone.
        head: [B, 3] rest bone heads, m.
        tail: [B, 3] rest bone tails, m.
        parent: [B] each bone's parent index, -1 for a root.
        axis: [3] the unit swing axis.
        theta: [..., B] each bone's own angle, rad.

    Returns:
        [..., N, 3] posed positions, m.
    """
    Theta, H, _ = pose_bones(head, tail, parent, axis, theta)
    return H[..., point_bone, :] + rotate(points - head[point_bone], axis, Theta[..., point_bone])


def pose_vertices(truth, theta_b: np.ndarray) -> np.ndarray:
    """Mesh vertices posed by bone angles.

    Args:
        truth (Truth): a [`Truth`][physgs.testbed.dataset.Truth] (or anything with its bone fields).
        theta_b: [..., B] bone angles, rad.

    Returns:
        [..., N, 3] vertex positions, m.
    """
    return pose_points(
        truth.rest_vertices,
        truth.vertex_bone,
        truth.bone_head,
        truth.bone_tail,
        truth.bone_parent,
        truth.swing_axis,
        theta_b,
    )


def pose_gaussians(truth, theta_b: np.ndarray) -> np.ndarray:
    """The observed Gaussians posed by bone angles, in Gaussian order.

    ``pose_vertices`` permuted by ``truth.gaussian_vertex`` (the order of ``canonical_xyz``). This
    is the ground-truth motion of each Gaussian (the true-motion reference moves the canonical
    Gaussians with it).

    Args:
        truth (Truth): the dataset's ground truth.
        theta_b: [..., B] bone angles, rad.

    Returns:
        [..., N, 3] Gaussian centres, m.
    """
    return pose_vertices(truth, theta_b)[..., np.asarray(truth.gaussian_vertex), :]
