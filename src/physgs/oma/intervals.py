"""The identified modes' 95% intervals, checked against the truth, and the modal analyst's trust rule.

Evaluation only where a truth is passed: ``interval_hits`` reads the matched bones' true
values; ``sigma_trusted`` reads the modes' own standard deviations and nothing else, so the
rule it applies is one a user with real footage can apply.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import stats

Z95 = float(stats.norm.ppf(0.975))  # 1.96: the half-width of a 95% interval, in sigmas
#: the miss rate of a central 95% interval: the interval score's penalty is 2 / ALPHA per unit
ALPHA = 0.05
#: a mode whose damping's relative standard deviation exceeds this is not trusted: its 95%
#: interval reaches zero damping (1 / 1.96), i.e. the record cannot tell it from an undamped
#: pole. Chosen on the lsim oracle (docs/blind.md), never on the testbeds' truth.
REL_SIGMA_MAX = 1.0 / Z95


def interval_hits(est, std, truth) -> np.ndarray:
    """Which ``est +- 1.96 std`` intervals contain the truth.

    Args:
        est (ArrayLike): [n] estimates.
        std (ArrayLike): [n] their standard deviations (NaN: no interval, never a hit).
        truth (ArrayLike): [n] the true values.

    Returns:
        [n] bool.
    """
    est, std, truth = (np.asarray(x, np.float64) for x in (est, std, truth))
    return np.isfinite(std) & (np.abs(est - truth) <= Z95 * std)


def sigma_trusted(value, std, rel_max: float = REL_SIGMA_MAX) -> np.ndarray:
    """The modal analyst's rule: a mode is trusted when its relative standard deviation is at
    most ``rel_max`` (NaN value or std: not trusted).

    Args:
        value (ArrayLike): [n] estimates (damping ratios).
        std (ArrayLike): [n] their standard deviations.
        rel_max: the largest relative standard deviation trusted.

    Returns:
        [n] bool.
    """
    value, std = np.asarray(value, np.float64), np.asarray(std, np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = std / np.abs(value)
    return np.isfinite(rel) & (rel <= rel_max)


def interval_score(lower, upper, truth, alpha: float = ALPHA) -> np.ndarray:
    """The interval score of central (1 - alpha) intervals (Gneiting and Raftery 2007, JASA
    102(477), 359-378, section 6.2): the width plus 2 / alpha times the distance by which the truth misses
    the interval. Lower is better; a proper score: wide intervals pay their width, narrow ones
    their misses.

    Args:
        lower (ArrayLike): [n] the intervals' low ends.
        upper (ArrayLike): [n] their high ends.
        truth (ArrayLike): [n] the true values, same unit.
        alpha: the intervals' nominal miss rate.

    Returns:
        [n] scores, in the values' unit.
    """
    lo, hi, x = (np.asarray(v, np.float64) for v in (lower, upper, truth))
    miss = np.maximum(lo - x, 0.0) + np.maximum(x - hi, 0.0)
    return (hi - lo) + (2.0 / alpha) * miss


def relative_scores(est, std, truth, null_range, alpha: float = ALPHA) -> dict:
    """The mean relative interval score of ``est +- 1.96 std`` and of the untrained null's
    interval, its draw range, on the same parts: each part's score over its true value (parts of
    different size weigh alike).

    A part without a standard deviation (NaN) is scored as a point, ``est +- 0``: it has an
    estimate and no interval, and pays its miss.

    Args:
        est (ArrayLike): [n] estimates.
        std (ArrayLike): [n] their standard deviations.
        truth (ArrayLike): [n] the true values (> 0).
        null_range (tuple[float, float] | None): ``(lo, hi)`` the null draws from, same unit;
            None: no null score.
        alpha: the intervals' nominal miss rate (0.05: ``Z95``).

    Returns:
        ``score`` and ``null_score`` (means over the parts, fractions of the truth; NaN with no
            part or no null range), ``n`` parts.
    """
    est, std, x = (np.asarray(v, np.float64).ravel() for v in (est, std, truth))
    nan = float("nan")
    if x.size == 0:
        return {"score": nan, "null_score": nan, "n": 0}
    z = float(stats.norm.ppf(1.0 - alpha / 2.0))
    half = z * np.where(np.isfinite(std), std, 0.0)
    score = float(np.mean(interval_score(est - half, est + half, x, alpha) / x))
    null = nan
    if null_range is not None:
        lo, hi = (float(v) for v in null_range)
        null = float(
            np.mean(interval_score(np.full_like(x, lo), np.full_like(x, hi), x, alpha) / x)
        )
    return {"score": score, "null_score": null, "n": int(x.size)}


@dataclass(frozen=True)
class Coverage:
    """k of n intervals contain the truth; fraction k / n and its 95% Clopper-Pearson interval
    (lo, hi); NaN when n = 0."""

    k: int
    n: int
    fraction: float
    lo: float
    hi: float

    def to_dict(self) -> dict:
        """The coverage as a plain dict.

        Returns:
            Field name -> value.
        """
        return asdict(self)


def coverage(hits) -> Coverage:
    """The coverage of a set of intervals with its exact binomial (Clopper-Pearson) 95% interval.

    Args:
        hits (ArrayLike): [n] bool, which intervals contain the truth.

    Returns:
        The [`Coverage`][physgs.oma.intervals.Coverage].
    """
    h = np.asarray(hits, bool).ravel()
    k, n = int(h.sum()), int(h.size)
    if n == 0:
        nan = float("nan")
        return Coverage(0, 0, nan, nan, nan)
    ci = stats.binomtest(k, n).proportion_ci(confidence_level=0.95, method="exact")
    return Coverage(k, n, k / n, float(ci.low), float(ci.high))
