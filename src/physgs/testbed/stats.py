"""Testbed statistics: what a tree offers a recovery method, and what it leaks.

``testbed_stats(observed, truth)`` gives, per tree: bone count; distinct natural frequencies;
frequency range and span; bones clamped into the band; the median nearest-bone gap the null
control faces; per-bone swing; per-bone visible motion in the training camera; how much of the
training image the tree uses; and how much bone information the stored Gaussian order carries.

Definitions (all over the training window, recorded frames 0..n_train-1, at the training wind,
condition 0, unless said otherwise):

- distinct frequencies: ``distinct_count(omega)``, values equal to a relative 1e-9 count once.
- nearest-bone gap: for a frequency omega drawn log-uniformly on [min omega_b, max omega_b], the
  relative distance to the nearest bone, [`nearest_bone_gap`][physgs.testbed.stats.nearest_bone_gap] (the quantity
  the null control reports); its median over the draw is taken on a dense log grid (so it is the
  expectation, not one seed's estimate).
- swing: each bone's own angle theta_b(t) (not its ancestors'), RMS over the window, degrees.
- visible motion ``visible_px[b]``: the bone's own degree of freedom acting alone on its subtree
  (its own vertices and all its descendants'), every other angle 0 (rest pose). Over the window
  theta_b(t) ranges over [theta_b^min, theta_b^max]; pose the subtree rigidly about the bone's head
  at each end of that range and project both with the training camera: visible_px[b] is the
  largest pixel distance between a subtree vertex's two projections (the peak-to-peak image
  excursion of the bone's own motion; for a rigid rotation about one axis the chord grows with the
  angle difference, so no other pair of frames moves a vertex further, up to perspective).
- height / width fill: the vertical / horizontal extent in the training image (fraction of its
  height / width) of every posed vertex over every recorded frame of every condition.
- coverage: mean over the training window of the fraction of training-image pixels inside the
  silhouette mask (training wind).
- order leak: ``neighbour_bone_share`` of the bone labels in stored Gaussian order, beside its
  expectation under a uniformly random order, ``expected_neighbour_share``.
"""

from __future__ import annotations

import numpy as np

from physgs.atomic import write_json
from physgs.intermediate import read_json
from physgs.testbed import kinematics


# --------------------------------------------------------------------------------------------
# Order leak


def neighbour_bone_share(labels) -> float:
    """Fraction of neighbouring index pairs (i, i+1) whose labels are equal (NaN below 2 labels).

    Args:
        labels (ArrayLike): [N] labels (e.g. bone indices) in some order.

    Returns:
        The fraction in [0, 1], or NaN for fewer than 2 labels.
    """
    labels = np.asarray(labels)
    if labels.size < 2:
        return float("nan")
    return float(np.mean(labels[1:] == labels[:-1]))


def expected_neighbour_share(labels) -> float:
    """Expectation of ``neighbour_bone_share`` under a uniformly random order of ``labels``:
    sum_b n_b (n_b - 1) / (N (N - 1)), n_b the count of label b, N the number of labels.

    Args:
        labels (ArrayLike): [N] labels; only their counts matter.

    Returns:
        The expected fraction in [0, 1], or NaN for fewer than 2 labels.
    """
    labels = np.asarray(labels)
    N = labels.size
    if N < 2:
        return float("nan")
    n = np.unique(labels, return_counts=True)[1].astype(np.float64)
    return float((n * (n - 1)).sum() / (N * (N - 1.0)))


# --------------------------------------------------------------------------------------------
# Frequencies


def distinct_count(values, rtol: float = 1e-9) -> int:
    """Number of distinct values, two values within a relative ``rtol`` of each other counting once
    (sorted values; a new one starts where the step to the previous exceeds rtol * |value|).

    Args:
        values (ArrayLike): any shape, flattened.
        rtol: relative tolerance within which two sorted neighbours count as one value.

    Returns:
        The count (0 for no values).
    """
    v = np.sort(np.asarray(values, dtype=np.float64).ravel())
    if v.size == 0:
        return 0
    step = np.diff(v) > rtol * np.maximum(np.abs(v[1:]), np.abs(v[:-1]))
    return int(1 + step.sum())


def nearest_bone_gap(omega: np.ndarray, omega_bones: np.ndarray) -> np.ndarray:
    """Relative distance of each frequency to the nearest bone's, min_b |omega - omega_b| / omega_b.

    Args:
        omega: [...] natural frequencies, rad/s.
        omega_bones: [B] the bones' natural frequencies, rad/s (> 0).

    Returns:
        [...] the gaps, fractions.
    """
    omega = np.asarray(omega, dtype=np.float64)
    ob = np.asarray(omega_bones, dtype=np.float64)
    return np.min(np.abs(omega[..., None] - ob) / ob, axis=-1)


