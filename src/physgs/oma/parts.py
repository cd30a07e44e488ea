"""From identified modes to per-part estimates: the image regions a mode moves, mapped to parts.

Cells are grouped into K parts by k-means on their centres (px), as the 2D-track control groups
its tracks by their seed positions ([`physgs.tracks.fit`][]). A mode belongs to the part whose
cells it moves most: the largest mean squared shape amplitude |phi_c|^2 over the part's
channels (x and y of each cell), so a large part does not win by its size alone. A part takes,
of the modes that belong to it, the one it carries the largest share of; a part no mode
belongs to gives no estimate (its theta is 0 in the recovery, so the matcher never trusts it,
and the record lists it), exactly as a tracks part with too few tracks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PartModes:
    """part_of_cell [N]; mode_part [M] the part each mode belongs to; omega [K] rad/s and zeta
    [K] per part (NaN where ``estimated`` is False); mode_of_part [K] (-1: none); omega_std [K]
    rad/s and zeta_std [K]: the part's mode's standard deviations (NaN where none)."""

    part_of_cell: np.ndarray
    mode_part: np.ndarray
    mode_of_part: np.ndarray
    omega: np.ndarray
    zeta: np.ndarray
    omega_std: np.ndarray
    zeta_std: np.ndarray

    @property
    def estimated(self) -> np.ndarray:
        """[K] bool: whether a mode gave the part an estimate."""
        return self.mode_of_part >= 0


def cell_parts(cell_xy: np.ndarray, K: int, seed: int, n_init: int) -> np.ndarray:
    """[N] part of each cell: the tracks control's k-means of image positions (px) into K
    parts ([`physgs.tracks.fit.track_parts`][]: numbered top to bottom, then left to right).

    Args:
        cell_xy: [N, 2] cell centres, px.
        K: number of parts.
        seed: the k-means seed.
        n_init: k-means restarts.

    Returns:
        [N] int64 part ids.

    Raises:
        ValueError: when K exceeds the cells.
    """
    # here: tracks.fit loads torch and numba, which the OMA scripts load only after
    # physgs.jobs.job has set the rule's threads
    from physgs.tracks.fit import track_parts

    n = int(np.asarray(cell_xy).shape[0])
    if K > n:
        raise ValueError(f"K = {K} parts exceeds the {n} foreground cells (oma/flow/cell_px)")
    return np.asarray(track_parts(np.asarray(cell_xy, np.float64), K, seed, n_init), np.int64)


def assign_modes(
    freq_hz: np.ndarray,
    zeta: np.ndarray,
    shape: np.ndarray,
    channel_cell: np.ndarray,
    part_of_cell: np.ndarray,
    K: int,
    freq_std: np.ndarray | None = None,
    zeta_std: np.ndarray | None = None,
) -> PartModes:
    """Each mode to the part it moves most, each part to its strongest mode.

    Args:
        freq_hz: [M] mode frequencies, Hz.
        zeta: [M] mode damping ratios.
        shape: [M, C] complex mode shapes over the cell channels.
        channel_cell: [C] the cell of each channel.
        part_of_cell: [N] part of each cell, in [0, K).
        K: number of parts.
        freq_std: [M] the modes' frequency standard deviations, Hz (None: NaN).
        zeta_std: [M] the modes' damping standard deviations (None: NaN).

    Returns:
        The [`PartModes`][physgs.oma.parts.PartModes]: omega (rad/s), zeta and their standard
            deviations per part, NaN where a part has no mode.
    """
    shape = np.asarray(shape)
    M = int(np.asarray(freq_hz).size)
    part_of_channel = np.asarray(part_of_cell)[np.asarray(channel_cell)]  # [C]
    energy = np.abs(shape) ** 2  # [M, C]
    energy = energy / np.maximum(energy.sum(axis=1, keepdims=True), 1e-300)
    share = np.zeros((M, K))  # share of each mode's motion carried by each part's cells
    for p in range(K):
        share[:, p] = energy[:, part_of_channel == p].sum(axis=1)
    has = np.bincount(part_of_channel, minlength=K) > 0
    mode_of_part = np.where(has & (M > 0), share.argmax(axis=0) if M else -1, -1).astype(np.int64)
    est = mode_of_part >= 0
    omega = (
        np.where(est, 2 * np.pi * np.asarray(freq_hz, float)[np.maximum(mode_of_part, 0)], np.nan)
        if M
        else np.full(K, np.nan)
    )
    zet = (
        np.where(est, np.asarray(zeta, float)[np.maximum(mode_of_part, 0)], np.nan)
        if M
        else np.full(K, np.nan)
    )
    mode_part = share.argmax(axis=1) if M else np.zeros(0, np.int64)

    def per_part(x) -> np.ndarray:  # [M] -> [K], NaN where a part has no mode
        x = np.full(M, np.nan) if x is None else np.asarray(x, float)
        return np.where(est, x[np.maximum(mode_of_part, 0)], np.nan) if M else np.full(K, np.nan)

    return PartModes(
        np.asarray(part_of_cell),
        np.asarray(mode_part, np.int64),
        mode_of_part,
        omega,
        zet,
        2 * np.pi * per_part(freq_std),
        per_part(zeta_std),
    )
