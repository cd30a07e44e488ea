"""The chained parts' world transforms, forward and backward in one numba pass each.

[`chain_transforms`][physgs.models.chain.chain_transforms] composes each part's own rotation
with its parent's, one depth of the tree at a time. As torch ops that is ~15 small ops a depth
(indexing, 3x3 products, out-of-place copies, a quaternion product) and their backward: on the
chained prior's trees (ten or more depths) ~1-3 ms a call, twice an iteration for the prior
posed at frame 0, most of it per-op overhead on [K <= 96] rows. Here it is one loop over the
parts each way, parents first (parent[p] < p) and back in reverse, so every part's gradient has
gathered its children's before it passes its own on. Arithmetic is float64 inside; results come
back in the inputs' dtype.

The recursion (chain.py's module docstring): with G_p = R_p - I the part's own rotation,
qo_p its quaternion and q = parent(p),

    E_p = E_q + G_p + E_q G_p,   u_p = u_q + E_q (c_p - c_q),   q_p = q_q * qo_p,

and E_p = G_p, u_p = 0, q_p = qo_p at a root.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import torch

from physgs.numpy_bridge import float64_array, tensor_like
from physgs.rotations import hamilton, hamilton_vjp


@nb.njit(cache=True, inline="always")
def _mm(A, B, tA, tB):  # pragma: no cover - compiled
    """op(A) op(B) for 3x3 arrays, op the transpose where tA / tB (spelled out: np.dot on 3x3
    goes through BLAS)."""
    out = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for k in range(3):
                acc += (A[k, i] if tA else A[i, k]) * (B[j, k] if tB else B[k, j])
            out[i, j] = acc
    return out


@nb.njit(cache=True, inline="always")
def _own(axis, theta, p):  # pragma: no cover - compiled
    """Part p's own rotation: (G = R - I, Kx the axis' cross-product matrix, KK = Kx Kx, sin,
    cos), the arrays [3, 3]."""
    x, y, z = axis[p, 0], axis[p, 1], axis[p, 2]
    s = math.sin(theta[p])
    c = math.cos(theta[p])
    Kx = np.zeros((3, 3))
    Kx[0, 1], Kx[0, 2], Kx[1, 0], Kx[1, 2], Kx[2, 0], Kx[2, 1] = -z, y, z, -x, -y, x
    KK = _mm(Kx, Kx, False, False)
    G = s * Kx + (1.0 - c) * KK
    return G, Kx, KK, s, c


@nb.njit(cache=True)
def _forward(axis, theta, pivot, parent, E, u, q):  # pragma: no cover - compiled
    """E [K, 3, 3], u [K, 3], q [K, 4] (written) from axis [K, 3], theta [K], pivot [K, 3] and
    parent [K] (-1 at a root, parent[p] < p), all float64 but parent."""
    for p in range(axis.shape[0]):
        G, _, _, _, _ = _own(axis, theta, p)
        h = 0.5 * theta[p]
        ow, sh = math.cos(h), math.sin(h)
        ox, oy, oz = sh * axis[p, 0], sh * axis[p, 1], sh * axis[p, 2]
        a = parent[p]
        if a < 0:
            E[p] = G
            u[p] = 0.0
            q[p, 0], q[p, 1], q[p, 2], q[p, 3] = ow, ox, oy, oz
            continue
        Eq = E[a]
        E[p] = Eq + G + _mm(Eq, G, False, False)
        for i in range(3):
            u[p, i] = u[a, i] + (
                Eq[i, 0] * (pivot[p, 0] - pivot[a, 0])
                + Eq[i, 1] * (pivot[p, 1] - pivot[a, 1])
                + Eq[i, 2] * (pivot[p, 2] - pivot[a, 2])
            )
        w, x, y, z = hamilton((q[a, 0], q[a, 1], q[a, 2], q[a, 3]), (ow, ox, oy, oz))
        q[p, 0], q[p, 1], q[p, 2], q[p, 3] = w, x, y, z


@nb.njit(cache=True)
def _backward(
    axis, theta, pivot, parent, E, q, gE, gu, gq, g_axis, g_theta, g_pivot
):  # pragma: no cover - compiled
    """Gradients w.r.t. axis, theta and pivot (written) from those w.r.t. E, u and q (gE, gu,
    gq: overwritten as accumulators), with E and q the forward's outputs."""
    g_axis[:] = 0.0
    g_theta[:] = 0.0
    g_pivot[:] = 0.0
    for p in range(axis.shape[0] - 1, -1, -1):  # children (p' > p) have passed theirs on
        G, Kx, KK, s, c = _own(axis, theta, p)
        h = 0.5 * theta[p]
        ow, sh = math.cos(h), math.sin(h)
        ox, oy, oz = sh * axis[p, 0], sh * axis[p, 1], sh * axis[p, 2]
        gEp = gE[p]
        hw, hx, hy, hz = gq[p, 0], gq[p, 1], gq[p, 2], gq[p, 3]
        a = parent[p]
        if a < 0:
            gG = gEp.copy()  # E_p = G_p
            gow, gox, goy, goz = hw, hx, hy, hz
        else:
            Eq = E[a]
            # E_p = E_q + G + E_q G
            gG = gEp + _mm(Eq, gEp, True, False)
            gE[a] += gEp + _mm(gEp, G, False, True)
            # u_p = u_q + E_q d, d = c_p - c_q
            d0 = pivot[p, 0] - pivot[a, 0]
            d1 = pivot[p, 1] - pivot[a, 1]
            d2 = pivot[p, 2] - pivot[a, 2]
            for i in range(3):
                g = gu[p, i]
                gu[a, i] += g
                gE[a, i, 0] += g * d0
                gE[a, i, 1] += g * d1
                gE[a, i, 2] += g * d2
            for j in range(3):
                gd = Eq[0, j] * gu[p, 0] + Eq[1, j] * gu[p, 1] + Eq[2, j] * gu[p, 2]
                g_pivot[p, j] += gd
                g_pivot[a, j] -= gd
            # q_p = q_q * qo_p
            gqa, go = hamilton_vjp(
                (q[a, 0], q[a, 1], q[a, 2], q[a, 3]), (ow, ox, oy, oz), (hw, hx, hy, hz)
            )
            gow, gox, goy, goz = go
            for i in range(4):
                gq[a, i] += gqa[i]
        # G = s Kx + (1 - c) Kx Kx
        gt = 0.0
        for i in range(3):
            for j in range(3):
                gt += gG[i, j] * (c * Kx[i, j] + s * KK[i, j])
        gK = s * gG + (1.0 - c) * (_mm(gG, Kx, False, True) + _mm(Kx, gG, True, False))
        g_axis[p, 0] += gK[2, 1] - gK[1, 2]
        g_axis[p, 1] += gK[0, 2] - gK[2, 0]
        g_axis[p, 2] += gK[1, 0] - gK[0, 1]
        # qo = (cos(theta / 2), sin(theta / 2) axis)
        gt += 0.5 * (-sh * gow + ow * (axis[p, 0] * gox + axis[p, 1] * goy + axis[p, 2] * goz))
        g_axis[p, 0] += sh * gox
        g_axis[p, 1] += sh * goy
        g_axis[p, 2] += sh * goz
        g_theta[p] = gt