def median_nearest_bone_gap(omega, n_grid: int = 200_001) -> float:
    """Median over omega log-uniform on [min, max] of ``nearest_bone_gap`` (fraction).

    Evaluated on ``n_grid`` log-spaced points (the median of a dense quadrature of the null draw).

    Args:
        omega (ArrayLike): [B] bone natural frequencies, rad/s (any positive unit: the gap is
            relative).
        n_grid: number of log-spaced evaluation points.

    Returns:
        The median relative gap (fraction).
    """
    om = np.asarray(omega, dtype=np.float64)
    grid = np.exp(np.linspace(np.log(om.min()), np.log(om.max()), int(n_grid)))
    ob = np.unique(om)
    gaps = np.empty_like(grid)
    for i in range(0, grid.size, 20_000):  # [chunk, B] at a time
        gaps[i : i + 20_000] = nearest_bone_gap(grid[i : i + 20_000], ob)
    return float(np.median(gaps))


# --------------------------------------------------------------------------------------------
# Motion


def _window(truth, n_train: int, condition: int = 0) -> np.ndarray:
    L = int(truth.lead_in_frames)
    th = np.asarray(truth.theta)[condition, L : L + int(n_train)]
    if th.shape[0] != int(n_train):
        raise ValueError(
            f"truth has {np.asarray(truth.theta).shape[1]} samples, fewer than lead-in "
            f"{L} + {n_train} training frames"
        )
    return th  # [n_train, B]


def bone_swing_deg(truth, n_train: int, condition: int = 0) -> np.ndarray:
    """[B] RMS over the training window of each bone's own angle theta_b (degrees).

    Args:
        truth (Truth): the tree's [`Truth`][physgs.testbed.dataset.Truth] (reads ``theta``, rad,
            and ``lead_in_frames``).
        n_train: training-window length, frames (after the lead-in).
        condition: the wind condition's index into ``theta``'s first axis.

    Returns:
        [B] RMS angle per bone, degrees.

    Raises:
        ValueError: when ``theta`` is shorter than the lead-in plus ``n_train`` frames.
    """
    return np.degrees(np.sqrt(np.mean(_window(truth, n_train, condition) ** 2, axis=0)))


def subtree_pairs(parent: np.ndarray, vertex_bone: np.ndarray):
    """(bone [P], vertex [P]) for every vertex and every bone on its chain (its own bone and all
    its ancestors): the pairs (b, v) with v in the subtree of b. Sorted by bone.

    Args:
        parent: [B] each bone's parent bone, -1 for a root.
        vertex_bone: [N] each vertex's bone.

    Returns:
        (tuple[np.ndarray, np.ndarray]): ``(bone, vertex)``, two int arrays [P] (P = sum over
            vertices of their chain lengths), sorted by bone (stable).

    Raises:
        ValueError: when ``parent`` has a cycle (from
            [`bone_depth`][physgs.testbed.kinematics.bone_depth]).
    """
    parent = np.asarray(parent)
    kinematics.bone_depth(parent)  # raises on a cycle
    cur = np.asarray(vertex_bone, dtype=np.int64).copy()
    idx = np.arange(cur.size)
    pb, pv = [], []
    while cur.size:
        pb.append(cur)
        pv.append(idx)
        nxt = parent[cur]
        keep = nxt >= 0
        cur, idx = nxt[keep], idx[keep]
    pb, pv = np.concatenate(pb), np.concatenate(pv)
    order = np.argsort(pb, kind="stable")
    return pb[order], pv[order]


