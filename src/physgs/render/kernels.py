"""Numba kernels of the fast CPU rasterizer: tile binning, forward compositing, explicit backward.

Work layout: 16x16 tiles run in parallel (prange); inside a tile the Gaussians are visited front
to back ("Gaussian-major") and each one updates only the pixels of its conservative pixel box, so
the work is the summed footprint rather than pixels x candidates. Per pixel this is exactly the
3DGS recurrence (skip alpha < 1/255, stop before transmittance falls below 1e-4), because pixels
outside a box have alpha < 1/255 anyway. Arithmetic is float64 inside the kernels whatever the
input dtype; per-pixel float64 totals from the forward pass feed the backward pass, which needs
no reverse traversal: the light behind Gaussian i is (total - prefix up to i).

Determinism: every tile writes only its own pixels and its own rows of the per-(tile, Gaussian)
gradient buffer; a sequential loop then sums those rows per Gaussian in a fixed order. No atomics.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

# Module globals: numba freezes them into the compiled (and cached) kernels.
from physgs.render.constants import (
    ALPHA_MAX,
    ALPHA_MIN,
    BOX_SLACK_PX,
    FOOTPRINT_SLACK,
    INV_ALPHA_MIN,
    ROW_SPAN_TOL,
    T_MIN,
)
from physgs.rotations import QUAT_NORM_EPS, quat_rotmat

N_GRAD = 7  # per-pair gradient columns before colours: mx, my, conic a, b, c, opacity, depth
# Floating-point operations (compares and min included) per composited pixel-Gaussian pair, for
# D = 3 colour channels, counted off the inner pixel loops below: forward 11 + 2 D, backward
# 47 + 4 D (its alpha test, the colour/depth sums, dL/dalpha and the five geometry gradients).
FLOPS_PER_PAIR_FORWARD = 17
FLOPS_PER_PAIR_BACKWARD = 59


@nb.njit(cache=True)
def bin_tiles(boxes, order, tile, tiles_x, tiles_y):  # pragma: no cover - compiled
    """Tile lists of depth-sorted Gaussians.

    Tile t holds pair_gid[tile_start[t]:tile_start[t + 1]], in depth order; pair k may record up to
    row_start[k + 1] - row_start[k] pixel rows (its box's rows inside the tile) in the forward's row
    buffers, which the backward reads back.

    Args:
        boxes (np.ndarray): [N, 4] int64 (x0, x1, y0, y1) inclusive pixel ranges.
        order (np.ndarray): [M] int64 Gaussian ids sorted front to back, only ones whose box is
            non-empty.
        tile (int): tile side, px.
        tiles_x (int): tiles per image row.
        tiles_y (int): tiles per image column.

    Returns:
        (tuple[np.ndarray, np.ndarray, np.ndarray]): ``(tile_start [T + 1], pair_gid [P],
            row_start [P + 1])``, T = tiles_x x tiles_y, P (tile, Gaussian) pairs.
    """
    n_tiles = tiles_x * tiles_y
    start = np.zeros(n_tiles + 1, np.int64)
    span = np.empty((order.shape[0], 4), np.int64)  # tile ranges, one integer division each
    for k in range(order.shape[0]):
        g = order[k]
        for j in range(4):
            span[k, j] = boxes[g, j] // tile
        for ty in range(span[k, 2], span[k, 3] + 1):
            for tx in range(span[k, 0], span[k, 1] + 1):
                start[ty * tiles_x + tx + 1] += 1
    for t in range(n_tiles):
        start[t + 1] += start[t]
    cursor = start[:-1].copy()
    pair_gid = np.empty(start[n_tiles], np.int64)
    pair_rows = np.zeros(start[n_tiles] + 1, np.int64)
    for k in range(order.shape[0]):
        g = order[k]
        for ty in range(span[k, 2], span[k, 3] + 1):
            n_rows = min(boxes[g, 3], ty * tile + tile - 1) - max(boxes[g, 2], ty * tile) + 1
            for tx in range(span[k, 0], span[k, 1] + 1):
                t = ty * tiles_x + tx
                pair_gid[cursor[t]] = g
                pair_rows[cursor[t] + 1] = n_rows
                cursor[t] += 1
    for k in range(start[n_tiles]):
        pair_rows[k + 1] += pair_rows[k]
    return start, pair_gid, pair_rows


@nb.njit(cache=True, inline="always")
def _footprint(o):  # pragma: no cover - compiled
    """sigma = d^T conic d above which o exp(-sigma / 2) < 1/255, widened by FOOTPRINT_SLACK so
    rounding can only add pixels (which the exact alpha test then skips), never drop them."""
    if o * INV_ALPHA_MIN <= 1.0:
        return -1.0
    return 2.0 * math.log(INV_ALPHA_MIN * o) * (1.0 + FOOTPRINT_SLACK) + FOOTPRINT_SLACK


@nb.njit(cache=True, inline="always")
def _row_span(ca, cb, det, ica, thr, mx, dy, lo, hi):  # pragma: no cover - compiled
    """Pixel columns [x0, x1] of one row (offset dy px from the mean) where
    ca dx^2 + 2 cb dx dy + cc dy^2 <= thr, clipped to [lo, hi]; x0 > x1 when empty.
    det = ca cc - cb^2 and ica = 1 / ca are per-Gaussian (hoisted out of the row loop); the
    span's rounding is absorbed by ROW_SPAN_TOL and the exact alpha test."""
    disc = ca * thr - det * dy * dy
    if thr < 0.0 or disc < 0.0 or ca <= 0.0:
        return lo, lo - 1
    r = math.sqrt(disc)
    c0 = mx - 0.5 + (-cb * dy - r) * ica
    c1 = mx - 0.5 + (-cb * dy + r) * ica
    if not (c1 >= lo and c0 <= hi):  # also catches NaN
        return lo, lo - 1
    return max(lo, int(math.ceil(c0 - ROW_SPAN_TOL))), min(hi, int(math.floor(c1 + ROW_SPAN_TOL)))


@nb.njit(cache=True, inline="always")
def _rows(ca, det, thr, my, lo, hi):  # pragma: no cover - compiled
    """Pixel rows [y0, y1] (clipped to [lo, hi]) that can hold a pixel of the contour
    ca dx^2 + 2 cb dx dy + cc dy^2 <= thr: |dy| <= sqrt(thr ca / det) (where ``_row_span``'s
    discriminant is >= 0), widened by ROW_SPAN_TOL px. Tighter than the axis-aligned pixel box,
    which adds a pixel of slack on each side: for the trees' pixel-sized Gaussians it skips about
    half the rows the box holds. Rows it keeps that have no pixel get an empty span."""
    if thr < 0.0 or ca <= 0.0 or det <= 0.0:
        return lo, lo - 1
    e = math.sqrt(thr * ca / det) + ROW_SPAN_TOL
    if not (e < 1e18):  # NaN or huge: every row of the tile
        return lo, hi
    return max(lo, int(math.ceil(my - 0.5 - e))), min(hi, int(math.floor(my - 0.5 + e)))


@nb.njit(cache=True, inline="always")
def _row_gauss(ca, cb, cc, mx, dy, x0, step):  # pragma: no cover - compiled
    """exp(-sigma / 2) at the first pixel x0 of a row (offset dy px from the mean) and the factor
    r that steps it one pixel right: G(x + 1) = G(x) r, r(x + 1) = r(x) exp(-ca).

    sigma(dx) = ca dx^2 + 2 cb dx dy + cc dy^2 is quadratic in dx, so the ratio of neighbouring
    values is exp(-ca (dx + 1/2) - cb dy), itself a geometric sequence of ratio exp(-ca)
    (computed once per Gaussian): two exps per row instead of one per pixel. Within a span (at
    most one tile wide, inside the 1/255 contour) the product drifts by a few ulps per pixel,
    ~1e-14 relative, far below the 1e-12 the fast path keeps to the reference. forward and
    backward step identically, so their alpha tests agree bit for bit."""
    dx = x0 + 0.5 - mx
    sigma = ca * dx * dx + 2.0 * cb * dx * dy + cc * dy * dy
    # a one-pixel span never steps: skip its second exp
    return math.exp(-0.5 * sigma), math.exp(-ca * (dx + 0.5) - cb * dy) if step else 0.0


@nb.njit(cache=True, inline="always")
def _rgb(col):  # pragma: no cover - compiled
    """The first three channels of col [D] as scalars (zeros past D): the kernels' RGB path."""
    D = col.shape[0]
    return col[0] if D > 0 else 0.0, col[1] if D > 1 else 0.0, col[2] if D > 2 else 0.0


@nb.njit(cache=True)
def pixel_boxes(means2d, cov2d, opac, valid, width, height, boxes):  # pragma: no cover
    """Numba twin of [`pixel_bounds`][physgs.render.project.pixel_bounds] (the reference's binning;
    same formula, constants and clipping).

    One flat loop instead of some twenty numpy passes over N.

    Args:
        means2d (np.ndarray): [N, 2] projected centres, px.
        cov2d (np.ndarray): [N, 3] 2D covariances (a, b, c), px^2.
        opac (np.ndarray): [N] opacities.
        valid (np.ndarray): [N] bool, False for culled Gaussians.
        width (int): image width, px.
        height (int): image height, px.
        boxes (np.ndarray): [N, 4] int64, written: (x0, x1, y0, y1) inclusive pixel ranges, x0 > x1
            for a Gaussian that touches no pixel.
    """
    s = float(BOX_SLACK_PX)
    lo = -(BOX_SLACK_PX + 1.0)
    for i in range(means2d.shape[0]):
        boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3] = 1, 0, 1, 0
        o = opac[i]
        mx = means2d[i, 0]
        my = means2d[i, 1]
        if not (valid[i] and o * INV_ALPHA_MIN > 1.0 and math.isfinite(mx) and math.isfinite(my)):
            continue
        thr = 2.0 * math.log(INV_ALPHA_MIN * o)
        rx = math.sqrt(thr * max(cov2d[i, 0], 0.0))
        ry = math.sqrt(thr * max(cov2d[i, 2], 0.0))
        if not (math.isfinite(rx) and math.isfinite(ry)):  # cannot be bounded: the whole image
            boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3] = 0, width - 1, 0, height - 1
            continue
        x0 = math.floor(min(max(mx - rx - 0.5, lo), width - lo)) - s
        x1 = math.ceil(min(max(mx + rx - 0.5, lo), width - lo)) + s
        y0 = math.floor(min(max(my - ry - 0.5, lo), height - lo)) - s
        y1 = math.ceil(min(max(my + ry - 0.5, lo), height - lo)) + s
        boxes[i, 0] = int(max(x0, 0.0))
        boxes[i, 1] = int(min(x1, width - 1.0))
        boxes[i, 2] = int(max(y0, 0.0))
        boxes[i, 3] = int(min(y1, height - 1.0))


