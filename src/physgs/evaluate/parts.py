"""Purity of a segmentation against the ground-truth bones (an evaluation check: reads truth.npz).

A part's purity is the share of its Gaussians whose mesh vertex belongs to the part's majority
bone; the segmentation's purity is the same share over all Gaussians (the parts' purities
weighted by their sizes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physgs.atomic import atomic_path
from physgs.intermediate import read_npz


@dataclass(frozen=True)
class Purity:
    """per_part [K] in (0, 1]; majority_bone [K] bone id; size [K] Gaussians per part;
    overall: share of all Gaussians lying in their part's majority bone."""

    per_part: np.ndarray
    majority_bone: np.ndarray
    size: np.ndarray
    overall: float


def gaussian_bone(truth) -> np.ndarray:
    """[N] bone of each observed Gaussian (in ``canonical_xyz`` order), from truth.npz.

    Args:
        truth (Truth): the dataset's ground truth (``vertex_bone``, ``gaussian_vertex``).

    Returns:
        [N] bone ids.
    """
    return np.asarray(truth.vertex_bone)[np.asarray(truth.gaussian_vertex)]


def part_purity(labels: np.ndarray, bone: np.ndarray) -> Purity:
    """Purity of parts ``labels`` [N] (ids in [0, K), every part non-empty) against ``bone`` [N].

    Args:
        labels: [N] part ids in [0, K).
        bone: [N] bone ids.

    Returns:
        The [`Purity`][physgs.evaluate.parts.Purity] per part and overall.

    Raises:
        ValueError: for shapes that are not one [N], or an empty part.
    """
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


def segmentation_record(models, bone: np.ndarray) -> dict[str, np.ndarray]:
    """Arrays of one tree's parts record: each trained prior's segmentation and its purity.

    Args:
        models (Mapping[str, OscillatorPrior]): model id -> trained oscillator prior (their
            ``part_labels`` [N], ``pivot`` [K, 3] world units, ``part_parent`` [K] for topology
            parts, all on the same canonical Gaussians).
        bone: [N] each Gaussian's bone ([`gaussian_bone`][physgs.evaluate.parts.gaussian_bone]).

    Returns:
        ``models`` [M] ids, ``xyz`` [N, 3] canonical positions, ``bone`` [N], and per model
            ``<id>/labels`` [N], ``<id>/parent`` [K] (-1 where a part has no parent: every part of
            k-means), ``<id>/pivots`` [K, 3], ``<id>/purity`` [K], ``<id>/majority_bone`` [K],
            ``<id>/size`` [K], ``<id>/overall`` [].

    Raises:
        ValueError: when a model's labels do not cover the N Gaussians.
    """
    bone = np.asarray(bone, dtype=np.int64)
    out: dict[str, np.ndarray] = {"models": np.asarray(list(models), dtype=str), "bone": bone}
    for name, m in models.items():
        labels = m.part_labels.cpu().numpy().astype(np.int64)
        if labels.shape != bone.shape:
            raise ValueError(f"{name}: {labels.shape[0]} part labels for {bone.shape[0]} Gaussians")
        K = int(m.K)
        parent = getattr(m, "part_parent", None)
        pur = part_purity(labels, bone)
        out.setdefault("xyz", np.asarray(m.ctx.canonical_xyz, dtype=np.float64))
        out[f"{name}/labels"] = labels
        out[f"{name}/parent"] = (
            np.full(K, -1, np.int64) if parent is None else parent.cpu().numpy().astype(np.int64)
        )
        out[f"{name}/pivots"] = m.pivot.detach().cpu().numpy().astype(np.float64)
        out[f"{name}/purity"] = pur.per_part
        out[f"{name}/majority_bone"] = pur.majority_bone
        out[f"{name}/size"] = pur.size
        out[f"{name}/overall"] = np.float64(pur.overall)
    return out


def save_segmentations(path, record: dict[str, np.ndarray]) -> None:
    """Write a ``segmentation_record`` atomically as .npz.

    Args:
        path (str | Path): the ``.npz`` to write.
        record: the arrays of
            [`segmentation_record`][physgs.evaluate.parts.segmentation_record].
    """
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        np.savez_compressed(f, **record)


def load_segmentations(path) -> dict[str, np.ndarray]:
    """The arrays of a parts record written by ``save_segmentations``.

    Args:
        path (str | Path): the ``.npz``.

    Returns:
        The arrays by key.

    Raises:
        IntermediateFileError: when the file is missing or corrupt (rule ``parts_segmentation``).
    """
    return read_npz(path, (), rule="parts_segmentation")
