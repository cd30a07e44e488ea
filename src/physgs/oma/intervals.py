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