@nb.njit(parallel=True, cache=True)
def forward(
    means2d,
    conics,
    opac,
    colors,
    depths,
    bg,
    boxes,
    tile_start,
    pair_gid,
    row_start,
    tile,
    tiles_x,
    width,
    height,
    with_depth,
    out_rgb,
    out_alpha,
    out_depth,
    acc_c,
    acc_d,
    t_final,
    n_contrib,
    row_pix,
    row_gauss,
    n_rows,
):  # pragma: no cover - compiled
    """Composite front to back.

    Writes the image and float64 totals for the backward, and the rows it composited, so the
    backward need not find them again: pair k's rows are row_start[k] + [0, n_rows[k]).

    Args:
        means2d (np.ndarray): [N, 2] projected centres, px.
        conics (np.ndarray): [N, 3] inverse 2D covariances, px^-2.
        opac (np.ndarray): [N] opacities.
        colors (np.ndarray): [N, D] colours.
        depths (np.ndarray): [N] camera-space depths, world units.
        bg (np.ndarray): [D] background colour.
        boxes (np.ndarray): [N, 4] pixel boxes from
            [`pixel_boxes`][physgs.render.kernels.pixel_boxes].
        tile_start (np.ndarray): [T + 1] from [`bin_tiles`][physgs.render.kernels.bin_tiles].
        pair_gid (np.ndarray): [P] from ``bin_tiles``.
        row_start (np.ndarray): [P + 1] from ``bin_tiles``.
        tile (int): tile side, px.
        tiles_x (int): tiles per image row.
        width (int): image width W, px.
        height (int): image height H, px.
        with_depth (bool): accumulate the depth; False leaves out_depth and acc_d at 0 (a
            caller that asked for no depth: the backward then takes no depth gradient).
        out_rgb (np.ndarray): [H, W, D], written.
        out_alpha (np.ndarray): [H, W], written.
        out_depth (np.ndarray): [H, W] expected depth sum z a T, written.
        acc_c (np.ndarray): [H, W, D] = sum c a T, written.
        acc_d (np.ndarray): [H, W] = sum z a T, written.
        t_final (np.ndarray): [H, W] final transmittance, written.
        n_contrib (np.ndarray): [H, W] int64, the Gaussians composited at each pixel, written.
        row_pix (np.ndarray): [R, 3] (y, x0, x1) pixels per recorded row (int32 as
            [`physgs.render.fast`][physgs.render.fast] allocates it), written.
        row_gauss (np.ndarray): [R, 2] (exp(-sigma / 2) at x0, its step ratio) per row, written.
        n_rows (np.ndarray): [P] int64 rows recorded per pair, written.
    """
    D = colors.shape[1]
    n_tiles = tile_start.shape[0] - 1
    for t in nb.prange(n_tiles):
        ty0 = (t // tiles_x) * tile
        tx0 = (t % tiles_x) * tile
        th = min(tile, height - ty0)
        tw = min(tile, width - tx0)
        npix = th * tw
        T = np.ones(npix)
        done = np.zeros(npix, np.bool_)
        cacc = np.zeros((npix, D))
        dacc = np.zeros(npix)
        cnt = np.zeros(npix, np.int64)
        col_g = np.empty(D)
        n_done = 0
        for k in range(tile_start[t], tile_start[t + 1]):
            if n_done == npix:
                break
            g = pair_gid[k]
            mx = means2d[g, 0]
            my = means2d[g, 1]
            ca = conics[g, 0]
            cb = conics[g, 1]
            cc = conics[g, 2]
            o = opac[g]
            z = depths[g]
            for c in range(D):  # a local copy: the compiler cannot hoist loads past cacc stores
                col_g[c] = colors[g, c]
            c0, c1, c2 = _rgb(col_g)
            thr = _footprint(o)
            det = ca * cc - cb * cb
            ica = 1.0 / ca if ca > 0.0 else 0.0
            q = math.exp(-ca)
            y0, y1 = _rows(ca, det, thr, my, max(boxes[g, 2], ty0), min(boxes[g, 3], ty0 + th - 1))
            ir = row_start[k]
            for py in range(y0, y1 + 1):
                dy = py + 0.5 - my
                x0, x1 = _row_span(ca, cb, det, ica, thr, mx, dy, tx0, tx0 + tw - 1)
                if x0 > x1:
                    continue
                Gn, r = _row_gauss(ca, cb, cc, mx, dy, x0, x1 > x0)
                row_pix[ir, 0] = py
                row_pix[ir, 1] = x0
                row_pix[ir, 2] = x1
                row_gauss[ir, 0] = Gn
                row_gauss[ir, 1] = r
                ir += 1
                base = (py - ty0) * tw - tx0  # pixel px of this row is tile-local base + px
                for px in range(x0, x1 + 1):
                    G = Gn
                    Gn *= r
                    r *= q
                    p = base + px
                    if done[p]:
                        continue
                    a = min(ALPHA_MAX, o * G)
                    if a < ALPHA_MIN:
                        continue
                    Tp = T[p]
                    nt = Tp * (1.0 - a)
                    if nt < T_MIN:
                        done[p] = True
                        n_done += 1
                        continue
                    w = a * Tp
                    if D == 3:  # RGB unrolled: the loop's operations in its order, ~8% faster
                        cacc[p, 0] += w * c0
                        cacc[p, 1] += w * c1
                        cacc[p, 2] += w * c2
                    else:
                        for c in range(D):
                            cacc[p, c] += w * col_g[c]
                    if with_depth:
                        dacc[p] += w * z
                    cnt[p] += 1
                    T[p] = nt
            n_rows[k] = ir - row_start[k]
        for ly in range(th):
            for lx in range(tw):
                p = ly * tw + lx
                py = ty0 + ly
                px = tx0 + lx
                for c in range(D):
                    acc_c[py, px, c] = cacc[p, c]
                    out_rgb[py, px, c] = cacc[p, c] + T[p] * bg[c]
                acc_d[py, px] = dacc[p]
                out_depth[py, px] = dacc[p]
                t_final[py, px] = T[p]
                out_alpha[py, px] = 1.0 - T[p]
                n_contrib[py, px] = cnt[p]


@nb.njit(parallel=True, cache=True)
def backward(
    means2d,
    conics,
    opac,
    colors,
    depths,
    bg,
    boxes,
    tile_start,
    pair_gid,
    row_start,
    tile,
    tiles_x,
    width,
    height,
    with_depth,
    acc_c,
    acc_d,
    t_final,
    row_pix,
    row_gauss,
    n_rows,
    g_rgb,
    g_alpha,
    g_depth,
    pair_grad,
):  # pragma: no cover - compiled
    """Explicit backward of [`forward`][physgs.render.kernels.forward], over the rows the forward
    recorded (the same pixels, the same exp(-sigma / 2) stepping bit for bit, so both passes make
    the same alpha tests).

    Front-to-back pass: the light behind Gaussian i (later Gaussians plus background) is the total
    minus the prefix up to i, so no per-pixel list is stored and no division by (1 - alpha)
    recovers transmittance.

    Args:
        means2d (np.ndarray): [N, 2] as in the forward.
        conics (np.ndarray): [N, 3] as in the forward.
        opac (np.ndarray): [N] as in the forward.
        colors (np.ndarray): [N, D] as in the forward.
        depths (np.ndarray): [N] as in the forward.
        bg (np.ndarray): [D] as in the forward.
        boxes (np.ndarray): [N, 4] as in the forward.
        tile_start (np.ndarray): [T + 1] as in the forward.
        pair_gid (np.ndarray): [P] as in the forward.
        row_start (np.ndarray): [P + 1] as in the forward.
        tile (int): tile side, px.
        tiles_x (int): tiles per image row.
        width (int): image width W, px.
        height (int): image height H, px.
        with_depth (bool): as in the forward; False skips the depth's terms (g_depth must then be
            zero: the same numbers as with them).
        acc_c (np.ndarray): [H, W, D] the forward's totals.
        acc_d (np.ndarray): [H, W] the forward's totals.
        t_final (np.ndarray): [H, W] the forward's final transmittance.
        row_pix (np.ndarray): [R, 3] the forward's recorded rows.
        row_gauss (np.ndarray): [R, 2] the forward's recorded rows.
        n_rows (np.ndarray): [P] the forward's row counts.
        g_rgb (np.ndarray): [H, W, D] upstream gradient, float64.
        g_alpha (np.ndarray): [H, W] upstream gradient, float64.
        g_depth (np.ndarray): [H, W] upstream gradient, float64.
        pair_grad (np.ndarray): [P, 7 + D], written per (tile, Gaussian) pair: d/d(mx, my, conic
            a, b, c, opacity, depth, colours).
    """
    D = colors.shape[1]
    n_tiles = tile_start.shape[0] - 1
    for t in nb.prange(n_tiles):
        ty0 = (t // tiles_x) * tile
        tx0 = (t % tiles_x) * tile
        th = min(tile, height - ty0)
        tw = min(tile, width - tx0)
        npix = th * tw
        T = np.ones(npix)
        done = np.zeros(npix, np.bool_)
        # tile-local per-pixel state. The gradient of the loss w.r.t. Gaussian i's alpha at a
        # pixel is T_i u_i - S_i / (1 - a_i), u_i = sum_c g_c c_i + g_z z_i (its colour and depth
        # seen through the upstream gradients) and S_i = sum_c g_c behind_c + g_z behind_z -
        # g_alpha T_final, behind = what lies behind i (later Gaussians plus background, from the
        # forward totals minus the prefix up to i). One scalar S per pixel carries all channels.
        up_c = np.empty((npix, D))
        up_d = np.empty(npix)
        S = np.empty(npix)
        for ly in range(th):
            for lx in range(tw):
                p = ly * tw + lx
                tf = t_final[ty0 + ly, tx0 + lx]
                acc = -g_alpha[ty0 + ly, tx0 + lx] * tf
                for c in range(D):
                    gc = g_rgb[ty0 + ly, tx0 + lx, c]
                    up_c[p, c] = gc
                    acc += gc * (acc_c[ty0 + ly, tx0 + lx, c] + tf * bg[c])
                if with_depth:
                    gz = g_depth[ty0 + ly, tx0 + lx]
                    up_d[p] = gz
                    acc += gz * acc_d[ty0 + ly, tx0 + lx]
                S[p] = acc
        g_col = np.empty(D)
        col_g = np.empty(D)
        n_done = 0
        for k in range(tile_start[t], tile_start[t + 1]):
            if n_done == npix:
                break
            g = pair_gid[k]
            mx = means2d[g, 0]
            my = means2d[g, 1]
            ca = conics[g, 0]
            cb = conics[g, 1]
            cc = conics[g, 2]
            o = opac[g]
            z = depths[g]
            for c in range(D):
                col_g[c] = colors[g, c]
                g_col[c] = 0.0
            c0, c1, c2 = _rgb(col_g)
            gr0 = 0.0  # RGB's colour gradients (D == 3), g_col's otherwise
            gr1 = 0.0
            gr2 = 0.0
            q = math.exp(-ca)
            g_mx = 0.0
            g_my = 0.0
            g_a = 0.0
            g_b = 0.0
            g_c = 0.0
            g_o = 0.0
            g_z = 0.0
            for ir in range(row_start[k], row_start[k] + n_rows[k]):
                py = row_pix[ir, 0]
                x0 = row_pix[ir, 1]
                x1 = row_pix[ir, 2]
                Gn = row_gauss[ir, 0]
                r = row_gauss[ir, 1]
                dy = py + 0.5 - my
                base = (py - ty0) * tw - tx0
                for px in range(x0, x1 + 1):
                    G = Gn
                    Gn *= r
                    r *= q
                    p = base + px
                    if done[p]:
                        continue
                    raw = o * G
                    a = min(ALPHA_MAX, raw)
                    if a < ALPHA_MIN:
                        continue
                    Tp = T[p]
                    nt = Tp * (1.0 - a)
                    if nt < T_MIN:
                        done[p] = True
                        n_done += 1
                        continue
                    w = a * Tp
                    u = up_d[p] * z if with_depth else 0.0
                    if D == 3:  # RGB unrolled, as in the forward
                        u0 = up_c[p, 0]
                        u1 = up_c[p, 1]
                        u2 = up_c[p, 2]
                        u += u0 * c0
                        u += u1 * c1
                        u += u2 * c2
                        gr0 += u0 * w
                        gr1 += u1 * w
                        gr2 += u2 * w
                    else:
                        for c in range(D):
                            gc = up_c[p, c]
                            u += gc * col_g[c]
                            g_col[c] += gc * w
                    if with_depth:
                        g_z += up_d[p] * w
                    Sp = S[p] - w * u
                    S[p] = Sp
                    T[p] = nt
                    if raw <= ALPHA_MAX:  # the clamp passes no gradient above 0.99
                        dlda = Tp * u - Sp / (1.0 - a)
                        g_o += dlda * G
                        ds = -0.5 * a * dlda  # dL/dsigma
                        dx = px + 0.5 - mx
                        g_a += ds * dx * dx
                        g_b += ds * 2.0 * dx * dy
                        g_c += ds * dy * dy
                        g_mx -= ds * 2.0 * (ca * dx + cb * dy)
                        g_my -= ds * 2.0 * (cb * dx + cc * dy)
            pair_grad[k, 0] = g_mx
            pair_grad[k, 1] = g_my
            pair_grad[k, 2] = g_a
            pair_grad[k, 3] = g_b
            pair_grad[k, 4] = g_c
            pair_grad[k, 5] = g_o
            pair_grad[k, 6] = g_z
            if D == 3:
                g_col[0] = gr0
                g_col[1] = gr1
                g_col[2] = gr2
            for c in range(D):
                pair_grad[k, N_GRAD + c] = g_col[c]


@nb.njit(cache=True)
def reduce_pairs(pair_gid, pair_grad, n):  # pragma: no cover - compiled
    """Sum pair_grad [P, C] into per-Gaussian rows [n, C] in pair order (deterministic).

    Args:
        pair_gid (np.ndarray): [P] the Gaussian of each pair.
        pair_grad (np.ndarray): [P, C] per-pair gradients.
        n (int): the number of Gaussians.

    Returns:
        (np.ndarray): [n, C] float64 sums.
    """
    out = np.zeros((n, pair_grad.shape[1]))
    for k in range(pair_gid.shape[0]):
        g = pair_gid[k]
        for j in range(pair_grad.shape[1]):
            out[g, j] += pair_grad[k, j]
    return out


@nb.njit(cache=True, inline="always")
def _mm(A, B, out, ta, tb):  # pragma: no cover - compiled
    """out = op(A) @ op(B), op = transpose when ta / tb. Plain loops: numba's @ calls BLAS,
    far too slow for 3x3 blocks, and allocates."""
    n = A.shape[1] if ta else A.shape[0]
    kk = A.shape[0] if ta else A.shape[1]
    m = B.shape[0] if tb else B.shape[1]
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for k in range(kk):
                acc += (A[k, i] if ta else A[i, k]) * (B[j, k] if tb else B[k, j])
            out[i, j] = acc


@nb.njit(cache=True)
def project_forward(
    means, quats, scales, Rc, tc, intr, lims, near, eps2d, means2d, conics, depths, cov2d, valid
):  # pragma: no cover - compiled
    """Fused EWA projection, same maths as
    [`project_gaussians`][physgs.render.project.project_gaussians].

    Culled Gaussians get zeros.

    Args:
        means (np.ndarray): [N, 3] centres, world units.
        quats (np.ndarray): [N, 4] orientations (w, x, y, z).
        scales (np.ndarray): [N, 3] standard deviations, world units.
        Rc (np.ndarray): [3, 3] world-to-camera rotation.
        tc (np.ndarray): [3] world-to-camera translation, world units.
        intr (np.ndarray): [4] (fx, fy, cx, cy), px.
        lims (np.ndarray): [4] (x-, x+, y-, y+) tangent clamps.
        near (float): near-plane depth, world units.
        eps2d (float): dilation added to the 2D covariance's diagonal, px^2.
        means2d (np.ndarray): [N, 2] px, written.
        conics (np.ndarray): [N, 3] px^-2, written.
        depths (np.ndarray): [N] world units, written.
        cov2d (np.ndarray): [N, 3] px^2, written.
        valid (np.ndarray): [N] bool, written.
    """
    fx, fy, cx, cy = intr[0], intr[1], intr[2], intr[3]
    n = means.shape[0]
    Rq = np.empty((3, 3))
    M = np.empty((3, 3))
    # one flat loop: ~50 ns per Gaussian, not worth threads (or their compile time)
    for i in range(n):
        x = Rc[0, 0] * means[i, 0] + Rc[0, 1] * means[i, 1] + Rc[0, 2] * means[i, 2] + tc[0]
        y = Rc[1, 0] * means[i, 0] + Rc[1, 1] * means[i, 1] + Rc[1, 2] * means[i, 2] + tc[1]
        z = Rc[2, 0] * means[i, 0] + Rc[2, 1] * means[i, 1] + Rc[2, 2] * means[i, 2] + tc[2]
        ok = z > near
        a = 0.0
        b = 0.0
        c = 0.0
        det = 0.0
        if ok:
            qn = math.sqrt(
                quats[i, 0] ** 2 + quats[i, 1] ** 2 + quats[i, 2] ** 2 + quats[i, 3] ** 2
            )
            qn = max(qn, QUAT_NORM_EPS)
            quat_rotmat(quats[i, 0] / qn, quats[i, 1] / qn, quats[i, 2] / qn, quats[i, 3] / qn, Rq)
            _mm(Rc, Rq, M, False, False)
            for col in range(3):
                for row in range(3):
                    M[row, col] *= scales[i, col]
            tx = z * min(max(x / z, -lims[0]), lims[1])
            ty = z * min(max(y / z, -lims[2]), lims[3])
            # rows of J @ M, J = [[fx/z, 0, -fx tx/z^2], [0, fy/z, -fy ty/z^2]]
            j00 = fx / z
            j02 = -fx * tx / (z * z)
            j11 = fy / z
            j12 = -fy * ty / (z * z)
            for col in range(3):
                r0 = j00 * M[0, col] + j02 * M[2, col]
                r1 = j11 * M[1, col] + j12 * M[2, col]
                a += r0 * r0
                b += r0 * r1
                c += r1 * r1
            a += eps2d
            c += eps2d
            det = a * c - b * b
            ok = det > 0 and math.isfinite(det)
        valid[i] = ok
        if ok:
            means2d[i, 0] = fx * x / z + cx
            means2d[i, 1] = fy * y / z + cy
            conics[i, 0] = c / det
            conics[i, 1] = -b / det
            conics[i, 2] = a / det
            depths[i] = z
            cov2d[i, 0] = a
            cov2d[i, 1] = b
            cov2d[i, 2] = c
        else:
            means2d[i, 0] = 0.0
            means2d[i, 1] = 0.0
            depths[i] = 0.0
            for j in range(3):
                conics[i, j] = 0.0
                cov2d[i, j] = 0.0


@nb.njit(cache=True)
def project_backward(
    means,
    quats,
    scales,
    Rc,
    tc,
    intr,
    lims,
    near,
    eps2d,
    valid,
    v_means2d,
    v_conics,
    v_depths,
    v_means,
    v_quats,
    v_scales,
):  # pragma: no cover
    """Explicit backward of [`project_forward`][physgs.render.kernels.project_forward].

    Each Gaussian is independent (no accumulation across Gaussians).

    Args:
        means (np.ndarray): [N, 3] as in the forward.
        quats (np.ndarray): [N, 4] as in the forward.
        scales (np.ndarray): [N, 3] as in the forward.
        Rc (np.ndarray): [3, 3] as in the forward.
        tc (np.ndarray): [3] as in the forward.
        intr (np.ndarray): [4] as in the forward.
        lims (np.ndarray): [4] as in the forward.
        near (float): as in the forward.
        eps2d (float): as in the forward.
        valid (np.ndarray): [N] the forward's culling.
        v_means2d (np.ndarray): [N, 2] upstream gradient.
        v_conics (np.ndarray): [N, 3] upstream gradient.
        v_depths (np.ndarray): [N] upstream gradient.
        v_means (np.ndarray): [N, 3], written (zero if culled).
        v_quats (np.ndarray): [N, 4], written (zero if culled).
        v_scales (np.ndarray): [N, 3], written (zero if culled).
    """
    fx, fy = intr[0], intr[1]
    n = means.shape[0]
    # serial: ~150 ns per Gaussian, not worth threads (or their compile time)
    Rq = np.empty((3, 3))
    RR = np.empty((3, 3))
    M = np.empty((3, 3))
    Sc = np.empty((3, 3))
    J = np.zeros((2, 3))
    JS = np.empty((2, 3))
    cov = np.empty((2, 2))
    Con = np.empty((2, 2))
    G = np.empty((2, 2))
    CG = np.empty((2, 2))
    Vcov = np.empty((2, 2))
    VJt = np.empty((2, 3))
    VSc = np.empty((3, 3))
    VJ = np.empty((2, 3))
    VM = np.empty((3, 3))
    VRR = np.empty((3, 3))
    VRq = np.empty((3, 3))
    for i in range(n):
        for j in range(3):
            v_means[i, j] = 0.0
            v_scales[i, j] = 0.0
        for j in range(4):
            v_quats[i, j] = 0.0
        if not valid[i]:
            continue
        x = Rc[0, 0] * means[i, 0] + Rc[0, 1] * means[i, 1] + Rc[0, 2] * means[i, 2] + tc[0]
        y = Rc[1, 0] * means[i, 0] + Rc[1, 1] * means[i, 1] + Rc[1, 2] * means[i, 2] + tc[1]
        z = Rc[2, 0] * means[i, 0] + Rc[2, 1] * means[i, 1] + Rc[2, 2] * means[i, 2] + tc[2]
        qn = max(
            math.sqrt(quats[i, 0] ** 2 + quats[i, 1] ** 2 + quats[i, 2] ** 2 + quats[i, 3] ** 2),
            QUAT_NORM_EPS,
        )
        qw, qx, qy, qz = quats[i, 0] / qn, quats[i, 1] / qn, quats[i, 2] / qn, quats[i, 3] / qn
        quat_rotmat(qw, qx, qy, qz, Rq)
        _mm(Rc, Rq, RR, False, False)
        for col in range(3):
            for row in range(3):
                M[row, col] = RR[row, col] * scales[i, col]
        ux = x / z
        uy = y / z
        cl_x = ux < -lims[0] or ux > lims[1]
        cl_y = uy < -lims[2] or uy > lims[3]
        tx = z * min(max(ux, -lims[0]), lims[1])
        ty = z * min(max(uy, -lims[2]), lims[3])
        J[0, 0] = fx / z
        J[0, 2] = -fx * tx / (z * z)
        J[1, 1] = fy / z
        J[1, 2] = -fy * ty / (z * z)
        _mm(M, M, Sc, False, True)  # camera-frame 3D covariance
        _mm(J, Sc, JS, False, False)
        _mm(JS, J, cov, False, True)
        a = cov[0, 0] + eps2d
        b = cov[0, 1]
        c = cov[1, 1] + eps2d
        det = a * c - b * b
        Con[0, 0] = c / det
        Con[0, 1] = -b / det
        Con[1, 0] = -b / det
        Con[1, 1] = a / det
        # conic = inverse(cov): dL/dcov = -Con G Con, G the symmetric split of dL/dconic.
        G[0, 0] = v_conics[i, 0]
        G[0, 1] = 0.5 * v_conics[i, 1]
        G[1, 0] = 0.5 * v_conics[i, 1]
        G[1, 1] = v_conics[i, 2]
        _mm(Con, G, CG, False, False)
        _mm(CG, Con, Vcov, False, False)
        for r in range(2):
            for q in range(2):
                Vcov[r, q] = -Vcov[r, q]
        # cov = J Sc J^T: dL/dSc = J^T Vcov J, dL/dJ = 2 Vcov J Sc
        _mm(Vcov, J, VJt, False, False)
        _mm(J, VJt, VSc, True, False)
        _mm(VJt, Sc, VJ, False, False)
        # Sc = M M^T, M = RR diag(s), RR = Rc Rq
        _mm(VSc, M, VM, False, False)
        for col in range(3):
            acc = 0.0
            for row in range(3):
                VM[row, col] *= 2.0
                VRR[row, col] = VM[row, col] * scales[i, col]
                acc += VM[row, col] * RR[row, col]
            v_scales[i, col] = acc
        _mm(Rc, VRR, VRq, True, False)
        # rotation matrix -> unit quaternion
        gw = 2 * (
            -qz * VRq[0, 1]
            + qy * VRq[0, 2]
            + qz * VRq[1, 0]
            - qx * VRq[1, 2]
            - qy * VRq[2, 0]
            + qx * VRq[2, 1]
        )
        gx = 2 * (
            qy * VRq[0, 1]
            + qz * VRq[0, 2]
            + qy * VRq[1, 0]
            - 2 * qx * VRq[1, 1]
            - qw * VRq[1, 2]
            + qz * VRq[2, 0]
            + qw * VRq[2, 1]
            - 2 * qx * VRq[2, 2]
        )
        gy = 2 * (
            -2 * qy * VRq[0, 0]
            + qx * VRq[0, 1]
            + qw * VRq[0, 2]
            + qx * VRq[1, 0]
            + qz * VRq[1, 2]
            - qw * VRq[2, 0]
            + qz * VRq[2, 1]
            - 2 * qy * VRq[2, 2]
        )
        gz = 2 * (
            -2 * qz * VRq[0, 0]
            - qw * VRq[0, 1]
            + qx * VRq[0, 2]
            + qw * VRq[1, 0]
            - 2 * qz * VRq[1, 1]
            + qy * VRq[1, 2]
            + qx * VRq[2, 0]
            + qy * VRq[2, 1]
        )
        # normalisation q / |q|
        dot = qw * gw + qx * gx + qy * gy + qz * gz
        v_quats[i, 0] = (gw - qw * dot) / qn
        v_quats[i, 1] = (gx - qx * dot) / qn
        v_quats[i, 2] = (gy - qy * dot) / qn
        v_quats[i, 3] = (gz - qz * dot) / qn
        # J entries -> camera position (x, y, z) through z, tx, ty
        VJ00 = 2.0 * VJ[0, 0]
        VJ02 = 2.0 * VJ[0, 2]
        VJ11 = 2.0 * VJ[1, 1]
        VJ12 = 2.0 * VJ[1, 2]
        z2 = z * z
        v_tx = VJ02 * (-fx / z2)
        v_ty = VJ12 * (-fy / z2)
        vz = (
            VJ00 * (-fx / z2)
            + VJ11 * (-fy / z2)
            + VJ02 * (2 * fx * tx / (z2 * z))
            + VJ12 * (2 * fy * ty / (z2 * z))
        )
        vx = 0.0
        vy = 0.0
        if cl_x:
            vz += v_tx * tx / z  # tx = z * lim
        else:
            vx += v_tx
        if cl_y:
            vz += v_ty * ty / z
        else:
            vy += v_ty
        # means2d and depth
        vx += v_means2d[i, 0] * fx / z
        vy += v_means2d[i, 1] * fy / z
        vz += -v_means2d[i, 0] * fx * x / z2 - v_means2d[i, 1] * fy * y / z2
        vz += v_depths[i]
        for j in range(3):
            v_means[i, j] = Rc[0, j] * vx + Rc[1, j] * vy + Rc[2, j] * vz
