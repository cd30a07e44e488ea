"""Damping recovery scored part by part against a per-bone truth (the damping testbed variant).

The frequency matcher ([`physgs.recovery.matcher`][]) says which bone each part k reproduces
(``bone[k]``) and whether to trust it (``trusted[k]``); here each trusted part's zeta_hat is read
against its bone's true zeta:

- median relative error |zeta_hat - zeta_b| / zeta_b over the trusted parts;
- Pearson correlation of log zeta_hat with log zeta_b over the trusted parts (does the model
  rank the bones' damping?);
- the exponent p in gamma_hat = zeta_hat omega_hat ~ omega_hat^p (log-log least squares over
  the trusted parts). A damping *ratio* recovered with no relation to frequency gives p near 1
  (exactly 1 for a constant ratio); the paper's diagnosis, a frequency-independent decay *rate*
  fitted in place of a ratio, gives p near 0. The same fit on the matched bones' truth is
  reported beside it (``gamma_exponent_true``).

The untrained null replaces zeta_hat by log-uniform draws from the testbed's zeta_range and
scores them the same way against the same matching (same bones, same trusted parts, same
omega_hat): a model that does not beat it has not recovered damping.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np

from physgs.records import JsonRecord, floats
from physgs.recovery.matcher import pearson_matrix
from physgs.recovery.null import N_DRAWS

#: fewest trusted parts for a correlation (with 2 it is +-1 whatever the values)
MIN_CORR_PARTS = 3
#: fewest trusted parts (with distinct omega_hat) for the gamma exponent
MIN_FIT_PARTS = 2
#: the damping null's own random stream beside the seed (the frequency null uses the bare seed)
NULL_STREAM = zlib.crc32(b"damping_null")


@dataclass(frozen=True)
class DampingScores(JsonRecord):
    """Per-part damping scores over the trusted parts of one matching.

    n_trusted: parts scored. median_rel_err: median |zeta_hat - zeta_b| / zeta_b (fraction; NaN
    with no trusted part). log_corr: Pearson r of log zeta_hat vs log zeta_b (NaN with fewer than
    MIN_CORR_PARTS; 0 when either side has no spread, as ``matcher.pearson_matrix``).
    gamma_exponent: p in zeta_hat omega_hat ~ omega_hat^p; gamma_exponent_true: p of the matched
    bones' zeta_b omega_b ~ omega_b^p (both NaN with fewer than MIN_FIT_PARTS or no spread in
    omega).
    """

    n_trusted: int
    median_rel_err: float
    log_corr: float
    gamma_exponent: float
    gamma_exponent_true: float


def _positive(name: str, x) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    if not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise ValueError(f"{name} must be positive and finite")
    return x


def loglog_exponent(omega: np.ndarray, gamma: np.ndarray) -> float:
    """Least-squares slope p of log gamma = p log omega + c.

    Args:
        omega: [n] natural frequencies, rad/s (> 0).
        gamma: [n] decay rates, 1/s (> 0).

    Returns:
        p, or NaN with fewer than MIN_FIT_PARTS values or no spread in omega (the slope is
            undefined).

    Raises:
        ValueError: for values that are not finite and positive.
    """
    x, y = np.log(_positive("omega", omega)), np.log(_positive("gamma", gamma))
    if x.size < MIN_FIT_PARTS or np.ptp(x) == 0:
        return float("nan")
    xc = x - x.mean()
    return float(xc @ (y - y.mean()) / (xc @ xc))


def log_correlation(zeta_hat: np.ndarray, zeta_true: np.ndarray) -> float:
    """Pearson r of log zeta_hat with log zeta_true, both [n]: NaN for n < MIN_CORR_PARTS,
    0 when either side is constant (no evidence of ranking, never 0/0).

    Args:
        zeta_hat: [n] estimated damping ratios (> 0).
        zeta_true: [n] true damping ratios (> 0).

    Returns:
        r in [-1, 1], NaN or 0 as said.

    Raises:
        ValueError: for values that are not finite and positive.
    """
    x, y = np.log(_positive("zeta_hat", zeta_hat)), np.log(_positive("zeta_true", zeta_true))
    if x.size < MIN_CORR_PARTS:
        return float("nan")
    return float(pearson_matrix(x[None], y[None])[0, 0])


def damping_scores(
    bone: np.ndarray,
    trusted: np.ndarray,
    zeta_hat: np.ndarray,
    omega_hat: np.ndarray,
    zeta_bones: np.ndarray,
    omega_bones: np.ndarray,
) -> DampingScores:
    """Score zeta_hat over the trusted parts of a matching.

    Args:
        bone: [K] int, the bone each part is matched to (``MatchResult.bone``).
        trusted: [K] bool (``MatchResult.trusted``).
        zeta_hat: [K] the parts' damping ratios.
        omega_hat: [K] the parts' natural frequencies, rad/s.
        zeta_bones: [B] the true per-bone damping ratios.
        omega_bones: [B] the true natural frequencies, rad/s (only for ``gamma_exponent_true``).

    Returns:
        The [`DampingScores`][physgs.recovery.damping_scores.DampingScores].
    """
    bone = np.asarray(bone, dtype=np.int64)
    trusted = np.asarray(trusted, dtype=bool)
    zeta_hat, omega_hat = _positive("zeta_hat", zeta_hat), _positive("omega_hat", omega_hat)
    zeta_bones = _positive("zeta_bones", zeta_bones)
    omega_bones = _positive("omega_bones", omega_bones)
    K, B = len(bone), len(zeta_bones)
    if trusted.shape != (K,) or zeta_hat.shape != (K,) or omega_hat.shape != (K,):
        raise ValueError(
            f"bone {bone.shape}, trusted {trusted.shape}, zeta_hat {zeta_hat.shape} "
            f"and omega_hat {omega_hat.shape} must all be [K]"
        )
    if omega_bones.shape != (B,) or np.any((bone < 0) | (bone >= B)):
        raise ValueError(
            f"zeta_bones {zeta_bones.shape} / omega_bones {omega_bones.shape} do not "
            f"cover the matched bone indices (0..{bone.max() if K else -1})"
        )
    b = bone[trusted]
    zh, oh, zt, ot = zeta_hat[trusted], omega_hat[trusted], zeta_bones[b], omega_bones[b]
    n = int(trusted.sum())
    med = float(np.median(np.abs(zh - zt) / zt)) if n else float("nan")
    return DampingScores(
        n, med, log_correlation(zh, zt), loglog_exponent(oh, zh * oh), loglog_exponent(ot, zt * ot)
    )


def score_match(
    match, zeta_hat: np.ndarray, zeta_bones: np.ndarray, omega_bones: np.ndarray
) -> DampingScores:
    """``damping_scores`` of a ``MatchResult`` (its bones, trusted parts and omega_hat).

    Args:
        match (MatchResult): the parts' match to bones.
        zeta_hat: [K] estimated damping ratios.
        zeta_bones: [B] true damping ratios.
        omega_bones: [B] true natural frequencies, rad/s.

    Returns:
        The [`DampingScores`][physgs.recovery.damping_scores.DampingScores] of the trusted parts.
    """
    return damping_scores(
        match.bone, match.trusted, zeta_hat, match.omega_hat, zeta_bones, omega_bones
    )


# --------------------------------------------------------------------------------------------
# The untrained null


def draw_null_zetas(zeta_range, n_parts: int, n_draws: int, seed: int) -> np.ndarray:
    """[n_draws, n_parts] damping ratios, log-uniform on zeta_range = (lo, hi), seeded (its own
    stream NULL_STREAM beside the seed, so it shares no draws with the frequency null).

    Args:
        zeta_range (Sequence[float]): ``(lo, hi)``, 0 < lo <= hi.
        n_parts: ratios per draw.
        n_draws: draws.
        seed: the seed (with NULL_STREAM).

    Returns:
        [n_draws, n_parts] damping ratios.

    Raises:
        ValueError: unless 0 < lo <= hi.
    """
    lo, hi = (float(z) for z in zeta_range)
    if not 0 < lo <= hi:
        raise ValueError(f"zeta_range {list(zeta_range)} must satisfy 0 < lo <= hi")
    rng = np.random.default_rng([int(seed), NULL_STREAM])
    return np.exp(rng.uniform(np.log(lo), np.log(hi), size=(n_draws, n_parts)))


@dataclass(frozen=True)
class DampingNull(JsonRecord):
    """Damping null: per-draw scores [D] (as DampingScores) and the drawn zeta [D, K]."""

    median_rel_err: np.ndarray = floats()
    log_corr: np.ndarray = floats()
    gamma_exponent: np.ndarray = floats()
    zeta: np.ndarray = floats()
    n_trusted: int
    seed: int

    @staticmethod
    def _median(v: np.ndarray) -> float:
        v = np.asarray(v, float)
        v = v[np.isfinite(v)]
        return float(np.median(v)) if v.size else float("nan")

    @property
    def median_median_rel_err(self) -> float:
        """Median over draws of each draw's median relative error (NaN draws skipped)."""
        return self._median(self.median_rel_err)

    @property
    def median_log_corr(self) -> float:
        """Median over draws of each draw's log-log correlation (NaN draws skipped)."""
        return self._median(self.log_corr)

    @property
    def median_gamma_exponent(self) -> float:
        """Median over draws of each draw's gamma exponent (NaN draws skipped)."""
        return self._median(self.gamma_exponent)