def subtree_excursion_px(truth, camera, theta_a, theta_b) -> np.ndarray:
    """[B] pixels: for each bone b, the largest distance in ``camera`` between the projections of a
    vertex of b's subtree posed with bone b alone at angle theta_a[b] and with it alone at
    theta_b[b] (rad; every other angle 0). The subtree rotates rigidly about bone b's head, about
    ``truth.swing_axis``. A bone whose subtree has no vertex gets 0.

    Args:
        truth (Truth): the tree's [`Truth`][physgs.testbed.dataset.Truth] (rest vertices, bones,
            swing axis).
        camera (Camera): the [`Camera`][physgs.camera.Camera] the pixels are measured in.
        theta_a (ArrayLike): [B] or a scalar broadcast to [B], first angle per bone, rad.
        theta_b (ArrayLike): [B] or a scalar, second angle per bone, rad.

    Returns:
        [B] largest projected distance per bone, px.
    """
    B = len(truth.bone_parent)
    ta = np.broadcast_to(np.asarray(theta_a, dtype=np.float64), (B,))
    tb = np.broadcast_to(np.asarray(theta_b, dtype=np.float64), (B,))
    pb, pv = subtree_pairs(truth.bone_parent, truth.vertex_bone)
    head = np.asarray(truth.bone_head, dtype=np.float64)[pb]
    rel = np.asarray(truth.rest_vertices, dtype=np.float64)[pv] - head  # [P, 3]
    axis = np.asarray(truth.swing_axis, dtype=np.float64)
    ua, _ = camera.project(head + kinematics.rotate(rel, axis, ta[pb]))
    ub, _ = camera.project(head + kinematics.rotate(rel, axis, tb[pb]))
    d = np.linalg.norm(ua - ub, axis=1)
    out = np.zeros(B)
    bones, starts = np.unique(pb, return_index=True)
    if bones.size:
        out[bones] = np.maximum.reduceat(d, starts)
    return out


def visible_motion_px(truth, camera, n_train: int, *, condition: int = 0) -> np.ndarray:
    """visible_px [B] (pixels of ``camera``): ``subtree_excursion_px`` between the smallest and the
    largest theta_b of the training window (all n_train frames). See the module docstring.

    Args:
        truth (Truth): the tree's [`Truth`][physgs.testbed.dataset.Truth].
        camera (Camera): the training [`Camera`][physgs.camera.Camera].
        n_train: training-window length, frames.
        condition: the wind condition's index.

    Returns:
        [B] visible motion per bone, px.
    """
    th = _window(truth, n_train, condition)
    return subtree_excursion_px(truth, camera, th.min(axis=0), th.max(axis=0))


def swept_image_extent(truth, camera, *, chunk: int = 25) -> tuple[np.ndarray, np.ndarray]:
    """(lo [2], hi [2]) pixel bounds (u, v) in ``camera`` of every posed vertex over every
    recorded frame of every condition (lead-in excluded).

    Args:
        truth (Truth): the tree's [`Truth`][physgs.testbed.dataset.Truth] (all conditions' theta).
        camera (Camera): the [`Camera`][physgs.camera.Camera] projected into.
        chunk: frames posed at a time (bounds memory, not the result).

    Returns:
        ``(lo, hi)``: [2] each, the smallest and largest (u, v), px.
    """
    L = int(truth.lead_in_frames)
    th = np.asarray(truth.theta)[:, L:].reshape(-1, np.asarray(truth.theta).shape[-1])
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for i in range(0, len(th), chunk):
        V = kinematics.pose_vertices(truth, th[i : i + chunk])
        uv, _ = camera.project(V.reshape(-1, 3))
        lo, hi = np.minimum(lo, uv.min(axis=0)), np.maximum(hi, uv.max(axis=0))
    return lo, hi


# --------------------------------------------------------------------------------------------
# Everything