class _ChainTransforms(torch.autograd.Function):
    @staticmethod
    def forward(ctx, axis, theta, pivot, parent):
        a, t, c = (float64_array(x) for x in (axis, theta, pivot))
        K = a.shape[0]
        E, u, q = np.empty((K, 3, 3)), np.empty((K, 3)), np.empty((K, 4))
        _forward(a, t, c, parent, E, u, q)
        ctx.save_for_backward(axis, theta, pivot)
        ctx.parent, ctx.E, ctx.q = parent, E, q
        return tensor_like(E, axis), tensor_like(u, axis), tensor_like(q, axis)

    @staticmethod
    def backward(ctx, gE, gu, gq):
        axis, theta, pivot = ctx.saved_tensors
        K = axis.shape[0]

        def acc(g, shape):  # a writable float64 accumulator (zeros where no gradient came)
            return np.zeros(shape) if g is None else np.array(float64_array(g), copy=True)

        out = (np.empty((K, 3)), np.empty(K), np.empty((K, 3)))
        _backward(
            *(float64_array(x) for x in (axis, theta, pivot)),
            ctx.parent,
            ctx.E,
            ctx.q,
            acc(gE, (K, 3, 3)),
            acc(gu, (K, 3)),
            acc(gq, (K, 4)),
            *out,
        )
        grads = [tensor_like(g, like) for g, like in zip(out, (axis, theta, pivot))]
        return (*(g if need else None for g, need in zip(grads, ctx.needs_input_grad)), None)


def parent_of_levels(levels, K: int) -> np.ndarray:
    """The parent array [K] int64 (-1 at the roots) that
    [`depth_levels`][physgs.models.chain.depth_levels] was built from.

    Args:
        levels (list[tuple[np.ndarray, np.ndarray]]): ``(parts, parents)`` per depth.
        K: the number of parts.

    Returns:
        (np.ndarray): [K] int64.
    """
    parent = np.full(K, -1, dtype=np.int64)
    for idx, par in levels:
        parent[idx] = par
    return parent


def fused_chain_transforms(
    axis: torch.Tensor, theta: torch.Tensor, pivot: torch.Tensor, parent: np.ndarray
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """[`chain_transforms`][physgs.models.chain.chain_transforms] in one numba pass each way,
    on the CPU; differentiable in axis, theta and pivot.

    Args:
        axis: [K, 3] unit swing axes.
        theta: [K] own angles, rad.
        pivot: [K, 3] canonical pivots, world units.
        parent: [K] int64 each part's parent, -1 at a root, parent[p] < p.

    Returns:
        ``(E [K, 3, 3], u [K, 3], q [K, 4])`` as chain_transforms, in axis' dtype.
    """
    return _ChainTransforms.apply(axis, theta, pivot, parent)
