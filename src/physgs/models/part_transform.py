"""Gaussians moved by their parts' rigid transforms, forward and backward in one numba pass each.

Every oscillator prior ends its deformation the same way: each Gaussian i of part k = labels[i]
gets

    means'_i = means_i + t_k + M_k (means_i - c_k),    quats'_i = Q_k * quats_i  (Hamilton),

with M_k a rotation minus the identity (kept apart from I so that a zero angle is exact), c_k a
centre, t_k a translation and Q_k the rotation's quaternion: one rotation about a pivot
([`rotate_parts`][physgs.models.gaussians.rotate_parts]: t = 0), a chain of them
([`chain_deform`][physgs.models.chain.chain_deform]) or a chain relative to frame 0
([`chain_deform_from`][physgs.models.chain.chain_deform_from]). As torch ops this is a gather,
a batched 3x3 matmul, a quaternion product and their backward: some forty small ops on N
Gaussians, ~1.5 ms a training iteration on the medium tree's 6,000 (most of it per-op
overhead). Here it is one loop over N each way; the per-part gradients are summed in Gaussian
order (deterministic). Arithmetic is float64 inside; results come back in the inputs' dtype.
"""

from __future__ import annotations

import numba as nb
import numpy as np
import torch

from physgs.numpy_bridge import float64_array, tensor_like
from physgs.rotations import hamilton, hamilton_vjp, quat_multiply


@nb.njit(cache=True, inline="always")
def _row4(a, i):  # pragma: no cover - compiled
    """Row i of a [*, 4] array as four float64 scalars."""
    return float(a[i, 0]), float(a[i, 1]), float(a[i, 2]), float(a[i, 3])


@nb.njit(cache=True)
def _forward(means, quats, labels, M, c, t, Q, out_means, out_quats):  # pragma: no cover
    for i in range(means.shape[0]):
        k = labels[i]
        r0 = float(means[i, 0]) - c[k, 0]
        r1 = float(means[i, 1]) - c[k, 1]
        r2 = float(means[i, 2]) - c[k, 2]
        for a in range(3):
            out_means[i, a] = (
                float(means[i, a]) + t[k, a] + (M[k, a, 0] * r0 + M[k, a, 1] * r1 + M[k, a, 2] * r2)
            )
        w, x, y, z = hamilton(_row4(Q, k), _row4(quats, i))
        out_quats[i, 0], out_quats[i, 1], out_quats[i, 2], out_quats[i, 3] = w, x, y, z


@nb.njit(cache=True)
def _backward(
    means, quats, labels, M, c, Q, g_nm, g_nq, g_means, g_quats, g_M, g_c, g_t, g_Q
):  # pragma: no cover - compiled
    g_M[:] = 0.0
    g_t[:] = 0.0
    g_Q[:] = 0.0
    for i in range(means.shape[0]):
        k = labels[i]
        g0 = float(g_nm[i, 0])
        g1 = float(g_nm[i, 1])
        g2 = float(g_nm[i, 2])
        g = (g0, g1, g2)
        r = (
            float(means[i, 0]) - c[k, 0],
            float(means[i, 1]) - c[k, 1],
            float(means[i, 2]) - c[k, 2],
        )
        for b in range(3):  # (I + M)^T g
            g_means[i, b] = g[b] + (M[k, 0, b] * g0 + M[k, 1, b] * g1 + M[k, 2, b] * g2)
            g_M[k, 0, b] += g0 * r[b]
            g_M[k, 1, b] += g1 * r[b]
            g_M[k, 2, b] += g2 * r[b]
        g_t[k, 0] += g0
        g_t[k, 1] += g1
        g_t[k, 2] += g2
        ga, gb = hamilton_vjp(_row4(Q, k), _row4(quats, i), _row4(g_nq, i))
        for a in range(4):
            g_quats[i, a] = gb[a]
            g_Q[k, a] += ga[a]
    # c enters as means - c: its gradient is -M^T (the sum of g over the part)
    for k in range(M.shape[0]):
        for b in range(3):
            g_c[k, b] = -(M[k, 0, b] * g_t[k, 0] + M[k, 1, b] * g_t[k, 1] + M[k, 2, b] * g_t[k, 2])


