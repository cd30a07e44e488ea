"""Statistics over training seeds (or any small sample): Student's t intervals on the mean,
paired differences decided only when their interval excludes 0 (with one seed nothing is), the
best of several candidates, and the seeds a claim would need.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

LEVEL = 0.95  # two-sided confidence level of every interval
POWER = 0.8  # the power at which ``seeds_to_decide`` sizes a two-sided t-test
MAX_SEEDS = 1000  # ``seeds_to_decide`` looks no further (NaN: more than this)


def finite(values: Sequence[float]) -> np.ndarray:
    """The finite values of ``values``, flattened, as float64.

    Args:
        values: per-seed values.

    Returns:
        [n] the finite ones.
    """
    v = np.asarray(values, dtype=np.float64).ravel()
    return v[np.isfinite(v)]


def interval(values: Sequence[float], level: float = LEVEL) -> tuple[float, float, float, float]:
    """(mean, sd, low, high) of the finite values, Student's t on the mean.

    Args:
        values: per-seed values.
        level: the interval's coverage.

    Returns:
        ``(mean, sd, low, high)``: sd and bounds NaN with one value, all NaN with none.
    """
    v = finite(values)
    if v.size == 0:
        return (np.nan,) * 4
    m = float(v.mean())
    if v.size == 1:
        return m, np.nan, np.nan, np.nan
    from scipy import stats  # here: the workflow plans with modules that import this one

    sd = float(v.std(ddof=1))
    h = float(stats.t.ppf(0.5 + level / 2, v.size - 1)) * sd / np.sqrt(v.size)
    return m, sd, m - h, m + h


def log_interval(
    values: Sequence[float], level: float = LEVEL
) -> tuple[float, float, float, float]:
    """``interval`` of the per-seed log-ratios, exponentiated: a ratio's interval stays positive.

    Args:
        values: per-seed ratios (> 0, else ValueError; NaN dropped).
        level: the interval's coverage.

    Returns:
        ``(exp(mean log), sd of log, exp(low), exp(high))``.
    """
    v = finite(values)
    if (v <= 0).any():
        raise ValueError(f"log_interval: ratios must be positive, got {v.tolist()}")
    m, sd, lo, hi = interval(np.log(v), level)
    return float(np.exp(m)), sd, float(np.exp(lo)), float(np.exp(hi))


def seeds_to_decide(
    effect: float, sd: float, level: float = LEVEL, power: float = POWER
) -> tuple[float, float]:
    """How many seeds would decide a claim whose mean lies ``effect`` from its threshold with
    seed-to-seed spread ``sd``, if both stayed as observed, estimated two ways.

    Plug-in: the smallest n whose t half-width ``t_{(1+level)/2, n-1} sd / sqrt(n)`` is below
    ``|effect|`` (decides about half the time); power: statsmodels' ``tt_solve_power`` for a
    one-sample two-sided t-test of effect size ``|effect| / sd`` at ``alpha = 1 - level``.

    Args:
        effect: the mean's distance from the threshold, in the claim's unit (log for a ratio).
        sd: the per-seed sd, same unit.
        level: the interval's coverage.
        power: the test's power.

    Returns:
        ``(plug-in n, power n)``; NaN where not finite (no spread, no effect) or > ``MAX_SEEDS``.
    """
    from scipy import stats  # here: the workflow plans with modules that import this one
    from statsmodels.stats.power import tt_solve_power

    e = abs(float(effect))
    if not (np.isfinite(e) and np.isfinite(sd) and sd > 0 and e > 0):
        return np.nan, np.nan
    n = np.arange(2, MAX_SEEDS + 1)
    ok = stats.t.ppf(0.5 + level / 2, n - 1) * sd / np.sqrt(n) < e
    plug = float(n[np.argmax(ok)]) if ok.any() else np.nan
    try:
        need = float(tt_solve_power(effect_size=e / sd, alpha=1 - level, power=power))
    except (ValueError, RuntimeError):  # no root in statsmodels' bracket: far too many seeds
        need = np.nan
    return plug, float(np.ceil(need)) if np.isfinite(need) and need <= MAX_SEEDS else np.nan


def decided(values: Sequence[float], level: float = LEVEL) -> bool:
    """Whether the interval of the mean excludes 0 (never with fewer than two seeds).

    Args:
        values: per-seed values (e.g. paired differences).
        level: the interval's coverage.

    Returns:
        True when decided.
    """
    _, _, lo, hi = interval(values, level)
    return bool(np.isfinite(lo) and (lo > 0 or hi < 0))


def paired(a: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """Per-seed differences a - b (ValueError when the shapes differ).

    Args:
        a: [S] values.
        b: [S] values, in the same seed order.

    Returns:
        [S] differences.
    """
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(
            f"paired differences need one value per seed on both sides, got {a.shape} and {b.shape}"
        )
    return a - b


def decided_best(values: np.ndarray, higher: bool = True, level: float = LEVEL) -> int | None:
    """The candidate whose mean is best, when its paired difference to the runner-up is decided.

    Args:
        values: [S, M] per-seed values of M candidates.
        higher: True when higher is better.
        level: the interval's coverage.

    Returns:
        The best column's index; None for a tie, one seed or fewer than two finite means.
    """
    v = np.asarray(values, dtype=np.float64)
    means = np.array([np.nanmean(c) if np.isfinite(c).any() else np.nan for c in v.T])
    order = np.argsort(-means if higher else means, kind="stable")
    order = [i for i in order if np.isfinite(means[i])]
    if len(order) < 2:
        return None
    d = paired(v[:, order[0]], v[:, order[1]])
    return int(order[0]) if decided(d if higher else -d, level) else None
