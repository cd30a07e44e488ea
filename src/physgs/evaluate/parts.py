"""Purity of a segmentation against the ground-truth bones (an evaluation check: reads truth.npz).

A part's purity is the share of its Gaussians whose mesh vertex belongs to the part's majority
bone; the segmentation's purity is the same share over all Gaussians (the parts' purities
weighted by their sizes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Purity:
    """per_part [K] in (0, 1]; majority_bone [K] bone id; size [K] Gaussians per part;
    overall: share of all Gaussians lying in their part's majority bone."""

    per_part: np.ndarray
    majority_bone: np.ndarray
    size: np.ndarray
    overall: float


def gaussian_bone(truth) -> np.ndarray:
    """[N] bone of each observed Gaussian (in ``canonical_xyz`` order), from truth.npz."""
    return np.asarray(truth.vertex_bone)[np.asarray(truth.gaussian_vertex)]


def part_purity(labels: np.ndarray, bone: np.ndarray) -> Purity:
    """Purity of parts ``labels`` [N] (ids in [0, K), every part non-empty) against ``bone`` [N]."""
    labels = np.asarray(labels, dtype=np.int64)
    bone = np.asarray(bone, dtype=np.int64)
    if labels.shape != bone.shape or labels.ndim != 1 or labels.size == 0:
        raise ValueError(
            f"labels and bones must be [N] of one length; got {labels.shape}, {bone.shape}"
        )
    K, B = int(labels.max()) + 1, int(bone.max()) + 1
    counts = np.zeros((K, B), dtype=np.int64)
    np.add.at(counts, (labels, bone), 1)
    size = counts.sum(1)
    if np.any(size == 0):
        raise ValueError(f"part labels must cover [0, K = {K}) with no empty part")
    top = counts.max(1)
    return Purity(top / size, counts.argmax(1), size, float(top.sum() / labels.size))
