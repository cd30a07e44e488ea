"""Rigid parts of the oscillator prior: k-means on canonical positions."""

from __future__ import annotations

import warnings

import numpy as np


def kmeans_parts(xyz: np.ndarray, k: int, seed: int, n_init: int = 4) -> np.ndarray:
    """Hard-assign N points [N, 3] to k parts, deterministic for ``seed``.

    Parts are numbered by ascending centroid height (z), then x, so part 0 sits lowest.

    Args:
        xyz: [N, 3] positions, world units.
        k: number of parts.
        seed: the k-means seed.
        n_init: k-means restarts.

    Returns:
        [N] int64 labels in [0, k).

    Raises:
        ValueError: for k < 1, k > N, or when k-means cannot form k distinct, non-empty parts.
    """
    xyz = np.asarray(xyz, dtype=np.float64)
    n = xyz.shape[0]
    if k < 1:
        raise ValueError(f"number of parts K must be >= 1, got {k} (config models.configs)")
    if k > n:
        raise ValueError(
            f"K = {k} parts exceeds the {n} Gaussians; lower K in config models.configs or raise "
            "testbed.vertices"
        )
    # imported here: sklearn costs ~2 s of start-up, and most workflow jobs (evaluation, tables,
    # every learned field) import this module without ever forming parts
    from sklearn.cluster import KMeans

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # sklearn warns when it finds fewer distinct clusters than K
        try:
            km = KMeans(n_clusters=k, random_state=seed, n_init=n_init).fit(xyz)
        except Warning as w:
            raise ValueError(
                f"k-means could not form {k} distinct parts from {n} positions ({w}); lower K"
            ) from None
    labels = km.labels_
    if np.unique(labels).size != k:
        raise ValueError(f"k-means left empty parts (K = {k}, N = {n}); lower K")
    c = km.cluster_centers_
    order = np.lexsort((c[:, 0], c[:, 2]))  # primary key z, then x
    rank = np.empty(k, dtype=np.int64)
    rank[order] = np.arange(k)
    return rank[labels]