def damping_null(
    bone: np.ndarray,
    trusted: np.ndarray,
    omega_hat: np.ndarray,
    zeta_bones: np.ndarray,
    omega_bones: np.ndarray,
    zeta_range,
    *,
    seed: int,
    n_draws: int = N_DRAWS,
) -> DampingNull:
    """Score log-uniform zeta draws exactly as ``damping_scores`` scores zeta_hat.

    Same matching, same omega_hat, same truth; only zeta is drawn (``draw_null_zetas``). Seeded:
    same seed, same draws.

    Args:
        bone: [K] int, the bone each part is matched to.
        trusted: [K] bool.
        omega_hat: [K] the parts' natural frequencies, rad/s.
        zeta_bones: [B] the true per-bone damping ratios.
        omega_bones: [B] the true natural frequencies, rad/s.
        zeta_range (tuple[float, float]): (lo, hi) of the draws, 0 < lo <= hi.
        seed: seeds the draws.
        n_draws: D, draws.

    Returns:
        The [`DampingNull`][physgs.recovery.damping_scores.DampingNull]: per-draw scores [D].

    Raises:
        ValueError: the range is not 0 < lo <= hi.
    """
    draws = draw_null_zetas(zeta_range, len(np.asarray(bone)), n_draws, seed)
    s = [damping_scores(bone, trusted, z, omega_hat, zeta_bones, omega_bones) for z in draws]
    return DampingNull(
        np.array([x.median_rel_err for x in s]),
        np.array([x.log_corr for x in s]),
        np.array([x.gamma_exponent for x in s]),
        draws,
        int(np.asarray(trusted, bool).sum()),
        int(seed),
    )