def displacement_energy_below(positions: np.ndarray, fps: float, cutoffs_hz) -> np.ndarray:
    """Share of the displacement energy of moving points at or below each cutoff frequency.

    The mean position of each point is removed, then the energy is summed over points and axes per
    rFFT bin. Used to ask how much of the true motion a time encoding whose top band is f Hz can
    reach without building harmonics of its own.

    Args:
        positions: [T, N, 3] positions, m, over T uniformly spaced frames.
        fps: frame rate, frames/s.
        cutoffs_hz (float | ArrayLike): one or more cutoff frequencies, Hz.

    Returns:
        [len(cutoffs_hz)] fractions in [0, 1].

    Raises:
        ValueError: when the points do not move (zero energy).
    """
    d = np.asarray(positions, dtype=np.float64)
    d = d - d.mean(0)
    energy = (np.abs(np.fft.rfft(d, axis=0)) ** 2).reshape(d.shape[0] // 2 + 1, -1).sum(1)
    freq = np.fft.rfftfreq(d.shape[0], 1.0 / fps)  # [T//2 + 1] Hz
    total = energy.sum()
    if total <= 0:
        raise ValueError("displacement_energy_below: the points do not move")
    return np.array([energy[freq <= c].sum() / total for c in np.atleast_1d(cutoffs_hz)])


def time_band_top_hz(bands: int, n_train: int, fps: float) -> float:
    """Highest frequency (Hz) of a Fourier time encoding with ``bands`` bands
    ([`physgs.models.encoding.fourier`][]: sin(2^k pi t), k < bands) over a training window of
    n_train frames mapped to t in [0, 1]: 2^(bands-1) / 2 cycles per (n_train - 1) / fps s.

    Args:
        bands: the encoding's number of frequency bands (>= 1).
        n_train: training-window length, frames.
        fps: frame rate, frames/s.

    Returns:
        The top band's frequency, Hz.

    Raises:
        ValueError: for ``bands`` < 1.
    """
    if bands < 1:
        raise ValueError(f"time_band_top_hz: bands must be >= 1, got {bands}")
    return 2.0 ** (bands - 1) / 2.0 / ((n_train - 1) / fps)


def truth_motion_window(truth, n_train: int, condition: int = 0) -> np.ndarray:
    """Ground-truth Gaussian positions [n_train, N, 3] (m) over the training window.

    Args:
        truth (Truth): the tree's [`Truth`][physgs.testbed.dataset.Truth].
        n_train: training-window length, frames.
        condition: the wind condition's index.

    Returns:
        [n_train, N, 3] positions, m, in stored Gaussian order.
    """
    return kinematics.pose_gaussians(truth, _window(truth, n_train, condition))


def testbed_stats(observed, truth, *, visible_threshold_px: float = 1.0) -> dict:
    """Statistics of one tree (see the module docstring for every definition).

    Args:
        observed (Observed): the tree's [`Observed`][physgs.testbed.dataset.Observed] (its training
            camera, masks and n_train are used).
        truth (Truth): the matching [`Truth`][physgs.testbed.dataset.Truth].
        visible_threshold_px: visible motion below which a bone counts as invisible, px.

    Returns:
        Scalars (floats / ints) and per-bone arrays: bones, distinct_frequencies, f_min_hz,
            f_median_hz, f_max_hz, f_span (max / min), clamped, nearest_bone_gap (fraction),
            swing_deg_median, visible_px_median, visible_below_px_fraction (fraction of bones with
            visible_px < visible_threshold_px), visible_threshold_px, height_fill, width_fill
            (fractions of the training image), coverage (fraction of pixels), order_share
            (neighbour_bone_share in stored Gaussian order), order_share_random (its expectation
            under a random order), mesh_order_share (the same statistic in mesh order), and the
            arrays swing_deg [B], visible_px [B] (pixels), visible [B] bool (visible_px >=
            threshold).
    """
    cam = observed.train_camera
    n_train = int(observed.n_train)
    omega = np.asarray(truth.omega, dtype=np.float64)
    f = omega / (2 * np.pi)
    swing = bone_swing_deg(truth, n_train)
    vis = visible_motion_px(truth, cam, n_train)
    lo, hi = swept_image_extent(truth, cam)
    vb = np.asarray(truth.vertex_bone)
    stored = vb[np.asarray(truth.gaussian_vertex)]
    masks = np.asarray(observed.masks)[0, :n_train]
    return dict(
        bones=int(omega.size),
        distinct_frequencies=distinct_count(omega),
        f_min_hz=float(f.min()),
        f_median_hz=float(np.median(f)),
        f_max_hz=float(f.max()),
        f_span=float(f.max() / f.min()),
        clamped=int(np.asarray(truth.omega_clamped).sum()),
        nearest_bone_gap=median_nearest_bone_gap(omega),
        swing_deg_median=float(np.median(swing)),
        visible_px_median=float(np.median(vis)),
        visible_below_px_fraction=float(np.mean(vis < visible_threshold_px)),
        visible_threshold_px=float(visible_threshold_px),
        height_fill=float((hi[1] - lo[1]) / cam.height),
        width_fill=float((hi[0] - lo[0]) / cam.width),
        coverage=float(masks.mean()),
        order_share=neighbour_bone_share(stored),
        order_share_random=expected_neighbour_share(vb),
        mesh_order_share=neighbour_bone_share(vb),
        swing_deg=swing,
        visible_px=vis,
        visible=vis >= visible_threshold_px,
    )


def save_stats(path, stats: dict) -> None:
    """Write ``testbed_stats`` as JSON (arrays as lists), atomically.

    Args:
        path (str | Path): the JSON file to write.
        stats: the dict of [`testbed_stats`][physgs.testbed.stats.testbed_stats].
    """
    write_json(
        path, {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in stats.items()}
    )


def load_stats(path) -> dict:
    """Read ``save_stats``'s JSON back; per-bone lists become arrays.

    Args:
        path (str | Path): the JSON file.

    Returns:
        The stats dict.

    Raises:
        IntermediateFileError: when the file is missing or corrupt (names the rule that makes it).
    """
    d = read_json(path, rule="testbed_stats")
    return {k: (np.asarray(v) if isinstance(v, list) else v) for k, v in d.items()}