class _PartTransform(torch.autograd.Function):
    @staticmethod
    def forward(ctx, means, quats, labels, M, c, t, Q):
        m = means.detach().cpu().numpy()
        q = quats.detach().cpu().numpy()
        lab = np.ascontiguousarray(labels.detach().cpu().numpy(), dtype=np.int64)
        out_m = np.empty(m.shape, m.dtype)
        out_q = np.empty(q.shape, q.dtype)
        _forward(m, q, lab, *(float64_array(x) for x in (M, c, t, Q)), out_m, out_q)
        # saved as tensors: autograd then refuses a backward after an in-place edit of any
        ctx.save_for_backward(means, quats, labels, M, c, t, Q)
        return torch.from_numpy(out_m).to(means.device), torch.from_numpy(out_q).to(quats.device)

    @staticmethod
    def backward(ctx, g_means, g_quats):
        means, quats, labels, M, c, t, Q = ctx.saved_tensors
        m, q = means.detach().cpu().numpy(), quats.detach().cpu().numpy()
        lab = np.ascontiguousarray(labels.cpu().numpy(), dtype=np.int64)
        M64, c64, Q64 = float64_array(M), float64_array(c), float64_array(Q)
        g_nm = np.zeros(m.shape) if g_means is None else g_means.detach().cpu().numpy()  # [N, 3]
        g_nq = np.zeros(q.shape) if g_quats is None else g_quats.detach().cpu().numpy()
        K = M.shape[0]
        out = (
            np.empty(m.shape),
            np.empty(q.shape),
            np.empty((K, 3, 3)),
            np.empty((K, 3)),
            np.empty((K, 3)),
            np.empty((K, 4)),
        )
        _backward(
            m, q, lab, M64, c64, Q64, np.ascontiguousarray(g_nm), np.ascontiguousarray(g_nq), *out
        )
        grads = [tensor_like(g, like) for g, like in zip(out, (means, quats, M, c, t, Q))]
        grads.insert(2, None)  # labels
        # None where no gradient is asked for (rotate_parts' zero translation, a fixed pivot)
        return tuple(g if need else None for g, need in zip(grads, ctx.needs_input_grad))


def _transform_parts_torch(means, quats, labels, M, c, t, Q):
    """[`transform_parts`][physgs.models.part_transform.transform_parts] as torch ops, on any
    device with autograd through every op (the fused pass's reference in the tests)."""
    rel = (means - c[labels])[..., None]  # [N, 3, 1]
    new_means = means + t[labels] + (M[labels] @ rel)[..., 0]
    return new_means, quat_multiply(Q[labels], quats)


def transform_parts(
    means: torch.Tensor,
    quats: torch.Tensor,
    labels: torch.Tensor,
    M: torch.Tensor,
    c: torch.Tensor,
    t: torch.Tensor,
    Q: torch.Tensor,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Move each Gaussian by its part's transform: means + t + M (means - c), Q * quats.

    One numba pass forward and one backward on the CPU (differentiable w.r.t. every tensor but
    ``labels``); the same sums as torch ops on other devices.

    Args:
        means: [N, 3] positions, world units.
        quats: [N, 4] orientations (w, x, y, z).
        labels: [N] int, the part of each Gaussian, in [0, K).
        M: [K, 3, 3] each part's rotation minus the identity.
        c: [K, 3] the centre each part rotates about, world units.
        t: [K, 3] each part's translation after the rotation, world units.
        Q: [K, 4] each part's rotation as a quaternion (w, x, y, z).

    Returns:
        ``(means [N, 3], quats [N, 4])`` in the dtypes of ``means`` and ``quats``.

    Raises:
        ValueError: a label outside [0, K), or shapes that do not fit.
    """
    N, K = means.shape[0], M.shape[0]
    if (
        means.shape != (N, 3)
        or quats.shape != (N, 4)
        or labels.shape != (N,)
        or M.shape != (K, 3, 3)
        or c.shape != (K, 3)
        or t.shape != (K, 3)
        or Q.shape != (K, 4)
    ):
        raise ValueError(
            "transform_parts: expected means [N, 3], quats [N, 4], labels [N], M [K, 3, 3], "
            f"c, t [K, 3], Q [K, 4]; got {tuple(means.shape)}, {tuple(quats.shape)}, "
            f"{tuple(labels.shape)}, {tuple(M.shape)}, {tuple(c.shape)}, {tuple(t.shape)}, "
            f"{tuple(Q.shape)}"
        )
    if N and (int(labels.min()) < 0 or int(labels.max()) >= K):
        raise ValueError(
            f"transform_parts: labels must lie in [0, {K}); got "
            f"[{int(labels.min())}, {int(labels.max())}]"
        )
    if means.device.type != "cpu":
        return _transform_parts_torch(means, quats, labels, M, c, t, Q)
    return _PartTransform.apply(means, quats, labels, M, c, t, Q)
