"""Match learned parts to ground-truth bones by trajectory correlation (the protocol, section 4).

Both a part and a bone solve the same oscillator under the same forcing, so a part that
recovered its bone reproduces the bone's theta(t); the match reads omega off that bone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physgs.records import JsonRecord

TRUST_THRESHOLD = 0.7  # |corr| at or above which a match is trusted (the paper and the protocol)


def training_window(theta: np.ndarray, lead_in_frames: int, n_train: int) -> np.ndarray:
    """The columns of recorded frames 0..n_train-1 of a series that starts at the lead-in.

    Args:
        theta: [..., L+F] series (any unit), column L = recorded frame 0.
        lead_in_frames: L, samples before recorded frame 0.
        n_train: training frames.

    Returns:
        [..., n_train] view of ``theta``.

    Raises:
        ValueError: the series is shorter than L + n_train.
    """
    theta = np.asarray(theta)
    if theta.shape[-1] < lead_in_frames + n_train:
        raise ValueError(
            f"series has {theta.shape[-1]} samples, fewer than lead-in {lead_in_frames}"
            f" + {n_train} training frames"
        )
    return theta[..., lead_in_frames : lead_in_frames + n_train]


def pearson_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pearson correlation of every row of ``a`` with every row of ``b``.

    A constant row has no defined correlation; it gets 0 (no evidence of a match), never NaN.

    Args:
        a: [K, T] rows (e.g. part angles, rad).
        b: [B, T] rows over the same T samples.

    Returns:
        [K, B] correlations in [-1, 1], float64.

    Raises:
        ValueError: shapes that are not [K, T] and [B, T], or NaN/inf in either input.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.ndim != 2 or b.ndim != 2 or a.shape[1] != b.shape[1]:
        raise ValueError(f"pearson_matrix needs [K, T] and [B, T], got {a.shape} and {b.shape}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("trajectories contain NaN/inf; the model or the truth file is broken")

    def unit(x):  # centred, unit-norm rows; constant rows -> 0
        xc = x - x.mean(axis=1, keepdims=True)
        n = np.linalg.norm(xc, axis=1, keepdims=True)
        # spread at round-off level of the row's magnitude counts as constant
        ok = n > 1e-12 * np.abs(x).max(axis=1, keepdims=True) * np.sqrt(x.shape[1])
        return np.where(ok, xc / np.where(ok, n, 1.0), 0.0)

    return np.clip(unit(a) @ unit(b).T, -1.0, 1.0)


def loglog_r2(omega_hat: np.ndarray, omega_true: np.ndarray) -> float:
    """Squared Pearson correlation of log omega_hat against log omega_true.

    Args:
        omega_hat: [n] estimated natural frequencies, rad/s (> 0).
        omega_true: [n] the matched bones' natural frequencies, rad/s (> 0).

    Returns:
        R^2 in [0, 1]; NaN when fewer than 3 pairs (undefined / trivially 1); 0 when either side
            has no spread (nothing explained), so a degenerate match never yields NaN from 0/0.
    """
    x, y = np.log(np.asarray(omega_hat, float)), np.log(np.asarray(omega_true, float))
    if x.size < 3:
        return float("nan")
    return float(pearson_matrix(x[None], y[None])[0, 0] ** 2)


@dataclass(frozen=True)
class MatchResult(JsonRecord):
    """Part-to-bone match. omega in rad/s; rel_err = |omega_hat - omega_true| / omega_true.

    bone [K]: best-|corr| bone index; corr [K]: that |corr|; trusted [K]: corr >= threshold.
    median_rel_err (fraction) and loglog_r2 are over trusted parts; NaN when no part is trusted
    (median) or fewer than 3 are (R^2), because then they are undefined.
    """

    bone: np.ndarray  # [K] int
    corr: np.ndarray  # [K]
    trusted: np.ndarray  # [K] bool
    omega_hat: np.ndarray  # [K] rad/s
    omega_true: np.ndarray  # [K] rad/s of the matched bone
    rel_err: np.ndarray  # [K]
    n_trusted: int
    n_parts: int
    median_rel_err: float
    loglog_r2: float


def match_parts(
    part_theta: np.ndarray,
    bone_theta: np.ndarray,
    omega_hat: np.ndarray,
    omega_bones: np.ndarray,
    threshold: float = TRUST_THRESHOLD,
) -> MatchResult:
    """Match each part to the bone whose trajectory it correlates with best (by |corr|).

    Args:
        part_theta: [K, T] part angles, rad, over the same samples as ``bone_theta`` (the training
            window at the training wind).
        bone_theta: [B, T] bone angles, rad.
        omega_hat: [K] the parts' natural frequencies, rad/s.
        omega_bones: [B] the bones' natural frequencies, rad/s.
        threshold: |corr| at or above which a match is trusted.

    Returns:
        The [`MatchResult`][physgs.recovery.matcher.MatchResult]: each part's bone, |corr|, trust,
            relative error, and the median relative error and log-log R^2 over trusted parts.

    Raises:
        ValueError: frequencies of the wrong shape or not positive, or NaN/inf trajectories.
    """
    omega_hat = np.asarray(omega_hat, dtype=np.float64)
    omega_bones = np.asarray(omega_bones, dtype=np.float64)
    K, B = len(part_theta), len(bone_theta)
    if omega_hat.shape != (K,) or omega_bones.shape != (B,):
        raise ValueError(
            f"omega_hat {omega_hat.shape} / omega_bones {omega_bones.shape} do not match "
            f"{K} parts / {B} bones"
        )
    if np.any(omega_hat <= 0) or np.any(omega_bones <= 0):
        raise ValueError("natural frequencies must be positive (rad/s)")
    absc = np.abs(pearson_matrix(part_theta, bone_theta))  # [K, B]
    bone = absc.argmax(axis=1)
    corr = absc[np.arange(K), bone]
    trusted = corr >= threshold
    omega_true = omega_bones[bone]
    rel = np.abs(omega_hat - omega_true) / omega_true
    n = int(trusted.sum())
    med = float(np.median(rel[trusted])) if n else float("nan")
    r2 = loglog_r2(omega_hat[trusted], omega_true[trusted])
    return MatchResult(bone, corr, trusted, omega_hat, omega_true, rel, n, K, med, r2)


def restricted(m: MatchResult, bone_mask: np.ndarray) -> tuple[int, float]:
    """The match's scores restricted to the parts matched to the bones in ``bone_mask``.

    Used to score recovery only on bones whose own motion is visible in the training camera
    ([`physgs.testbed.stats`][]).

    Args:
        m: the match.
        bone_mask: [B] bool, the bones to keep.

    Returns:
        (trusted parts matched to a kept bone, their median relative error as a fraction; NaN when
            there is none).
    """
    sel = np.asarray(m.trusted, bool) & np.asarray(bone_mask, bool)[np.asarray(m.bone, int)]
    return int(sel.sum()), float(np.median(m.rel_err[sel])) if sel.any() else float("nan")
